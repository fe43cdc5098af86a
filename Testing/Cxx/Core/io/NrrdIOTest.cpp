// NRRD and Slicer .seg.nrrd: round trips (attached, detached, raw, gzip), the real Slicer files
// (LPS geometry, segment fields, a 4D layered segmentation) and bad input.
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/io/NrrdIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <signal.h>
#include <unistd.h>
#include <zlib.h>

#if defined(__SANITIZE_ADDRESS__)
#define REPOSE_TEST_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define REPOSE_TEST_LSAN 1
#endif
#endif
#ifdef REPOSE_TEST_LSAN
#include <sanitizer/lsan_interface.h>
#endif

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <regex>

using namespace repose;
using namespace repose::test;

namespace {

std::string headerText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string text, line;
  while (std::getline(in, line) && !line.empty()) text += line + "\n";
  return text;
}

// `bytes` as one gzip member.
std::string gzipped(const std::string& bytes) {
  z_stream z{};
  EXPECT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&z, uLong(bytes.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = uInt(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

}  // namespace

TEST(NrrdIO, RoundTripsEveryTypeAttachedAndDetachedRawAndGzip) {
  ScratchDir dir;
  int seed = 10;
  for (ScalarType t : {ScalarType::UInt8, ScalarType::UInt16, ScalarType::Int16, ScalarType::Int32,
                       ScalarType::Float32})
    for (const char* ext : {".nrrd", ".nhdr"})
      for (bool compress : {true, false}) {
        const Volume v = randomVolume(t, obliqueGeometry(), 60, seed++);
        const std::string path = dir.file(std::string("v") + std::to_string(seed) + ext);
        WriteOptions o;
        o.compress = compress;
        writeVolume(v, path, o);
        const Volume r = readVolume(path);
        EXPECT_TRUE(sameVoxels(v, r)) << path;
        EXPECT_LT(matrixDifference(v.geometry().ijkToRas, r.geometry().ijkToRas), 1e-9) << path;
        EXPECT_NE(headerText(path).find("space: left-posterior-superior"), std::string::npos);
      }
  // Detached headers brought their data files along, and nothing temporary is left.
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().rfind(".repose-tmp", 0), std::string::npos);
}

TEST(NrrdIO, ReadsSlicerCtInLpsAsRas) {
  const Volume ct = readVolume(dataPath("slicer_seg/CTChest4.nrrd"));
  EXPECT_EQ(ct.dims(), (std::array<std::int64_t, 3>{128, 128, 34}));
  EXPECT_EQ(ct.scalarType(), ScalarType::Int32);
  EXPECT_FALSE(ct.isLabelMap());
  // space directions (-3.05,0,0) (0,-3.05,0) (0,0,10) in LPS are +x, +y in RAS.
  const Eigen::Matrix4d& m = ct.geometry().ijkToRas;
  EXPECT_NEAR(m(0, 0), 3.04687595367432, 1e-9);
  EXPECT_NEAR(m(1, 1), 3.04687595367432, 1e-9);
  EXPECT_NEAR(m(2, 2), 10.0, 1e-9);
  EXPECT_NEAR(m(0, 3), -193.09599304199222, 1e-9);
  EXPECT_NEAR(m(1, 3), -216.39599609374994, 1e-9);
  EXPECT_NEAR(m(2, 3), -340.24999999999994, 1e-9);
  EXPECT_EQ(ct.geometry().axisCodes(), "RAS");
}

TEST(NrrdIO, ReadsSlicerSegmentationFields) {
  const Volume seg = readVolume(dataPath("slicer_seg/Segmentation.seg.nrrd"));
  const Volume ct = readVolume(dataPath("slicer_seg/CTChest4.nrrd"));
  EXPECT_TRUE(seg.isLabelMap());
  EXPECT_EQ(seg.layers(), 1);
  EXPECT_EQ(seg.labels().size(), 7u);
  ASSERT_NE(seg.labels().find(5), nullptr);
  EXPECT_EQ(seg.labels().find(5)->name, "right lung");
  EXPECT_EQ(seg.labels().find(1)->id, "Segment_1");
  EXPECT_NE(seg.labels().find(1)->tags.find("SCT^113197003^Rib"), std::string::npos);
  EXPECT_NEAR(seg.labels().find(5)->color[1], 0.772549, 1e-6);
  EXPECT_LT(matrixDifference(seg.geometry().ijkToRas, ct.geometry().ijkToRas), 1e-9);
  // Orientation sanity on real anatomy: lungs are air (HU < -500), ribs are bone (HU > 150).
  auto meanHu = [&](int label) {
    double sum = 0;
    std::int64_t n = 0;
    for (std::int64_t i = 0; i < seg.numVoxels(); ++i)
      if (seg.data<std::uint8_t>()[i] == label) sum += ct.data<std::int32_t>()[i], ++n;
    return sum / n;
  };
  EXPECT_LT(meanHu(5), -500);
  EXPECT_LT(meanHu(6), -500);
  EXPECT_GT(meanHu(1), 150);
}

TEST(NrrdIO, ReadsLayeredSegmentationWithoutMergingSegments) {
  const Volume seg = readVolume(dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd"));
  EXPECT_EQ(seg.layers(), 2);
  EXPECT_EQ(seg.dims(), (std::array<std::int64_t, 3>{128, 128, 34}));
  ASSERT_NE(seg.labels().find(1, 0), nullptr);
  ASSERT_NE(seg.labels().find(1, 1), nullptr);
  EXPECT_EQ(seg.labels().find(1, 0)->name, "ribs");
  EXPECT_EQ(seg.labels().find(1, 1)->name, "overlapping sphere");
  // The sphere overlaps other segments: some voxels carry a label on both layers.
  std::int64_t overlap = 0, sphere = 0;
  for (std::int64_t i = 0; i < seg.numVoxels(); ++i) {
    sphere += seg.data<std::uint8_t>(1)[i] == 1;
    overlap += seg.data<std::uint8_t>(1)[i] == 1 && seg.data<std::uint8_t>(0)[i] != 0;
  }
  EXPECT_GT(sphere, 0);
  EXPECT_GT(overlap, 0);
  // Layer 0 alone equals the single-layer file's voxels.
  const Volume flat = readVolume(dataPath("slicer_seg/Segmentation.seg.nrrd"));
  EXPECT_EQ(std::memcmp(flat.layerData(0), seg.layerData(0), flat.numVoxels()), 0);
}

TEST(NrrdIO, WrittenSegmentationCarriesSlicerFieldsAndRoundTrips) {
  ScratchDir dir;
  for (const char* name : {"Segmentation.seg.nrrd", "SegmentationOverlapping.seg.nrrd"}) {
    const Volume seg = readVolume(dataPath(std::string("slicer_seg/") + name));
    const std::string out = dir.file(name);
    writeVolume(seg, out);
    const Volume back = readVolume(out);
    EXPECT_TRUE(sameVoxels(seg, back)) << name;
    EXPECT_LT(matrixDifference(seg.geometry().ijkToRas, back.geometry().ijkToRas), 1e-9);
    ASSERT_EQ(back.labels().size(), seg.labels().size());
    for (const Label& l : seg.labels().labels()) {
      const Label* b = back.labels().find(l.value, l.layer);
      ASSERT_NE(b, nullptr);
      EXPECT_EQ(b->name, l.name);
      EXPECT_EQ(b->id, l.id);
      EXPECT_EQ(b->tags, l.tags);
    }
    // Every per-segment and per-segmentation field Slicer's own file has, ours has too.
    const std::string ours = headerText(out),
                      theirs = headerText(dataPath(std::string("slicer_seg/") + name));
    std::regex key(R"((Segment\d+_\w+|Segmentation_\w+):=)");
    for (auto it = std::sregex_iterator(theirs.begin(), theirs.end(), key);
         it != std::sregex_iterator(); ++it)
      EXPECT_NE(ours.find((*it)[1].str() + ":="), std::string::npos) << (*it)[1] << " in " << name;
  }
}

TEST(NrrdIO, SegmentExtentsMatchTheVoxels) {
  ScratchDir dir;
  Volume v(obliqueGeometry({20, 10, 8}), ScalarType::UInt8);
  v.data<std::uint8_t>()[v.index(3, 4, 5)] = 2;
  v.data<std::uint8_t>()[v.index(7, 1, 6)] = 2;
  v.setLabelMap(true);
  writeVolume(v, dir.file("e.seg.nrrd"));
  EXPECT_NE(headerText(dir.file("e.seg.nrrd")).find("Segment0_Extent:=3 7 1 4 5 6"),
            std::string::npos);
}

// vtkMRMLSegmentationStorageNode.cxx: a segment for every table label, an empty one written with
// the empty extent "0 -1 0 -1 0 -1" (offset 0 0 0); ColorAutoGenerated/NameAutoGenerated are "1"
// exactly when made up, and only "1" reads as true; ContainedRepresentationNames lists each
// representation followed by '|', and a name other than the stored one is built on load.
TEST(NrrdIO, SegmentationListsEveryTableLabelAndMarksWhatWasGenerated) {
  ScratchDir dir;
  Volume v(obliqueGeometry({12, 10, 8}), ScalarType::UInt8);
  v.data<std::uint8_t>()[v.index(3, 4, 5)] = 2;  // "liver", colour given
  v.data<std::uint8_t>()[v.index(6, 1, 2)] = 9;  // in no table: generated name and colour
  v.setLabelMap(true);
  Label liver;
  liver.value = 2, liver.name = "liver", liver.color = {0.8, 0.2, 0.1};
  Label lost;  // no voxel left (a pose lost it): still a segment, empty
  lost.value = 5, lost.name = "spleen", lost.color = LabelTable::defaultColor(5);
  lost.colorGenerated = true;
  v.labels().set(liver);
  v.labels().set(lost);
  writeVolume(v, dir.file("s.seg.nrrd"));
  const std::string h = headerText(dir.file("s.seg.nrrd"));
  auto has = [&](const std::string& line) { return h.find(line + "\n") != std::string::npos; };
  EXPECT_TRUE(has("Segmentation_ContainedRepresentationNames:=Binary labelmap|Closed surface|"));
  // Sorted by value: 2, 5, 9.
  EXPECT_TRUE(has("Segment0_Name:=liver"));
  EXPECT_TRUE(has("Segment0_ColorAutoGenerated:=0"));
  EXPECT_TRUE(has("Segment0_NameAutoGenerated:=0"));
  EXPECT_TRUE(has("Segment0_Extent:=3 3 4 4 5 5"));
  EXPECT_TRUE(has("Segment1_Name:=spleen"));
  EXPECT_TRUE(has("Segment1_LabelValue:=5"));
  EXPECT_TRUE(has("Segment1_Extent:=0 -1 0 -1 0 -1"));
  EXPECT_TRUE(has("Segment1_ColorAutoGenerated:=1"));
  EXPECT_TRUE(has("Segment2_Name:=Segment_9"));
  EXPECT_TRUE(has("Segment2_NameAutoGenerated:=1"));
  EXPECT_TRUE(has("Segment2_ColorAutoGenerated:=1"));
  const Volume back = readVolume(dir.file("s.seg.nrrd"));
  ASSERT_EQ(back.labels().size(), 3u);
  EXPECT_FALSE(back.labels().find(2)->colorGenerated);
  EXPECT_TRUE(back.labels().find(5)->colorGenerated);
  EXPECT_EQ(back.labels().find(5)->name, "spleen");
  EXPECT_TRUE(sameVoxels(v, back));
}

// The header check before teem (NrrdHeaderCheck.h) refuses only what teem refuses too: every
// optional field NRRD0005 allows with space directions, in the order the format asks for, is
// still read (per-axis units, spacings and mins go with no directions: teem refuses the mix).
TEST(NrrdIO, EveryOptionalFieldInOrderPassesTheHeaderCheck) {
  ScratchDir dir;
  const std::string path = dir.file("rich.nrrd");
  std::ofstream(path, std::ios::binary)
      << "NRRD0005\r\n# a comment: with a colon\ntype: short\ncontent: test\ndimension: 3\n"
         "space: left-posterior-superior\nspace units: \"mm\" \"mm\"\t\"mm\"\nsizes: 2 3 2\n"
         "space directions: (2,0,0) (0,1,0) (0,0,1)\ncenterings: cell cell cell\n"
         "kinds: domain domain domain\nlabels: \"x\" \"y \\\"q\\\"\" \"z\"\n"
         "measurement frame: (1,0,0) (0,1,0) (0,0,1)\n"
         "space origin: (1,2,3)\nkey:=value: with colon\nendian: little\nencoding: raw\n\n"
      << std::string(24, '\0');
  const Volume v = readVolume(path);
  EXPECT_EQ(v.dims(), (std::array<std::int64_t, 3>{2, 3, 2}));
}

TEST(NrrdIO, BadInputGivesOneLineErrors) {
  ScratchDir dir;
  auto expectError = [&](const std::string& name, const std::string& content,
                         const std::string& fragment) {
    const std::string path = dir.file(name);
    std::ofstream(path, std::ios::binary) << content;
    try {
      readVolume(path);
      FAIL() << name;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
      EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
    }
  };
  const std::string head =
      "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
      "sizes: 4 4 4\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nendian: little\n";
  expectError("short.nrrd", head + "encoding: raw\n\n" + std::string(10, 'x'), "truncated");
  expectError("garbage.nrrd", "this is not a nrrd file\n", "not a NRRD file");
  // Regression (FuzzNrrd with leak checking): without the magic teem reads a file as plain text,
  // and its text reader leaked its buffers on a short line (the sanitizer gate checks leaks).
  expectError("text.nrrd", "1 2 3\n4 5 6\n7 8\n", "not a NRRD file");
  expectError("nan.nrrd", "NRRD000nan\n1 2\n3\n", "not a NRRD file");
  expectError("empty.nrrd", "", "file is empty");
  expectError("blankfirst.nrrd", "\nNRRD0004\n", "not a NRRD file");
  expectError("version6.nrrd", "NRRD0006\ntype: short\n", "not a NRRD file");
  // Regressions (FuzzNrrd and FuzzSegNrrd with leak checking): teem leaked what it allocated
  // for kinds or centers before the dimension, for an unclosed quoted label or unit, and for a
  // surplus space unit. The NRRD format forbids each; they are refused before teem reads them.
  // Regression (a FuzzSegNrrd campaign with leak checking): a header teem parses but finds
  // inconsistent leaked teem's cleanup list; Repose runs teem's NRRD reader and check itself.
  expectError("kindsize.nrrd",
              "NRRD0004\ntype: unsigned char\ndimension: 3\nsizes: 4 4 4\n"
              "kinds: domain hsv-color domain\nencoding: raw\n\n" +
                  std::string(64, 'x'),
              "kind HSV-color requires size 3, but have 4");
  const std::string magic = "NRRD0004\ntype: short\n";
  expectError("kinds.nrrd", magic + "kinds: domain domain domain\ndimension: 3\n",
              "header line 3 (kinds) comes before the dimension field");
  expectError("centers.nrrd", magic + "centers: cell cell cell\ndimension: 3\n",
              "(centers) comes before the dimension field");
  expectError("list.nhdr", magic + "data file: LIST\na.raw\n",
              "(data file) comes before the dimension field");
  expectError("dirs.nrrd", magic + "dimension: 3\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n",
              "(space directions) comes before the space or space dimension field");
  expectError("origin.nrrd", magic + "space origin: (0,0,0)\nspace: RAS\n",
              "(space origin) comes before the space");
  expectError("label.nrrd", magic + "dimension: 3\nlabels: \"x\" \"y\" \"z\n",
              "header line 4 (labels) is not a list of closed quoted strings");
  expectError("units.nrrd", magic + "dimension: 3\nunits: \"mm\" \"mm\"\n",
              "(units) holds 2 quoted strings, not one per axis (3)");
  expectError("spaceunits.nrrd",
              magic + "dimension: 3\nspace: RAS\nspace units: \"mm\" \"mm\" \"mm\" \"mm\"\n",
              "(space units) holds 4 quoted strings, not one per space axis (3)");
  expectError("type.nrrd",
              "NRRD0004\ntype: block\nblock size: 3\ndimension: 3\nsizes: 2 2 2\nendian: "
              "little\nencoding: raw\n\n" +
                  std::string(24, 'x'),
              "unsupported voxel type block");
  expectError("twod.nrrd",
              "NRRD0004\ntype: short\ndimension: 2\nsizes: 2 2\nendian: little\nencoding: raw\n\n" +
                  std::string(8, 'x'),
              "2D");
  expectError("missingdata.nhdr", head + "encoding: raw\ndata file: nowhere.raw\n",
              "couldn't open \"" + dir.file("nowhere.raw") + "\"");
  expectError("badgz.nrrd", head + "encoding: gzip\n\nnot gzip at all", "truncated or corrupt");
  // Regression (Testing/Fuzz/FuzzSegNrrd): a field of ~1,000-1,900 characters that teem cannot
  // parse overflowed teem's error buffer on the stack; it is refused before teem reads it.
  for (const std::size_t n : {1000u, 1500u})
    expectError("longfield" + std::to_string(n) + ".nrrd",
                head + "space origin: (" + std::string(n, '9') + ")\nencoding: raw\n\n" +
                    std::string(128, 'x'),
                "(space origin) is " + std::to_string(n + 16) + " characters long");
  // Regression (a FuzzSegNrrd campaign): a NUL byte before ":=" made teem read a long key:=value
  // line as a field it could not parse, and the same stack buffer overflowed.
  expectError("nul.nrrd",
              head + "encoding: raw\nConversion" + std::string(1, '\0') +
                  "s:=" + std::string(2000, 't') + "\n\n" + std::string(128, 'x'),
              "header line 9 holds a NUL byte");
  // Regressions (FuzzSegNrrd campaigns): teem ends a line at a lone "\r" too, which made the
  // tail of a long key:=value line a field; and a line whose first ':' is not followed by '=' is
  // a field to teem even with a ":=" further on. Both overflowed the same buffer.
  expectError("cr.nrrd",
              head + "encoding: raw\nSegment0_Tags:=Segmentation\rion" + std::string(1500, 't') +
                  "\n\n" + std::string(128, 'x'),
              "header line 10 (ion");
  expectError("colon.nrrd",
              head + "encoding: raw\nSegment1_Ext:" + std::string(1500, 't') + ":=x\n\n" +
                  std::string(128, 'x'),
              "header line 9 (Segment1_Ext) is 1516 characters long");
  // Regression (a FuzzNrrd campaign): sizes whose product overflows made teem ask malloc for
  // 1.4e19 bytes; sizes beyond 2^40 voxels are refused from the header, with or without a budget.
  // (teem itself refuses a count beyond size_t; the fuzzed one wrapped to 8.8e17 x 4 x 4).
  for (const auto& [sizes, fragment] : std::vector<std::pair<std::string, std::string>>{
           {"5555555555555555555555555554 4 4", "too large"},
           {"876950927440754914 4 4", "sizes 876950927440754914 4 4 hold more than 2^40 voxels"},
           {"1048576 1048576 2", "hold more than 2^40 voxels"}})
    expectError("huge.nrrd",
                "NRRD0004\ntype: unsigned char\ndimension: 3\nsizes: " + sizes +
                    "\nencoding: raw\n\n" + std::string(64, 'x'),
                fragment);
  // Long key:=value pairs are data, not fields: Slicer's segment tags are read as before, with
  // "\r\n" line ends too.
  std::string crlf = head + "encoding: raw\nSegment0_Tags:=" + std::string(3000, 't') + "\n\n";
  for (std::size_t i = crlf.find('\n'); i != std::string::npos; i = crlf.find('\n', i + 2))
    crlf.insert(i, 1, '\r');
  std::ofstream(dir.file("crlf.nrrd"), std::ios::binary) << crlf + std::string(128, 'x');
  EXPECT_NO_THROW(readVolume(dir.file("crlf.nrrd")));
  const std::string tags = head + "encoding: raw\nSegment0_Tags:=" + std::string(3000, 't') +
                           "\n\n" + std::string(128, 'x');
  std::ofstream(dir.file("longtags.nrrd"), std::ios::binary) << tags;
  EXPECT_NO_THROW(readVolume(dir.file("longtags.nrrd")));
}

// gzip data are inflated by Repose's own zlib stream (io/NrrdGzipData.h), released on every path
// (teem's reader kept ~50 KB per corrupt file; the sanitizer gate checks nothing leaks here):
// big-endian shorts come out in the host's order, attached or in a detached file, two gzip
// members back to back read as one, and data cut short or not gzip give one line naming the file.
TEST(NrrdIO, GzipVoxelsInflateInHostOrderAndBadDataIsOneLine) {
  ScratchDir dir;
  std::string raw;  // 4 x 4 x 4 shorts, big-endian, some negative
  std::vector<std::int16_t> expected;
  for (int i = 0; i < 64; ++i) {
    const auto v = std::int16_t(i * 37 - 1000);
    expected.push_back(v);
    const auto u = std::uint16_t(v);
    raw += char(u >> 8), raw += char(u & 0xff);
  }
  const std::string head =
      "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 4 4 4\n"
      "space directions: (1,0,0) (0,1,0) (0,0,1)\nendian: big\nencoding: gzip\n";
  auto expectVoxels = [&](const std::string& path) {
    const Volume v = readVolume(path);
    ASSERT_EQ(v.numVoxels(), 64);
    ASSERT_EQ(v.scalarType(), ScalarType::Int16);
    for (int i = 0; i < 64; ++i)
      EXPECT_EQ(v.data<std::int16_t>()[i], expected[std::size_t(i)]) << i;
  };
  const std::string attached = dir.file("attached.nrrd");
  std::ofstream(attached, std::ios::binary) << head << "\n" << gzipped(raw);
  expectVoxels(attached);
  const std::string twoMembers = dir.file("members.nrrd");
  std::ofstream(twoMembers, std::ios::binary)
      << head << "\n"
      << gzipped(raw.substr(0, 50)) << gzipped(raw.substr(50));
  expectVoxels(twoMembers);
  const std::string detached = dir.file("detached.nhdr");
  std::ofstream(dir.file("detached.raw.gz"), std::ios::binary) << gzipped(raw);
  std::ofstream(detached, std::ios::binary) << head << "data file: detached.raw.gz\n";
  expectVoxels(detached);
  for (const auto& [name, data] :
       std::vector<std::pair<std::string, std::string>>{{"cut.nrrd", gzipped(raw).substr(0, 40)},
                                                        {"short.nrrd", gzipped(raw.substr(0, 100))},
                                                        {"notgzip.nrrd", std::string(200, 'z')}}) {
    const std::string path = dir.file(name);
    std::ofstream(path, std::ios::binary) << head << "\n" << data;
    try {
      readVolume(path);
      ADD_FAILURE() << name;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(path + ": voxel data is truncated or corrupt", 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

// A NRRD write that fails (a full disk: the file size limited to 20 KB, in a child process) gives
// one line naming the file, leaves no file, and under the sanitizers (the sanitizer gate) leaves
// nothing allocated: teem's gzip writer kept its zlib stream then; Repose writes gzip data itself.
TEST(NrrdIO, AFailedWriteGivesOneLineAndLeavesNothingAllocated) {
  ScratchDir dir;
  // Noise in 30 labels: the gzip data outgrow the limit.
  const Volume v = randomVolume(ScalarType::Int16, obliqueGeometry({48, 48, 48}), 30, 7);
  for (const std::string name : {"g.nrrd", "g.nhdr", "g.seg.nrrd", "raw.nrrd"}) {
    const std::string path = dir.file(name);
    const pid_t child = ::fork();
    if (child == 0) {
      ::signal(SIGXFSZ, SIG_IGN);  // a full disk sends no signal
      const rlimit limit{20000, 20000};
      ::setrlimit(RLIMIT_FSIZE, &limit);
      int code = 0;
      try {
        WriteOptions options;
        options.compress = name != "raw.nrrd";
        writeVolume(v, path, options);
        code = 3;
      } catch (const Error& e) {
        const std::string m = e.what();
        code = m.rfind(path, 0) == 0 && m.find('\n') == std::string::npos ? 0 : 4;
      }
#ifdef REPOSE_TEST_LSAN
      if (__lsan_do_recoverable_leak_check() != 0) code = 5;
#endif
      ::_exit(code);
    }
    int status = -1;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << name;
    EXPECT_EQ(WEXITSTATUS(status), 0) << name << ": 3 written, 4 not one line naming it, 5 leaked";
    std::vector<std::string> left;
    for (const auto& e : std::filesystem::directory_iterator(dir.path()))
      left.push_back(e.path().filename());
    EXPECT_TRUE(left.empty()) << name << ": " << left.front();
  }
}

// A segmentation written slab by slab (the header last, its extents gathered on the way) is the
// whole map's file byte for byte: Slicer's own single-layer and overlapping (layered) ones.
TEST(NrrdIO, ASegmentationWrittenInSlabsIsTheWholeMapsFile) {
  ScratchDir dir;
  auto bytes = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const char* name : {"Segmentation.seg.nrrd", "SegmentationOverlapping.seg.nrrd"}) {
    const Volume seg = readVolume(dataPath(std::string("slicer_seg/") + name));
    const std::string whole = dir.file(std::string("whole_") + name);
    writeVolume(seg, whole);
    const auto d = seg.dims();
    const std::int64_t plane = d[0] * d[1];
    const std::size_t size = scalarSize(seg.scalarType());
    for (const std::int64_t slab : {std::int64_t(1), std::int64_t(7), d[2]}) {
      const std::string path = dir.file(std::to_string(slab) + "_" + name);
      SegNrrdSlabWriter writer(path, seg.geometry(), seg.scalarType(), seg.layers(), seg.labels());
      std::vector<std::uint8_t> buffer;
      for (std::int64_t k0 = 0; k0 < d[2]; k0 += slab) {
        const std::int64_t n = std::min(slab, d[2] - k0);
        buffer.resize(std::size_t(n * plane * seg.layers()) * size);
        for (int l = 0; l < seg.layers(); ++l)
          std::memcpy(buffer.data() + std::size_t(l * n * plane) * size,
                      static_cast<const std::uint8_t*>(seg.layerData(l)) + k0 * plane * size,
                      std::size_t(n * plane) * size);
        writer.writeSlices(buffer.data(), n);
      }
      EXPECT_FALSE(std::ifstream(path).good()) << "nothing appears before finish()";
      writer.finish();
      EXPECT_EQ(bytes(path), bytes(whole)) << name << ", slabs of " << slab;
    }
    if (std::string(name).find("Overlapping") != std::string::npos) EXPECT_GT(seg.layers(), 1);
  }
  SegNrrdSlabWriter unfinished(dir.file("short.seg.nrrd"),
                               VolumeGeometry::make({4, 4, 4}, {1, 1, 1}, {0, 0, 0}),
                               ScalarType::UInt8, 1, LabelTable());
  std::vector<std::uint8_t> slice(16, 1);
  unfinished.writeSlices(slice.data(), 1);
  EXPECT_THROW(unfinished.finish(), Error);
}

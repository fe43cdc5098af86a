// DICOM SEG in: the real dcmqi files against the label map made from the same segmentation and
// against DCMTK's own dcmseg reading them; generated files for what the real ones lack (odd frame
// sizes, fractional pixels, sparse frames) and for the broken files a reader must refuse.
#include "TestDicomSeg.h"
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/io/DicomSegIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"
#include "repose/volume/SegmentTerminology.h"

#include <dcmtk/dcmfg/fgplanpo.h>
#include <dcmtk/dcmiod/cielabutil.h>
#include <dcmtk/dcmseg/segdoc.h>
#include <dcmtk/dcmseg/segment.h>
#include <dcmtk/dcmseg/segutils.h>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>

using namespace repose;
using namespace repose::test;

namespace {

std::array<int, 3> rgb255(const std::array<double, 3>& c) {
  return {int(std::lround(c[0] * 255)), int(std::lround(c[1] * 255)), int(std::lround(c[2] * 255))};
}

// The voxels of a label in its layer.
std::set<std::int64_t> voxelsOf(const Volume& v, int value, int layer) {
  std::set<std::int64_t> out;
  const auto* d = v.data<std::uint8_t>(layer);
  for (std::int64_t i = 0; i < v.numVoxels(); ++i)
    if (d[i] == value) out.insert(i);
  return out;
}

std::string errorOf(const std::string& path) {
  try {
    readVolume(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DicomSeg, TheLiverSegIsTheLabelMapBesideItOnTheGridOfItsCt) {
  std::vector<std::string> notes;
  ReadOptions options;
  options.note = [&](const std::string& n) { notes.push_back(n); };
  const Volume seg = readVolume(dataPath("dcmqi_ct3slice/liver.dcm"), options);
  const Volume reference = readVolume(dataPath("dcmqi_ct3slice/liver_seg.nrrd"));
  ASSERT_TRUE(seg.isLabelMap());
  ASSERT_EQ(seg.dims(), reference.dims());
  EXPECT_LT(matrixDifference(seg.geometry().ijkToRas, reference.geometry().ijkToRas), 1e-3);
  EXPECT_EQ(seg.layers(), 1);
  // The NRRD marks the liver 1, as the SEG's only segment is numbered.
  std::int64_t liver = 0, differ = 0;
  for (std::int64_t i = 0; i < seg.numVoxels(); ++i) {
    const bool inSeg = seg.valueAsDouble(i) == 1;
    const bool inRef = reference.valueAsDouble(i) == 1;
    liver += inSeg;
    differ += inSeg != inRef;
  }
  EXPECT_EQ(liver, 36233 + 35645 + 35220);  // the set bits of its three frames
  EXPECT_EQ(differ, 0);
  ASSERT_EQ(seg.labels().size(), 1u);
  const Label& l = seg.labels().labels()[0];
  EXPECT_EQ(l.value, 1);
  EXPECT_EQ(l.name, "Liver");
  EXPECT_EQ(rgb255(l.color), (std::array<int, 3>{221, 130, 101}));  // Slicer's liver colour
  EXPECT_FALSE(l.colorGenerated);
  const auto t = terminologyFromTags(l.tags);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->category, (TerminologyCode{"SRT", "T-D0050", "Tissue"}));
  EXPECT_EQ(t->type, (TerminologyCode{"SRT", "T-62000", "Liver"}));
  // Placed on the CT of ct-3slice/, which it references.
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("ct-3slice"), std::string::npos) << notes[0];
}

TEST(DicomSeg, AFolderHoldingASegReadsTheSegOnItsOwnGridWithoutItsCt) {
  ScratchDir dir;
  std::filesystem::copy_file(dataPath("dcmqi_ct3slice/liver.dcm"), dir.file("seg.dcm"));
  const Volume fromFolder = readVolume(dir.path().string());
  const Volume fromCtGrid = readVolume(dataPath("dcmqi_ct3slice/liver.dcm"));
  // Its frames cover the CT's three slices, so its own grid is the CT's.
  EXPECT_EQ(fromFolder.dims(), fromCtGrid.dims());
  EXPECT_LT(matrixDifference(fromFolder.geometry().ijkToRas, fromCtGrid.geometry().ijkToRas), 1e-3);
  EXPECT_TRUE(sameVoxels(fromFolder, fromCtGrid));
  // A file without an extension is known by its content.
  std::filesystem::copy_file(dataPath("dcmqi_ct3slice/liver.dcm"), dir.file("SEG0001"));
  std::filesystem::remove(dir.file("seg.dcm"));
  EXPECT_TRUE(sameVoxels(readVolume(dir.file("SEG0001")), fromCtGrid));
  // Two SEGs in one folder: which one is meant is asked.
  std::filesystem::copy_file(dataPath("dcmqi_ct3slice/liver.dcm"), dir.file("other.dcm"));
  EXPECT_NE(errorOf(dir.path().string()).find("holds 2 DICOM segmentations"), std::string::npos);
}

TEST(DicomSeg, OverlappingSegmentsGoToLayersAndEachIsWhatDcmtksOwnReaderReads) {
  const std::string path = dataPath("dcmqi_ct3slice/partial_overlaps.dcm");
  const Volume v = readVolume(path);
  ASSERT_EQ(v.labels().size(), 5u);
  EXPECT_EQ(v.layers(), 3);  // segments 1, 2 and 3 share voxels

  DcmSegmentation* raw = nullptr;
  ASSERT_TRUE(DcmSegmentation::loadFile(path.c_str(), raw).good());
  std::unique_ptr<DcmSegmentation> dcm(raw);
  ASSERT_EQ(dcm->getNumberOfSegments(), 5u);
  for (std::size_t s = 1; s <= 5; ++s) {
    const Label* label = nullptr;
    for (const Label& l : v.labels().labels())
      if (l.value == int(s)) label = &l;
    ASSERT_TRUE(label) << s;
    OFString name;
    dcm->getSegment(s)->getSegmentLabel(name);
    EXPECT_EQ(label->name, name.c_str());
    // Every pixel DCMTK unpacks (512x512: a multiple of 8, where 3.6.7 unpacks right) must be
    // the label in its layer, and nothing else.
    std::set<std::int64_t> expected;
    OFVector<size_t> frames;
    dcm->getFramesForSegment(s, frames);
    ASSERT_FALSE(frames.empty());
    for (size_t f : frames) {
      std::unique_ptr<DcmIODTypes::Frame> bits(
          DcmSegUtils::unpackBinaryFrame(dcm->getFrame(f), 512, 512));
      auto* pos = static_cast<FGPlanePosPatient*>(
          dcm->getFunctionalGroups().get(Uint32(f), DcmFGTypes::EFG_PLANEPOSPATIENT));
      ASSERT_TRUE(pos);
      Float64 x = 0, y = 0, z = 0;
      pos->getImagePositionPatient(x, y, z);
      for (int r = 0; r < 512; ++r)
        for (int c = 0; c < 512; ++c)
          if (bits->pixData[r * 512 + c]) {
            // Orientation 1\0\0\0\1\0, spacing 0.810547: LPS, then RAS.
            const Eigen::Vector3d lps(x + c * 0.810547, y + r * 0.810547, z);
            const Eigen::Vector3d ijk = v.geometry().rasToVoxel({-lps.x(), -lps.y(), lps.z()});
            expected.insert(
                v.index(std::lround(ijk.x()), std::lround(ijk.y()), std::lround(ijk.z())));
          }
    }
    EXPECT_EQ(voxelsOf(v, int(s), label->layer), expected) << "segment " << s;
  }
}

TEST(DicomSeg, OddFrameSizesSparseFramesAndSeveralSegmentsArePlacedByPosition) {
  // 5x3 frames (15 bits: frames do not start on a byte), two segments, slices at z = 10, 14 and
  // 16 mm with 2 mm between slices: four slices, one of them (z = 12) with no frame.
  TinySeg t;
  t.positions = {{-1, 2, 14}, {-1, 2, 10}, {-1, 2, 16}, {-1, 2, 14}};
  t.segmentOfFrame = {1, 1, 2, 2};
  t.frames.assign(4, std::vector<std::uint8_t>(15, 0));
  t.frames[0][0] = t.frames[0][14] = 1;
  t.frames[1][7] = 1;
  t.frames[2][4] = t.frames[2][10] = 1;
  t.frames[3][3] = 1;
  ScratchDir dir;
  writeTinySeg(t, dir.file("tiny.dcm"));
  const Volume v = readVolume(dir.file("tiny.dcm"));
  ASSERT_EQ(v.dims(), (std::array<std::int64_t, 3>{5, 3, 4}));
  EXPECT_EQ(v.layers(), 1);  // the two segments do not overlap
  EXPECT_LT((v.geometry().spacing() - Eigen::Vector3d(0.75, 0.5, 2)).norm(), 1e-9);
  // Voxel (0,0,0) is the first pixel of the frame at z = 10: LPS (-1, 2, 10), RAS (1, -2, 10).
  EXPECT_LT((v.geometry().voxelToRas(0, 0, 0) - Eigen::Vector3d(1, -2, 10)).norm(), 1e-9);
  auto at = [&](int i, int j, int k) { return int(v.valueAsDouble(v.index(i, j, k))); };
  EXPECT_EQ(at(0, 0, 2), 1);  // frame 0, pixel 0, z = 14
  EXPECT_EQ(at(4, 2, 2), 1);  // frame 0, pixel 14
  EXPECT_EQ(at(2, 1, 0), 1);  // frame 1, pixel 7, z = 10
  EXPECT_EQ(at(4, 0, 3), 2);  // frame 2, pixel 4, z = 16
  EXPECT_EQ(at(0, 2, 3), 2);  // frame 2, pixel 10
  EXPECT_EQ(at(3, 0, 2), 2);  // frame 3, pixel 3, z = 14
  std::int64_t set = 0;
  for (std::int64_t i = 0; i < v.numVoxels(); ++i) set += v.valueAsDouble(i) != 0;
  EXPECT_EQ(set, 6);
  ASSERT_EQ(v.labels().size(), 2u);
  EXPECT_EQ(v.labels().labels()[1].name, "Segment 2 name");
  EXPECT_NE(rgb255(v.labels().labels()[0].color), rgb255(v.labels().labels()[1].color));
}

TEST(DicomSeg, ASpacingBetweenSlicesTheFramesDoNotKeepGivesWayToTheirOwnAndIsSaid) {
  TinySeg t;
  t.spacingBetweenSlices = "3";
  t.segments = 1;
  t.positions = {{0, 0, 0}, {0, 0, 2}, {0, 0, 6}};
  t.segmentOfFrame = {1, 1, 1};
  t.frames.assign(3, std::vector<std::uint8_t>(15, 1));
  ScratchDir dir;
  writeTinySeg(t, dir.file("spacing.dcm"));
  std::vector<std::string> notes;
  ReadOptions options;
  options.note = [&](const std::string& n) { notes.push_back(n); };
  const Volume v = readVolume(dir.file("spacing.dcm"), options);
  EXPECT_EQ(v.dims()[2], 4);  // z = 0, 2, 4 (no frame), 6
  EXPECT_NEAR(v.geometry().spacing()[2], 2, 1e-9);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("not 3.000000 mm apart as SpacingBetweenSlices says"), std::string::npos)
      << notes[0];
  EXPECT_EQ(v.valueAsDouble(v.index(2, 1, 2)), 0);
  EXPECT_EQ(v.valueAsDouble(v.index(2, 1, 3)), 1);
}

TEST(DicomSeg, FractionalPixelsAreThresholdedAtHalfTheMaximumAndTheReaderSaysSo) {
  TinySeg t;
  t.fractional = true;
  t.maxFractional = 200;
  t.segments = 1;
  t.positions = {{0, 0, 0}};
  t.segmentOfFrame = {1};
  t.frames = {{0, 99, 100, 101, 200, 1, 0, 150, 0, 0, 0, 0, 0, 0, 0}};
  ScratchDir dir;
  writeTinySeg(t, dir.file("fractional.dcm"));
  std::vector<std::string> notes;
  ReadOptions options;
  options.note = [&](const std::string& n) { notes.push_back(n); };
  const Volume v = readVolume(dir.file("fractional.dcm"), options);
  std::vector<int> values;
  for (std::int64_t i = 0; i < 15; ++i) values.push_back(int(v.valueAsDouble(i)));
  EXPECT_EQ(values, (std::vector<int>{0, 0, 1, 1, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0}));
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("FRACTIONAL segmentation (PROBABILITY, maximum 200) thresholded at 0.5"),
            std::string::npos);
}

TEST(DicomSeg, BrokenFilesAreRefusedWithOneLineNamingTheFileAndTheProblem) {
  ScratchDir dir;
  auto base = [] {
    TinySeg t;
    t.positions = {{0, 0, 0}, {0, 0, 2}};
    t.segmentOfFrame = {1, 2};
    t.frames.assign(2, std::vector<std::uint8_t>(15, 1));
    return t;
  };
  struct Case {
    std::string name, expected;
    TinySeg seg;
  };
  std::vector<Case> cases;
  {
    TinySeg t = base();
    t.frameWithoutPosition = 1;
    cases.push_back({"noposition.dcm", "frame 2 has no plane position", t});
  }
  {
    TinySeg t = base();
    t.segmentOfFrame[1] = 7;
    cases.push_back(
        {"unknownsegment.dcm", "frame 2 refers to segment 7, which the file does not define", t});
  }
  {
    TinySeg t = base();
    t.cutPixelBytes = 2;
    cases.push_back({"truncated.dcm", "pixel data is truncated", t});
  }
  {
    TinySeg t = base();
    t.framesDeclared = 0;
    cases.push_back({"zeroframes.dcm", "NumberOfFrames is missing or zero", t});
  }
  {
    TinySeg t = base();
    t.framesDeclared = 3;
    cases.push_back({"moreframes.dcm", "do not match NumberOfFrames (3)", t});
  }
  {
    TinySeg t = base();  // 2 mm apart as said, and 1.3 mm: no spacing holds all three
    t.positions.push_back({0, 0, 3.3});
    t.segmentOfFrame.push_back(1);
    t.frames.push_back(t.frames[0]);
    cases.push_back({"offgrid.dcm", "frame 3 is not on the grid of the other frames", t});
  }
  for (const Case& c : cases) {
    const std::string path = dir.file(c.name);
    writeTinySeg(c.seg, path);
    const std::string message = errorOf(path);
    EXPECT_NE(message.find(path), std::string::npos) << c.name << ": " << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.name << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // The real file cut in half.
  const std::string cut = dir.file("cut.dcm");
  {
    std::ifstream in(dataPath("dcmqi_ct3slice/liver.dcm"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  const std::string message = errorOf(cut);
  EXPECT_NE(message.find(cut), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  // Other DICOM objects are named for what they are.
  EXPECT_NE(errorOf(dataPath("dicompyler_rt/rtss.dcm")).find("an RT Structure Set"),
            std::string::npos);
  EXPECT_NE(errorOf(dataPath("dcmqi_ct3slice/ct-3slice/01.dcm")).find("a DICOM image file"),
            std::string::npos);
}

TEST(SegmentTerminology, SlicersTagsRoundTripAndGenericTissueIsTheDefault) {
  SegmentTerminology t;
  t.category = {"SCT", "123037004", "Anatomical Structure"};
  t.type = {"SCT", "113197003", "Rib"};
  t.region = {"SCT", "51185008", "Thorax"};
  const std::string tags = "Segmentation.Status:inprogress|" + terminologyTag(t);
  EXPECT_EQ(terminologyFromTags(tags), t);
  // As Slicer writes it (its own .seg.nrrd).
  const auto slicer = terminologyFromTags(
      "Segmentation.Status:inprogress|TerminologyEntry:Segmentation category and type - 3D Slicer "
      "General Anatomy list~SCT^123037004^Anatomical Structure~SCT^113197003^Rib~^^~Anatomic "
      "codes - DICOM master list~^^~^^|");
  ASSERT_TRUE(slicer);
  EXPECT_EQ(slicer->type.meaning, "Rib");
  EXPECT_TRUE(slicer->region.empty());
  EXPECT_FALSE(terminologyFromTags("Segmentation.Status:inprogress|"));
  EXPECT_EQ(genericTissueTerminology().type.value, "85756007");
}

namespace {

std::string attribute(const std::string& path, const DcmTagKey& tag) {
  DcmFileFormat file;
  EXPECT_TRUE(file.loadFile(path.c_str()).good()) << path;
  OFString v;
  file.getDataset()->findAndGetOFStringArray(tag, v);
  return v.c_str();
}

}  // namespace

TEST(DicomSegWrite,
     ASlicerSegmentationWithLayersComesBackVoxelForVoxelWithItsNamesColoursAndCodes) {
  const Volume in = readVolume(dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd"));
  ASSERT_EQ(in.layers(), 2);
  ScratchDir dir;
  const std::string out = dir.file("seg.dcm");
  writeVolume(in, out);
  const Volume back = readVolume(out);
  ASSERT_EQ(back.dims(), in.dims());
  EXPECT_LT(matrixDifference(back.geometry().ijkToRas, in.geometry().ijkToRas), 1e-6);
  ASSERT_EQ(back.layers(), in.layers());
  EXPECT_TRUE(sameVoxels(back, in));
  ASSERT_EQ(back.labels().size(), in.labels().size());
  for (const Label& l : in.labels().labels()) {
    const Label* b = back.labels().find(l.value, l.layer);
    ASSERT_TRUE(b) << l.name;
    EXPECT_EQ(b->name, l.name);
    EXPECT_EQ(rgb255(b->color), rgb255(l.color)) << l.name;
    ASSERT_TRUE(terminologyFromTags(l.tags)) << l.tags;
    EXPECT_EQ(terminologyFromTags(b->tags), terminologyFromTags(l.tags)) << l.name;
  }
}

TEST(DicomSegWrite, DcmtksOwnSegReaderReadsEverySegmentWhereReposePutIt) {
  const Volume in = readVolume(dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd"));
  ScratchDir dir;
  const std::string out = dir.file("seg.dcm");
  writeVolume(in, out);
  DcmSegmentation* raw = nullptr;
  ASSERT_TRUE(DcmSegmentation::loadFile(out.c_str(), raw).good());
  std::unique_ptr<DcmSegmentation> dcm(raw);
  ASSERT_EQ(dcm->getNumberOfSegments(), in.labels().size());
  const std::int64_t columns = in.dims()[0], rows = in.dims()[1];
  // Segments are numbered in (layer, value) order.
  std::size_t number = 0;
  for (const Label& l : in.labels().labels()) {
    ++number;
    DcmSegment* segment = dcm->getSegment(number);
    ASSERT_TRUE(segment);
    OFString name;
    segment->getSegmentLabel(name);
    EXPECT_EQ(l.name, name.c_str());
    Uint16 L = 0, a = 0, b = 0;
    ASSERT_TRUE(segment->getRecommendedDisplayCIELabValue(L, a, b).good());
    double r = 0, g = 0, bl = 0;
    IODCIELabUtil::dicomLab2RGB(r, g, bl, L, a, b);
    EXPECT_EQ(rgb255({r, g, bl}), rgb255(l.color)) << l.name;
    std::set<std::int64_t> read;
    OFVector<size_t> frames;
    dcm->getFramesForSegment(number, frames);
    for (size_t f : frames) {
      std::unique_ptr<DcmIODTypes::Frame> bits(
          DcmSegUtils::unpackBinaryFrame(dcm->getFrame(f), Uint16(rows), Uint16(columns)));
      auto* pos = static_cast<FGPlanePosPatient*>(
          dcm->getFunctionalGroups().get(Uint32(f), DcmFGTypes::EFG_PLANEPOSPATIENT));
      ASSERT_TRUE(pos);
      Float64 x = 0, y = 0, z = 0;
      pos->getImagePositionPatient(x, y, z);
      const Eigen::Vector3d ijk0 = in.geometry().rasToVoxel({-x, -y, z});
      for (std::int64_t p = 0; p < rows * columns; ++p)
        if (bits->pixData[p])
          read.insert(in.index(std::lround(ijk0.x()) + p % columns,
                               std::lround(ijk0.y()) + p / columns, std::lround(ijk0.z())));
    }
    EXPECT_EQ(read, voxelsOf(in, l.value, l.layer)) << l.name;
  }
}

TEST(DicomSegWrite, OddSlicesAndValuesThatAreNotOneToNComeBackAndPatientAndStudyAreTheSources) {
  VolumeGeometry g;
  g.dims = {5, 3, 4};
  g.ijkToRas.block<3, 3>(0, 0) = Eigen::Vector3d(0.5, 0.7, 2.5).asDiagonal();
  g.ijkToRas.block<3, 1>(0, 3) = Eigen::Vector3d(10, -20, 30);
  Volume v(g, ScalarType::UInt16);
  v.setLabelMap(true);
  auto* d = v.data<std::uint16_t>();
  d[v.index(0, 0, 0)] = 300;
  d[v.index(4, 2, 0)] = 7;
  d[v.index(3, 1, 3)] = 7;
  d[v.index(2, 2, 3)] = 300;  // slices 1 and 2 hold nothing
  Label named;
  named.value = 7;
  named.name = "kidney";
  named.color = {0.2, 0.4, 0.6};
  v.labels().set(named);
  Label empty;  // in the table, with no voxel
  empty.value = 9;
  empty.name = "lost";
  v.labels().set(empty);
  ScratchDir dir;
  WriteOptions w;
  w.sourceDicom = dataPath("dcmqi_ct3slice/liver.dcm");
  writeVolume(v, dir.file("odd.dcm"), w);
  const Volume back = readVolume(dir.file("odd.dcm"));
  EXPECT_LT(matrixDifference(back.geometry().ijkToRas, g.ijkToRas), 1e-9);
  EXPECT_TRUE(sameVoxels(back, v));
  ASSERT_TRUE(back.labels().find(7) && back.labels().find(9) && back.labels().find(300));
  EXPECT_EQ(back.labels().find(7)->name, "kidney");
  EXPECT_EQ(back.labels().find(9)->name, "lost");
  EXPECT_EQ(back.labels().find(300)->name, "Segment_300");
  EXPECT_EQ(rgb255(back.labels().find(7)->color), rgb255(named.color));
  const auto t = terminologyFromTags(back.labels().find(7)->tags);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t, genericTissueTerminology());
  // Patient and study of the source; its own series, instance, frame of reference and equipment.
  const std::string source = dataPath("dcmqi_ct3slice/liver.dcm"), out = dir.file("odd.dcm");
  for (const DcmTagKey& same : {DCM_PatientName, DCM_PatientID, DCM_StudyInstanceUID})
    EXPECT_EQ(attribute(out, same), attribute(source, same)) << DcmTag(same).getTagName();
  for (const DcmTagKey& fresh :
       {DCM_SeriesInstanceUID, DCM_SOPInstanceUID, DCM_FrameOfReferenceUID}) {
    EXPECT_NE(attribute(out, fresh), attribute(source, fresh)) << DcmTag(fresh).getTagName();
    EXPECT_FALSE(attribute(out, fresh).empty());
  }
  EXPECT_EQ(attribute(out, DCM_Manufacturer), "Repose");
}

TEST(DicomSegWrite, NamesAndCodesDicomCannotHoldAreMadeFitRatherThanRefused) {
  VolumeGeometry g;
  g.dims = {4, 4, 1};
  Volume v(g, ScalarType::UInt8);
  v.setLabelMap(true);
  v.data<std::uint8_t>()[0] = 1;
  v.data<std::uint8_t>()[1] = 2;
  Label longName;
  longName.value = 1;
  longName.name = std::string(70, 'x') + "\\tail";
  longName.tags =
      "TerminologyEntry:ctx~SCT^12345678901234567890^Too long a code~SCT^1^Type~^^~ctx~^^~^^|";
  v.labels().set(longName);
  Label accented;
  accented.value = 2;
  accented.name = "muscle, m\u00fcscle";
  v.labels().set(accented);
  ScratchDir dir;
  writeVolume(v, dir.file("names.dcm"));
  const Volume back = readVolume(dir.file("names.dcm"));
  EXPECT_EQ(back.labels().find(1)->name, std::string(64, 'x'));
  EXPECT_EQ(back.labels().find(2)->name, accented.name);  // UTF-8 (ISO_IR 192)
  // The category code was too long for DICOM: both codes give way to SCT Tissue.
  EXPECT_EQ(terminologyFromTags(back.labels().find(1)->tags), genericTissueTerminology());
}

TEST(DicomSegWrite, WhatDicomCannotHoldIsRefusedAndNothingIsWritten) {
  ScratchDir dir;
  VolumeGeometry g;
  g.dims = {4, 4, 2};
  Volume image(g, ScalarType::Float32);
  EXPECT_THROW(writeVolume(image, dir.file("image.dcm")), Error);
  g.ijkToRas(0, 2) = 0.5;  // k leans along x: sheared
  Volume sheared(g, ScalarType::UInt8);
  sheared.setLabelMap(true);
  sheared.data<std::uint8_t>()[0] = 1;
  try {
    writeVolume(sheared, dir.file("sheared.dcm"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sheared.dcm: a DICOM SEG's slices must be stacked"),
              std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(DicomSegWrite, TheSourceOfPatientAndStudyIsTheInputsDicomFile) {
  EXPECT_EQ(dicomSourceOf(dataPath("dcmqi_ct3slice/liver.dcm")),
            dataPath("dcmqi_ct3slice/liver.dcm"));
  EXPECT_EQ(dicomSourceOf(dataPath("dcmqi_ct3slice/ct-3slice")),
            dataPath("dcmqi_ct3slice/ct-3slice/01.dcm"));
  EXPECT_EQ(dicomSourceOf(dataPath("dcmqi_ct3slice/liver_seg.nrrd")), "");
  ScratchDir dir;
  std::filesystem::copy_file(dataPath("dcmqi_ct3slice/liver.dcm"), dir.file("seg.dcm"));
  EXPECT_EQ(dicomSourceOf(dir.path().string()), dir.file("seg.dcm"));
}

namespace {

// `v` written by DicomSegSlabWriter in slabs of `slices` (each layer's slices together, as
// LabelSlabs makes them).
void writeInSlabs(const Volume& v, const std::string& path, std::int64_t slices) {
  DicomSegSlabWriter writer(path, v.geometry(), v.scalarType(), v.layers(), v.labels());
  const std::int64_t nz = v.dims()[2];
  const std::size_t slice = std::size_t(v.dims()[0] * v.dims()[1]) * scalarSize(v.scalarType());
  for (std::int64_t k0 = 0; k0 < nz; k0 += slices) {
    const std::int64_t n = std::min(slices, nz - k0);
    std::vector<std::uint8_t> slab(slice * std::size_t(n * v.layers()));
    for (int l = 0; l < v.layers(); ++l)
      std::memcpy(slab.data() + slice * std::size_t(l * n),
                  static_cast<const std::uint8_t*>(v.layerData(l)) + slice * std::size_t(k0),
                  slice * std::size_t(n));
    writer.writeSlices(slab.data(), n);
  }
  writer.finish();
}

}  // namespace

TEST(DicomSegWrite, SlabsOfAnySizeWriteTheWholeVolumesFramesAndTheStandardsCheckFindsNoError) {
  // Layers (overlapping segments), and odd slices with empty ones and a segment with no voxel.
  VolumeGeometry g;
  g.dims = {5, 3, 4};
  g.ijkToRas.block<3, 3>(0, 0) = Eigen::Vector3d(0.5, 0.7, 2.5).asDiagonal();
  Volume odd(g, ScalarType::UInt16);
  odd.setLabelMap(true);
  odd.data<std::uint16_t>()[odd.index(0, 0, 0)] = 300;
  odd.data<std::uint16_t>()[odd.index(4, 2, 0)] = 7;
  odd.data<std::uint16_t>()[odd.index(2, 2, 3)] = 300;
  Label lost;
  lost.value = 9;
  lost.name = "lost";
  odd.labels().set(lost);
  ScratchDir dir;
  int volumes = 0;
  for (const Volume& in :
       {readVolume(dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd")), std::move(odd)}) {
    const std::string whole = dir.file("whole" + std::to_string(volumes) + ".dcm");
    writeVolume(in, whole);
    EXPECT_EQ(dciodvfyErrors(whole), "") << whole;
    for (const std::int64_t slices : {std::int64_t(1), std::int64_t(3), in.dims()[2]}) {
      const std::string slabs =
          dir.file("slabs" + std::to_string(volumes) + "_" + std::to_string(slices) + ".dcm");
      writeInSlabs(in, slabs, slices);
      EXPECT_TRUE(segFramesOf(slabs) == segFramesOf(whole)) << slabs;
      const Volume back = readVolume(slabs);
      EXPECT_TRUE(sameVoxels(back, in)) << slabs;
      EXPECT_EQ(back.labels().size(), readVolume(whole).labels().size()) << slabs;
      EXPECT_EQ(dciodvfyErrors(slabs), "") << slabs;
      EXPECT_NE(attribute(slabs, DCM_SOPInstanceUID), attribute(whole, DCM_SOPInstanceUID));
    }
    ++volumes;
  }
  // A writer given too few slices or too many says so, and leaves nothing.
  const Volume in = readVolume(dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd"));
  ScratchDir empty;
  {
    DicomSegSlabWriter writer(empty.file("short.dcm"), in.geometry(), in.scalarType(), 2,
                              in.labels());
    std::vector<std::uint8_t> slab(std::size_t(in.dims()[0] * in.dims()[1] * 2), 0);
    writer.writeSlices(slab.data(), 1);
    EXPECT_THROW(writer.finish(), Error);
    EXPECT_THROW(writer.writeSlices(slab.data(), in.dims()[2]), Error);
  }
  EXPECT_TRUE(std::filesystem::is_empty(empty.path()));
}

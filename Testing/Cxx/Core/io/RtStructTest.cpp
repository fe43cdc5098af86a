// RT Structure Sets: the real dicompyler file rasterized as plastimatch rasterizes it (Dice per
// ROI on the same grid), and generated structure sets for holes, layers, the reach of contours
// between their planes, and the broken files a reader must refuse.
#include "TestPaths.h"
#include "TestRtStruct.h"
#include "TestVolumes.h"

#include "repose/io/RtStructIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>

using namespace repose;
using namespace repose::test;

namespace {

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

}  // namespace

TEST(RtStruct, EveryRoiOfARealStructureSetMatchesPlastimatchsOwnRasterization) {
  const std::string rtss = dataPath("dicompyler_rt/rtss.dcm");
  RtStructOptions options;
  options.spacingMm = 3;  // the contours' plane spacing: every slice is one plane
  const Volume ours = readRtStruct(rtss, options);
  ASSERT_EQ(ours.labels().size(), 10u);  // "Areola" has no contour and stays listed, empty
  ScratchDir dir;
  // plastimatch on the same grid: a volume of ours' geometry given as --fixed.
  Volume grid(ours.geometry(), ScalarType::UInt8);
  writeVolume(grid, dir.file("grid.nrrd"));
  const std::string command = "plastimatch convert --input " + quoted(rtss) + " --fixed " +
                              quoted(dir.file("grid.nrrd")) + " --output-prefix " +
                              quoted(dir.file("pm")) + " --prefix-format nrrd > " +
                              quoted(dir.file("pm.log")) + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  int compared = 0;
  for (const Label& l : ours.labels().labels()) {
    const std::string theirs = dir.file("pm/" + l.name + ".nrrd");
    if (l.name == "Areola") continue;  // no contour: plastimatch writes no image for it
    ASSERT_TRUE(std::filesystem::exists(theirs)) << theirs;
    const Volume pm = readVolume(theirs);
    ASSERT_EQ(pm.dims(), ours.dims()) << l.name;
    ASSERT_LT(matrixDifference(pm.geometry().ijkToRas, ours.geometry().ijkToRas), 1e-3) << l.name;
    std::int64_t a = 0, b = 0, both = 0;
    for (std::int64_t i = 0; i < ours.numVoxels(); ++i) {
      const bool inOurs = ours.valueAsDouble(i, l.layer) == l.value;
      const bool inTheirs = pm.valueAsDouble(i) != 0;
      a += inOurs;
      b += inTheirs;
      both += inOurs && inTheirs;
    }
    ASSERT_GT(a + b, 0) << l.name;
    const double dice = 2.0 * double(both) / double(a + b);
    EXPECT_GE(dice, 0.98) << l.name << ": ours " << a << ", plastimatch " << b;
    RecordProperty("dice_" + l.name, std::to_string(dice));
    std::printf("%-16s ours %7lld plastimatch %7lld Dice %.4f\n", l.name.c_str(), (long long)a,
                (long long)b, dice);
    ++compared;
  }
  EXPECT_EQ(compared, 9);
}

namespace {

int at(const Volume& v, const Eigen::Vector3d& lps, int layer = 0) {
  const Eigen::Vector3d ijk = v.geometry().rasToVoxel({-lps.x(), -lps.y(), lps.z()});
  const std::int64_t i = std::lround(ijk.x()), j = std::lround(ijk.y()), k = std::lround(ijk.z());
  if (i < 0 || j < 0 || k < 0 || i >= v.dims()[0] || j >= v.dims()[1] || k >= v.dims()[2])
    return -1;
  return int(v.valueAsDouble(v.index(i, j, k), layer));
}

std::string errorOf(const std::string& path, double spacing = 1) {
  try {
    RtStructOptions o;
    o.spacingMm = spacing;
    readRtStruct(path, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(RtStruct, NestedContoursAreHolesOverlappingRoisTakeLayersAndContoursReachHalfwayToTheNext) {
  // ROI 5: a 20 mm square with a 10 mm hole holding a 4 mm island, on planes z = 0 and 6.
  // ROI 12 overlaps it on z = 0 only.
  TinyRoi ring;
  ring.number = 5;
  ring.name = "ring";
  ring.color = {10, 200, 30};
  for (double z : {0.0, 6.0}) {
    ring.contours.push_back(square(0, 0, 20, 20, z));
    ring.contours.push_back(square(5, 5, 15, 15, z));
    ring.contours.push_back(square(8, 8, 12, 12, z));
  }
  TinyRoi patch;
  patch.number = 12;
  patch.name = "patch";
  patch.contours.push_back(square(1, 1, 4, 4, 0));
  TinyRoi empty;
  empty.number = 3;
  empty.name = "planned";
  ScratchDir dir;
  writeTinyRtStruct({empty, ring, patch}, dir.file("rs.dcm"));
  RtStructOptions o;
  o.spacingMm = 1;
  const Volume v = readRtStruct(dir.file("rs.dcm"), o);
  ASSERT_EQ(v.layers(), 2);
  const Label* r = v.labels().find(5, 0);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->name, "ring");
  EXPECT_NEAR(r->color[1], 200 / 255.0, 1e-9);
  ASSERT_TRUE(v.labels().find(12, 1));
  ASSERT_TRUE(v.labels().find(3, 0));      // no contour: listed, empty
  EXPECT_EQ(at(v, {2.5, 2.5, 0}), 5);      // in the ring
  EXPECT_EQ(at(v, {2.5, 2.5, 0}, 1), 12);  // and in the patch, one layer up
  EXPECT_EQ(at(v, {6.5, 10.5, 0}), 0);     // in the hole
  EXPECT_EQ(at(v, {10.5, 10.5, 0}), 5);    // on the island
  // Slices between the planes take the nearest plane's contours: z = 1, 2 from z = 0, z = 4, 5
  // from z = 6; the patch, on one plane only, reaches 3 mm (half the plane gap) and no further.
  for (double z : {1.0, 2.0, 4.0, 5.0}) {
    EXPECT_EQ(at(v, {2.5, 2.5, z}), 5) << z;
    EXPECT_EQ(at(v, {6.5, 10.5, z}), 0) << z;
  }
  EXPECT_EQ(at(v, {2.5, 2.5, 2}, 1), 12);
  EXPECT_EQ(at(v, {2.5, 2.5, 4}, 1), 0);
  // Voxel centres inside the 20 mm square: 20 x 20 per slice, minus the hole's 10 x 10, plus the
  // island's 4 x 4, over 7 slices.
  std::int64_t ringVoxels = 0;
  for (std::int64_t i = 0; i < v.numVoxels(); ++i) ringVoxels += v.valueAsDouble(i, 0) == 5;
  EXPECT_EQ(ringVoxels, 7 * (400 - 100 + 16));
}

TEST(RtStruct, BrokenStructureSetsAreRefusedWithOneLineNamingTheFileAndTheProblem) {
  ScratchDir dir;
  struct Case {
    std::string name, expected;
    TinyRoi roi;
  };
  std::vector<Case> cases;
  {
    TinyRoi r;
    r.name = "two points";
    r.contours.push_back({{{0, 0, 0}, {5, 0, 0}}});
    cases.push_back({"twopoints.dcm",
                     "ROI 'two points' contour 1 has 2 points (a closed contour needs at least 3)",
                     r});
  }
  {
    TinyRoi r;
    r.name = "count";
    r.contours.push_back(square(0, 0, 5, 5, 0));
    r.contours.back().declaredPoints = 7;
    cases.push_back({"count.dcm", "ContourData holds 12 numbers for 7 points", r});
  }
  {
    TinyRoi r;
    r.name = "orphan";
    r.referencedNumber = 9;
    r.contours.push_back(square(0, 0, 5, 5, 0));
    cases.push_back({"orphan.dcm", "names ROI 9, which the structure set does not define", r});
  }
  {
    TinyRoi r;
    r.name = "bent";
    r.contours.push_back(square(0, 0, 5, 5, 0));
    r.contours.push_back({{{0, 0, 2}, {5, 0, 2}, {5, 5, 4}, {0, 5, 2}}});
    cases.push_back({"bent.dcm", "ROI 'bent' contour 2 is not in a plane of the grid's slices", r});
  }
  for (const Case& c : cases) {
    writeTinyRtStruct({c.roi}, dir.file(c.name));
    const std::string message = errorOf(dir.file(c.name));
    EXPECT_NE(message.find(dir.file(c.name)), std::string::npos) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.name << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // A reference folder that does not hold the series the structure set references.
  TinyRoi ok;
  ok.name = "ok";
  ok.contours.push_back(square(0, 0, 5, 5, 0));
  writeTinyRtStruct({ok}, dir.file("elsewhere.dcm"), "1.2.3.4.5");
  RtStructOptions o;
  o.reference = dataPath("dcmqi_ct3slice/ct-3slice");
  try {
    readRtStruct(dir.file("elsewhere.dcm"), o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("references series 1.2.3.4.5, which"), std::string::npos)
        << e.what();
  }
  // The real file cut short.
  const std::string cut = dir.file("cut.dcm");
  std::filesystem::copy_file(dataPath("dicompyler_rt/rtss.dcm"), cut);
  std::filesystem::resize_file(cut, std::filesystem::file_size(cut) / 3);
  const std::string message = errorOf(cut);
  EXPECT_NE(message.find(cut), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(RtStruct, OnTheReferencedSeriesGridEachContourFillsItsOwnSlice) {
  // A structure set drawn on ct-3slice: its series UID referenced, a square on each CT slice.
  DcmFileFormat ct;
  ASSERT_TRUE(ct.loadFile(dataPath("dcmqi_ct3slice/ct-3slice/01.dcm").c_str()).good());
  OFString series;
  ct.getDataset()->findAndGetOFString(DCM_SeriesInstanceUID, series);
  const Volume image = readVolume(dataPath("dcmqi_ct3slice/ct-3slice"));
  TinyRoi roi;
  roi.name = "square";
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d ras = image.geometry().voxelToRas(100, 200, k);
    // 10 x 20 voxels of 0.810547 mm, corners between voxel centres (LPS = RAS with x, y negated).
    const double x0 = -ras.x() - 0.4, y0 = -ras.y() - 0.4;
    roi.contours.push_back(square(x0, y0, x0 + 10 * 0.810547, y0 + 20 * 0.810547, ras.z()));
  }
  ScratchDir dir;
  writeTinyRtStruct({roi}, dir.file("rs.dcm"), series.c_str());
  RtStructOptions o;
  o.reference = dataPath("dcmqi_ct3slice/ct-3slice");
  const Volume v = readRtStruct(dir.file("rs.dcm"), o);
  ASSERT_EQ(v.dims(), image.dims());
  EXPECT_LT(matrixDifference(v.geometry().ijkToRas, image.geometry().ijkToRas), 1e-9);
  std::int64_t inside = 0;
  for (std::int64_t i = 0; i < v.numVoxels(); ++i) inside += v.valueAsDouble(i) == 1;
  EXPECT_EQ(inside, 3 * 10 * 20);
  EXPECT_EQ(v.valueAsDouble(v.index(100, 200, 0)), 1);
  EXPECT_EQ(v.valueAsDouble(v.index(109, 219, 2)), 1);
  EXPECT_EQ(v.valueAsDouble(v.index(110, 219, 2)), 0);
}

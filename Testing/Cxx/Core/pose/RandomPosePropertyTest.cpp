// Property-based test of whole frames (issue 10, item 5): random poses of the phantom's four limbs
// — any axis, up to 150 degrees about the joint, plus a drift of up to 40 mm that pulls a limb off
// its joint or into the body — posed at full resolution. Whatever the pose, every frame keeps:
// finite vertex positions, tet maps and displacement field; only labels of the input, in G and S;
// one label per voxel, in both maps alike (the body's voxels of G are those of S); and a report
// that accounts for every input label, whose voxel counts are the output's own.
// The seed is fixed so a failure reproduces; the poses are printed.
#include "TestPaths.h"
#include "TestPoses.h"

#include "repose/phantom/Phantom.h"
#include "repose/pose/PoseFrame.h"
#include "repose/pose/PoseRig.h"
#include "repose/volume/LabelStatistics.h"
#include "repose/volume/TissueTable.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <set>

using namespace repose;
using namespace repose::test;

namespace {

constexpr int kFrames = 6;

// The walk's groups (both legs, both arms, the rest fixed) with kFrames random keyframes.
Pose randomPoses(unsigned seed) {
  PhantomOptions po;
  po.voxelMm = 8;
  Pose pose = suitePose("walk", Phantom(po));
  pose.keyframes.clear();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int f = 0; f < kFrames; ++f) {
    PoseKeyframe k;
    k.name = "random" + std::to_string(f);
    for (const PoseGroup& g : pose.groups) {
      if (g.fixed) continue;
      PoseTransform t = g.transform;  // keeps the group's joint pivot
      Eigen::Vector3d axis(unit(rng), unit(rng), unit(rng));
      if (axis.norm() < 1e-3) axis = Eigen::Vector3d::UnitX();
      t.axis = axis.normalized();
      t.angleDeg = 150 * unit(rng);
      t.translation = 40 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) / std::sqrt(3.0);
      k.transforms.emplace_back(g.name, t);
    }
    pose.keyframes.push_back(k);
  }
  return pose;
}

std::set<int> valuesOf(const Volume& v) {
  std::set<int> s;
  for (const LabelCount& c : countLabels(v)) s.insert(c.value);
  return s;
}

}  // namespace

TEST(RandomPoseProperties, EveryFrameIsFiniteLabelledOnceAndFullyReported) {
  PhantomOptions o;
  o.voxelMm = 4;
  Volume organs, parts;
  std::tie(organs, parts) = Phantom(o).makeVolumes();
  const TissueTable tissues =
      readTissueTable(std::string(REPOSE_SOURCE_DIR) + "/Resources/Tissues/phantom.csv");
  RigSettings settings;
  settings.cageVertices = 200;
  settings.threads = 2;
  for (const auto& [label, tissue] : tissues)
    if (tissue.rigid) settings.rigidLabels.push_back(label);
  const unsigned seed = 20261123;
  const Pose pose = randomPoses(seed);
  std::cout << "random poses (seed " << seed << "):\n" << poseToJson(pose) << "\n";
  const PoseRig rig(buildRigGeometry(parts, {}, settings, {}, &organs), pose, parts.labels(), 2);
  ASSERT_EQ(rig.frameCount(), std::size_t(kFrames));

  const std::set<int> organValues = valuesOf(organs), partValues = valuesOf(parts);
  // At rest the maps agree voxel for voxel on where the body is: what every frame must keep.
  for (std::int64_t v = 0; v < organs.numVoxels(); ++v)
    ASSERT_EQ(organs.valueAsDouble(v) != 0, parts.valueAsDouble(v) != 0) << "rest voxel " << v;

  PoseFrameOptions fo;
  fo.tissues = &tissues;
  fo.threads = 2;
  for (std::size_t f = 0; f < rig.frameCount(); ++f) {
    SCOPED_TRACE("frame " + rig.frameName(f));
    const PoseRig::Frame frame = rig.frame(f);
    ASSERT_TRUE(frame.deformed.allFinite());
    ASSERT_TRUE(frame.cage.allFinite());
    for (const Eigen::Matrix3d& B : frame.tetMaps) ASSERT_TRUE(B.allFinite());

    const PosedFrame posed = poseFrame(rig, f, organs, parts, fo);
    for (const float x : posed.field) ASSERT_TRUE(std::isfinite(x));
    ASSERT_EQ(posed.field.size(), std::size_t(3 * posed.grid.numVoxels()));

    // One label per voxel, the same body in both maps, only the input's labels.
    std::int64_t body = 0, mismatched = 0;
    std::map<int, std::int64_t> organVoxels;
    for (std::int64_t v = 0; v < posed.grid.numVoxels(); ++v) {
      const int g = int(posed.organs.valueAsDouble(v)), s = int(posed.parts.valueAsDouble(v));
      ASSERT_TRUE(organValues.count(g) || g == 0) << "G value " << g << " at voxel " << v;
      ASSERT_TRUE(partValues.count(s) || s == 0) << "S value " << s << " at voxel " << v;
      mismatched += (g != 0) != (s != 0);
      body += g != 0;
      ++organVoxels[g];
    }
    EXPECT_EQ(mismatched, 0) << "voxels in the body of one map only";
    EXPECT_GT(body, 0);

    // The report: every input label, with the output's own counts and a finite change.
    const nlohmann::json report = nlohmann::json::parse(posed.reportJson);
    std::set<int> reported;
    std::int64_t reportedVoxels = 0;
    for (const auto& row : report["labels"]) {
      const int value = row["value"].get<int>();
      reported.insert(value);
      ASSERT_TRUE(std::isfinite(row["change_percent"].get<double>())) << value;
      EXPECT_EQ(row["voxels_after"].get<std::int64_t>(), organVoxels[value]) << "label " << value;
      reportedVoxels += row["voxels_after"].get<std::int64_t>();
    }
    for (const int value : organValues) {
      if (value != 0) {
        EXPECT_TRUE(reported.count(value)) << "label " << value << " unreported";
      }
    }
    EXPECT_EQ(reportedVoxels, body);
    const double bodyChange = report["body"]["volume_change_percent"].get<double>();
    ASSERT_TRUE(std::isfinite(bodyChange));
    std::cout << rig.frameName(f) << ": body " << bodyChange << " %, worst label "
              << report["quality"]["labels_within_1_percent"]["worst_change_percent"] << " %, "
              << report["mesh"]["inverted_tets"] << " inverted tets\n";
  }
}

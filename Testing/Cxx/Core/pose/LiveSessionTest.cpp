// A live session (pose/LiveSession.h) on the 8 mm phantom, elbow90 rigged: one frame per pose
// change from parsed poses, the views' slices in one call equal to the same slices asked for one
// by one, layers the session lacks left empty, the prediction computed once per frame, the
// joints where the frame puts them, and a pose with other groups refused.
#include "TestPoses.h"

#include "repose/phantom/Phantom.h"
#include "repose/pose/LivePredictionWorker.h"
#include "repose/pose/LiveSession.h"
#include "repose/pose/PoseEdit.h"
#include "repose/pose/PoseJob.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace repose;
using namespace repose::test;

namespace {

struct Body {
  std::shared_ptr<const Volume> organs, parts;
  std::optional<Skeleton> skeleton;
  std::unique_ptr<PoseJob> job;
  std::unique_ptr<LiveSession> session;

  Body() {
    PhantomOptions o;
    o.voxelMm = 8;
    const Phantom phantom(o);
    auto maps = phantom.makeVolumes();
    organs = std::make_shared<const Volume>(std::move(maps.first));
    parts = std::make_shared<const Volume>(std::move(maps.second));
    skeleton = phantom.skeleton();
    PoseJobRequest request;
    request.organsName = "G.nii.gz";
    request.skeleton = skeleton;
    request.settings.cageVertices = 200;
    request.settings.threads = 2;
    job = std::make_unique<PoseJob>(readPoseFile(suitePosePath("elbow90")), *organs, *parts,
                                    std::move(request));
    LiveInputs inputs;
    inputs.labels = organs;
    inputs.partLabels = parts->labels();
    inputs.skeleton = skeleton;
    session = std::make_unique<LiveSession>(*job, job->buildGeometry(), inputs);
  }
};

Body& body() {
  static Body b;
  return b;
}

// The job's pose with the forearm turned `deg` about its elbow.
Pose elbowAt(double deg) {
  Pose pose = body().job->userPose();
  setGroupTurnAngle(pose, "left forearm and hand", 0, 0, deg);
  return pose;
}

bool sameVoxels(const Volume& a, const Volume& b) {
  if (a.dims() != b.dims() || a.numVoxels() != b.numVoxels()) return false;
  for (std::int64_t v = 0; v < a.numVoxels(); ++v)
    if (a.valueAsDouble(v) != b.valueAsDouble(v)) return false;
  return true;
}

}  // namespace

TEST(LiveSession, AFramePerPoseAndTheSlicesOfItInOneCall) {
  LiveSession& live = *body().session;
  EXPECT_FALSE(live.hasFrame());
  EXPECT_TRUE(live.slices({{}}).at(0).voxels == std::nullopt);  // nothing before a frame
  live.setPose(elbowAt(0), 0);
  ASSERT_TRUE(live.hasFrame());
  const Eigen::MatrixX3d atRest = live.deformed();
  live.setPose(elbowAt(90), 0);
  EXPECT_GT(live.frameMilliseconds(), 0);
  // The forearm moved; the box holds the rest and the posed body.
  EXPECT_GT((live.deformed() - atRest).rowwise().norm().maxCoeff(), 50);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(live.lo()[k], live.deformed().col(k).minCoeff());
    EXPECT_GE(live.hi()[k], live.rig().mesh().vertices.col(k).maxCoeff());
  }

  // The three views' labels in one call are the slices asked for one by one.
  using Layer = LiveSession::Layer;
  const Eigen::Vector3d c = live.restCentre();
  std::vector<LiveSession::SliceRequest> requests;
  for (int o = 0; o < 3; ++o)
    requests.push_back({Layer::Labels, SliceOrientation(o), c[o == 0 ? 2 : o == 1 ? 1 : 0], 64});
  requests.push_back({Layer::Image, SliceOrientation::Coronal, c.y(), 64});  // no image
  requests.push_back({Layer::Parts, SliceOrientation::Coronal, c.y(), 64});  // not given yet
  const std::vector<LiveSession::Slice> all = live.slices(requests);
  ASSERT_EQ(all.size(), requests.size());
  for (int o = 0; o < 3; ++o) {
    ASSERT_TRUE(all[o].voxels) << o;
    const LiveSession::Slice alone = live.slices({requests[std::size_t(o)]}).at(0);
    ASSERT_TRUE(alone.voxels);
    EXPECT_TRUE(sameVoxels(*all[o].voxels, *alone.voxels)) << "orientation " << o;
    // One voxel thick; 64 pixels across the box's larger in-plane side.
    const auto& d = all[o].voxels->dims();
    EXPECT_EQ(d[2], 1);
    EXPECT_EQ(std::max(d[0], d[1]), 64);
  }
  EXPECT_FALSE(all[3].voxels);
  EXPECT_FALSE(all[4].voxels);
  // S for the outlines once given: on the labels' grid, its parts where the labels have tissue.
  live.setParts(body().parts);
  const LiveSession::Slice parts = live.slices({requests[4]}).at(0);
  ASSERT_TRUE(parts.voxels);
  ASSERT_EQ(parts.voxels->dims(), all[1].voxels->dims());
  for (std::int64_t v = 0; v < parts.voxels->numVoxels(); ++v)
    ASSERT_EQ(parts.voxels->valueAsDouble(v) != 0, all[1].voxels->valueAsDouble(v) != 0) << v;
}

TEST(LiveSession, PredictionJointsAndQueries) {
  LiveSession& live = *body().session;
  live.setPose(elbowAt(0), 0);
  const LivePrediction& rest = live.prediction();
  EXPECT_NEAR(rest.bodyChangePercent, 0, 1e-6);
  EXPECT_TRUE(rest.met) << rest.missed;
  EXPECT_EQ(&live.prediction(), &rest);  // once per frame
  // At rest every joint is where the skeleton puts it.
  const std::vector<LiveJoint> joints = live.joints();
  ASSERT_EQ(joints.size(), body().skeleton->joints.size());
  for (std::size_t j = 0; j < joints.size(); ++j)
    EXPECT_LT((joints[j].centre - body().skeleton->joints[j].centre).norm(), 1e-6)
        << joints[j].name;
  // Turned, the left wrist moves with the forearm; the right one stays.
  live.setPose(elbowAt(90), 0);
  const std::vector<LiveJoint> turned = live.joints();
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const double moved = (turned[j].centre - joints[j].centre).norm();
    if (joints[j].name == "wrist_left") {
      EXPECT_GT(moved, 50);
    }
    if (joints[j].name == "wrist_right") {
      EXPECT_LT(moved, 1);
    }
  }
  EXPECT_FALSE(live.groupVertices("left forearm and hand").empty());
  EXPECT_TRUE(live.groupVertices("no such group").empty());
  const Label* forearm = nullptr;
  for (const Label& l : body().parts->labels().labels())
    if (l.name == "forearm_left") forearm = &l;
  ASSERT_TRUE(forearm);
  EXPECT_FALSE(live.cageVerticesOfPart(forearm->value).empty());
  EXPECT_EQ(live.partName(forearm->value), "forearm_left");
  EXPECT_EQ(live.partName(9999), "9999");
  // G at rest under a point: its voxel's label; outside the grid -1.
  const Volume& G = *body().organs;
  const std::int64_t i = G.dims()[0] / 2, j = G.dims()[1] / 2, k = G.dims()[2] / 2;
  const Eigen::Vector3d ras = G.geometry().voxelToRas(double(i), double(j), double(k));
  EXPECT_EQ(live.restLabelAt(ras), int(G.valueAsDouble(G.index(i, j, k))));
  EXPECT_EQ(live.restLabelAt(Eigen::Vector3d(1e6, 0, 0)), -1);
  EXPECT_FALSE(live.imageWindow());  // no image given
}

TEST(LiveSession, APoseWithOtherGroupsIsRefusedAndTheFrameStays) {
  LiveSession& live = *body().session;
  live.setPose(elbowAt(30), 0);
  const Eigen::MatrixX3d before = live.deformed();
  Pose other = elbowAt(30);
  other.groups.pop_back();  // no fixed rest
  EXPECT_FALSE(live.solves(other));
  EXPECT_TRUE(live.solves(elbowAt(60)));
  EXPECT_THROW(live.setPose(other, 0), Error);
  EXPECT_TRUE(live.deformed().isApprox(before));
}

TEST(LiveSession, AnImageLayerAndItsWindow) {
  LiveInputs inputs;
  inputs.labels = body().organs;
  inputs.image = std::make_shared<const Volume>(syntheticCT(*body().organs));
  inputs.partLabels = body().parts->labels();
  LiveSession live(*body().job, body().job->buildGeometry(), inputs);
  live.setPose(elbowAt(45), 0);
  const auto window = live.imageWindow();
  ASSERT_TRUE(window);
  EXPECT_EQ(window->window, 400);  // Hounsfield units: the soft-tissue window
  EXPECT_EQ(window->level, 40);
  const Eigen::Vector3d c = live.restCentre();
  const auto s = live.slices({{LiveSession::Layer::Labels, SliceOrientation::Coronal, c.y(), 48},
                              {LiveSession::Layer::Image, SliceOrientation::Coronal, c.y(), 48}});
  ASSERT_TRUE(s[0].voxels && s[1].voxels);
  ASSERT_EQ(s[0].voxels->dims(), s[1].voxels->dims());
  // Air (the image's background, as the export has it) beyond the body: the slice's corners and
  // nearly every voxel without a label (the rest are the skin's edge, sampled trilinearly); the
  // CT's own values inside.
  const Volume &labels = *s[0].voxels, &ct = *s[1].voxels;
  const std::int64_t nx = ct.dims()[0], ny = ct.dims()[1];
  for (const std::int64_t corner : {std::int64_t(0), nx - 1, (ny - 1) * nx, ny * nx - 1})
    EXPECT_EQ(ct.valueAsDouble(corner), -1000) << corner;
  std::int64_t empty = 0, air = 0, tissue = 0, dense = 0;
  for (std::int64_t v = 0; v < labels.numVoxels(); ++v) {
    const bool labelled = labels.valueAsDouble(v) != 0;
    empty += !labelled, tissue += labelled;
    air += !labelled && ct.valueAsDouble(v) == -1000;
    dense += labelled && ct.valueAsDouble(v) > -900;
  }
  ASSERT_GT(empty, 0);
  ASSERT_GT(tissue, 0);
  EXPECT_GT(double(air), 0.9 * double(empty));
  EXPECT_GT(double(dense), 0.9 * double(tissue));
}

// The prediction off the caller's thread (LivePredictionWorker, what the workbench's panel uses
// when a drag ends): the same figures as prediction(), while the session goes on solving frames;
// a newer frame's job cancels the older one, whose answer is never given; a set cancel flag
// stops a job with nothing.
TEST(LiveSession, PredictionJobsRunOffTheCallersThreadAndANewerFrameCancelsTheOlder) {
  LiveSession& live = *body().session;
  live.setPose(elbowAt(90), 0);
  const LivePrediction expected = live.prediction();
  LivePredictionWorker worker;
  EXPECT_EQ(worker.state(1), LivePredictionWorker::State::None);
  worker.start(1, live.predictionJob());
  live.setPose(elbowAt(45), 0);  // the session solves on while the job runs on its own copy
  const std::optional<LivePrediction> got = worker.wait(1);
  ASSERT_TRUE(got);
  EXPECT_EQ(worker.state(1), LivePredictionWorker::State::Ready);
  // The same computation on another thread (1e-6: a multithreaded BLAS may sum in another order).
  EXPECT_NEAR(got->bodyChangePercent, expected.bodyChangePercent, 1e-6);
  EXPECT_EQ(got->worstPart, expected.worstPart);
  EXPECT_EQ(got->met, expected.met);

  worker.start(2, live.predictionJob());
  worker.start(3, live.predictionJob());  // frame 2's job is cancelled
  EXPECT_EQ(worker.state(2), LivePredictionWorker::State::None);
  EXPECT_FALSE(worker.ready(2));
  const std::optional<LivePrediction> third = worker.wait(3);
  ASSERT_TRUE(third);
  EXPECT_NEAR(third->bodyChangePercent, live.prediction().bodyChangePercent, 1e-6);
  // The two frames predict apart: the first job predicted the frame it copied, not the session's.
  EXPECT_GT(std::fabs(third->bodyChangePercent - expected.bodyChangePercent), 1e-5);

  std::atomic<bool> cancelled{true};
  EXPECT_FALSE(live.predictionJob()(&cancelled));
  worker.cancel();
  EXPECT_EQ(worker.state(3), LivePredictionWorker::State::None);
}

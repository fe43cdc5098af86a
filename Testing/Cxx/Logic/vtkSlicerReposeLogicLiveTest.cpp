// Live posing on the 8 mm phantom: a pose node prepared once on the worker, then every edit of it
// re-solves the frame on this thread; the live slice through the left forearm shows G as it is at
// rest when the elbow is straight, changes when it bends, and undo brings back the same voxels.
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkSlicerReposeLogic.h"

#include "TestPaths.h"

#include <repose/io/VolumeIO.h>
#include <repose/phantom/Phantom.h>

#include <gtest/gtest.h>

#include <vtkNew.h>
#include <vtkPointData.h>

#include <cstring>

using namespace repose::test;

namespace {

std::vector<std::uint8_t> voxels(vtkImageData* image) {
  vtkDataArray* a = image->GetPointData()->GetScalars();
  const auto* p = static_cast<const std::uint8_t*>(a->GetVoidPointer(0));
  return {p, p + a->GetNumberOfTuples()};
}

}  // namespace

TEST(vtkSlicerReposeLogicLive, EditsResolveTheFrameAndTheSlicesFollow) {
  ScratchDir dir("live");
  repose::PhantomOptions po;
  po.voxelMm = 8;
  const auto [organs, parts] = repose::Phantom(po).makeVolumes();
  repose::writeVolume(organs, dir.file("G.nii.gz"));
  repose::writeVolume(parts, dir.file("S.nii.gz"));

  vtkNew<vtkSlicerReposeLogic> logic;
  auto* seg = logic->AddSegmentation(dir.file("G.nii.gz"), dir.file("S.nii.gz"));
  ASSERT_TRUE(seg) << logic->GetLastErrorMessage();
  auto* pose = logic->AddPose(std::string(REPOSE_SOURCE_DIR) + "/bench/poses/elbow90.pose.json");
  ASSERT_TRUE(pose) << logic->GetLastErrorMessage();
  // Before the rig there is nothing to prepare; without a live pose no slice.
  EXPECT_FALSE(logic->StartLivePose(pose));
  EXPECT_FALSE(logic->ComputeLiveSlice(1, 0, 64));
  ASSERT_TRUE(logic->StartBuildRig(seg, pose)) << logic->GetLastErrorMessage();
  ASSERT_EQ(logic->WaitForJob(), vtkSlicerReposeLogic::JobSucceeded);
  ASSERT_TRUE(logic->StartLivePose(pose)) << logic->GetLastErrorMessage();
  EXPECT_EQ(logic->GetLivePose(), nullptr);  // committed only by WaitForJob
  ASSERT_EQ(logic->WaitForJob(), vtkSlicerReposeLogic::JobSucceeded);
  ASSERT_EQ(logic->GetLivePose(), pose);
  ASSERT_TRUE(logic->GetLiveCage() && logic->GetLiveBodySurface());
  EXPECT_GT(logic->GetLiveBodySurface()->GetNumberOfCells(), 100);
  EXPECT_GT(logic->GetLiveFrameMilliseconds(), 0.0);

  // The coronal plane through the elbow's pivot (A = -14 mm).
  const double y = -14;
  double ms = 0;
  vtkSmartPointer<vtkImageData> bent = logic->ComputeLiveSlice(1, y, 128, &ms);
  ASSERT_TRUE(bent);
  EXPECT_GT(ms, 0.0);
  int dims[3];
  bent->GetDimensions(dims);
  EXPECT_LT(dims[0], 128);  // R (i) by S (j), square pixels, the body taller than wide
  EXPECT_EQ(dims[1], 128);
  EXPECT_EQ(dims[2], 1);  // one voxel thick along A

  // Straighten the elbow: the pose node changes, the frame re-solves by itself.
  const unsigned long before = logic->GetMTime();
  ASSERT_TRUE(logic->SetPoseGroupTransform(pose, "left forearm and hand", {1, 0, 0}, 0,
                                           {-176, -14, 806}, {0, 0, 0}))
      << logic->GetLastErrorMessage();
  EXPECT_GT(logic->GetMTime(), before);
  vtkSmartPointer<vtkImageData> straight = logic->ComputeLiveSlice(1, y, 128);
  ASSERT_TRUE(straight);
  const std::vector<std::uint8_t> b = voxels(bent), s = voxels(straight);
  ASSERT_EQ(b.size(), s.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < b.size(); ++i) differ += b[i] != s[i];
  EXPECT_GT(differ, 50u);  // the forearm left the plane

  // At rest the slice is G sampled on the plane (nearest voxel), up to the mesh's boundary.
  std::size_t agree = 0, body = 0;
  for (int j = 0; j < dims[1]; ++j)
    for (int i = 0; i < dims[0]; ++i) {
      double ras[3];
      bent->TransformIndexToPhysicalPoint(i, j, 0, ras);
      EXPECT_NEAR(ras[1], y, 1e-9);
      const Eigen::Vector3d ijk = organs.geometry().rasToVoxel({ras[0], ras[1], ras[2]});
      const std::int64_t a = std::lround(ijk.x()), c = std::lround(ijk.y()),
                         d = std::lround(ijk.z());
      if (a < 0 || c < 0 || d < 0 || a >= organs.dims()[0] || c >= organs.dims()[1] ||
          d >= organs.dims()[2])
        continue;
      const int expected = int(organs.valueAsDouble(organs.index(a, c, d)));
      const int shown = s[std::size_t(i + dims[0] * j)];
      if (expected == 0 && shown == 0) continue;
      ++body;
      agree += expected == shown;
    }
  EXPECT_GT(body, 500u);
  EXPECT_GE(double(agree), 0.9 * double(body));

  // Undo: the bent elbow again, voxel for voxel.
  ASSERT_TRUE(logic->Undo());
  EXPECT_EQ(voxels(logic->ComputeLiveSlice(1, y, 128)), b);
  logic->StopLivePose();
  EXPECT_EQ(logic->GetLivePose(), nullptr);
  EXPECT_FALSE(logic->ComputeLiveSlice(1, y, 128));
}

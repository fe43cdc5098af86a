// A saved scene reopens with the panel as it was: every result a job left (the rig's summary and
// tissue table, the export's report and warnings, the refinement's rounds) lives in a node, and
// the parameter node itself is saved with the scene. Save, reopen in a new logic, compare.
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkSlicerReposeLogic.h"

#include "TestPaths.h"

#include <repose/io/VolumeIO.h>
#include <repose/phantom/Phantom.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <vtkImageData.h>
#include <vtkNew.h>

#include <filesystem>

using namespace repose::test;

namespace {

// Everything the panel shows of a logic's state beyond the scene's nodes themselves.
struct PanelState {
  nlohmann::json parameters;
  std::string rigSummary, refinementSummary;
  std::vector<int> refinementVertices;
  std::vector<double> refinementErrors;
  std::vector<std::string> quality, labelChanges, warnings, movableGroups;
  std::string outputNodeID;
};

PanelState panelOf(vtkSlicerReposeLogic* logic) {
  PanelState s;
  s.parameters = nlohmann::json::parse(logic->GetParameterNode()->WriteJSON());
  vtkSlicerReposeJobsLogic* jobs = logic->GetJobs();
  s.rigSummary = jobs->GetLastRigSummary();
  s.refinementSummary = jobs->GetLastRefinementSummary();
  s.refinementVertices = jobs->GetLastRefinementVertices();
  s.refinementErrors = jobs->GetLastRefinementMaxErrors();
  for (const auto& q : jobs->GetLastPoseQuality())
    s.quality.push_back(q.name + "|" + q.measured + "|" + q.target + "|" + (q.met ? "met" : "no"));
  for (const auto& c : jobs->GetLastPoseLabelChanges())
    s.labelChanges.push_back(c.name + "|" + std::to_string(c.changePercent));
  s.warnings = jobs->GetLastPoseWarnings();
  if (vtkMRMLReposeSegmentationNode* posed = jobs->GetLastPosedSegmentation())
    s.outputNodeID = posed->GetID();
  auto* pose = vtkMRMLReposePoseNode::SafeDownCast(
      logic->GetScene()->GetNodeByID(logic->GetParameterNode()->GetActivePoseNodeID()));
  s.movableGroups = logic->GetPoseEdits()->GetPoseSummary(pose).movableGroups;
  return s;
}

}  // namespace

TEST(vtkSlicerReposeLogicScene, ASavedSceneReopensWithThePanelAsItWas) {
  ScratchDir dir("panel-scene");
  repose::PhantomOptions po;
  po.voxelMm = 8;
  po.armsResting = true;
  po.labels = repose::PhantomLabelling::Icrp110;
  const std::string G = dir.file("AF.nii.gz");
  repose::writeVolume(repose::Phantom(po).makeVolumes().first, G);

  vtkNew<vtkSlicerReposeLogic> logic;
  vtkMRMLReposeParametersNode* p = logic->GetParameterNode();
  vtkSlicerReposeJobsLogic* jobs = logic->GetJobs();
  // Every kind of job the panel runs: rig from the organ map, the rig, live posing, a refinement
  // for the frame, and an export.
  ASSERT_TRUE(jobs->StartRigFromOrganMap(G, dir.file("rig"))) << logic->GetLastErrorMessage();
  ASSERT_EQ(jobs->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  EXPECT_EQ(p->GetTissueTablePath(), dir.file("rig") + "/tissues.csv");
  auto* seg = logic->AddSegmentation(G, p->GetBodyPartMapPath());
  ASSERT_TRUE(seg) << logic->GetLastErrorMessage();
  auto* pose = logic->AddPose(std::string(REPOSE_SOURCE_DIR) + "/bench/poses/elbow90.pose.json");
  ASSERT_TRUE(pose) << logic->GetLastErrorMessage();
  ASSERT_TRUE(jobs->StartBuildRig(seg, pose)) << logic->GetLastErrorMessage();
  ASSERT_EQ(jobs->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  ASSERT_TRUE(logic->GetLive()->StartLivePose(pose)) << logic->GetLastErrorMessage();
  ASSERT_EQ(jobs->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded);
  ASSERT_TRUE(jobs->StartRefineMesh(pose, 1)) << logic->GetLastErrorMessage();
  ASSERT_EQ(jobs->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  ASSERT_TRUE(jobs->StartApplyPose(pose, dir.file("export"))) << logic->GetLastErrorMessage();
  ASSERT_EQ(jobs->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  // The panel's own choices.
  const int state = p->StartModify();
  p->SetInputSegmentationNodeID(seg->GetID());
  p->SetActivePoseNodeID(pose->GetID());
  p->SetActiveGroup("left forearm and hand");
  p->SetLabelOpacity(0.35);
  p->SetShowBodyParts(true);
  p->SetShowJoints(false);
  p->SetSelectedCageVertices({3, 5, 8});
  p->SetCageVertexCount(333);
  p->SetOutputFolder(dir.file("export"));
  p->EndModify(state);

  const PanelState before = panelOf(logic);
  // What there is to compare: each result is there before the save.
  ASSERT_FALSE(before.rigSummary.empty());
  ASSERT_FALSE(before.refinementSummary.empty());
  ASSERT_EQ(before.refinementVertices.size(), 1u);
  ASSERT_FALSE(before.quality.empty());
  ASSERT_FALSE(before.labelChanges.empty());
  ASSERT_FALSE(before.outputNodeID.empty());
  const std::string folder = dir.file("scene");
  ASSERT_TRUE(logic->SaveScene(folder)) << logic->GetLastErrorMessage();

  vtkNew<vtkSlicerReposeLogic> reopened;
  ASSERT_TRUE(reopened->OpenScene(folder)) << reopened->GetLastErrorMessage();
  ASSERT_EQ(reopened->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << reopened->GetLastErrorMessage();  // the active pose goes live
  const PanelState after = panelOf(reopened);
  // The inputs now name the folder's files (G, S and the pose as the scene holds them); every
  // other field is as it was.
  nlohmann::json a = after.parameters, b = before.parameters;
  for (const char* moved : {"InputSegmentationPath", "BodyPartMapPath", "ImagePath", "PosePath"}) {
    const std::string path = a[moved];
    if (!path.empty()) {
      EXPECT_TRUE(std::filesystem::exists(path)) << moved << ": " << path;
    }
    EXPECT_EQ(path.rfind(folder, 0), path.empty() ? std::string::npos : 0u) << moved;
    a.erase(moved);
    b.erase(moved);
  }
  EXPECT_EQ(a, b);
  EXPECT_EQ(after.rigSummary, before.rigSummary);
  EXPECT_EQ(after.refinementSummary, before.refinementSummary);
  EXPECT_EQ(after.refinementVertices, before.refinementVertices);
  EXPECT_EQ(after.refinementErrors, before.refinementErrors);
  EXPECT_EQ(after.quality, before.quality);
  EXPECT_EQ(after.labelChanges, before.labelChanges);
  EXPECT_EQ(after.warnings, before.warnings);
  EXPECT_EQ(after.outputNodeID, before.outputNodeID);
  EXPECT_EQ(after.movableGroups, before.movableGroups);
  EXPECT_EQ(reopened->GetLive()->GetLivePose()->GetID(), pose->GetID());
  // The posed segmentation is the export's, voxel for voxel.
  vtkImageData* x = jobs->GetLastPosedSegmentation()->GetLabelMap();
  vtkImageData* y = reopened->GetJobs()->GetLastPosedSegmentation()->GetLabelMap();
  ASSERT_TRUE(x && y);
  EXPECT_EQ(x->GetNumberOfPoints(), y->GetNumberOfPoints());
}

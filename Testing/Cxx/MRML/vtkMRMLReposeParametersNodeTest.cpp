// Tests of vtkMRMLReposeParametersNode: set/get, clamping, Modified only on change, copy, JSON
// round trip and PrintSelf, the node test every Slicer module has.
#include "vtkMRMLReposeParametersNode.h"

#include <gtest/gtest.h>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkNew.h>

#include <cmath>
#include <limits>
#include <sstream>

namespace {

// Counts ModifiedEvents of one object.
struct ModifiedCounter {
  explicit ModifiedCounter(vtkObject* object) {
    callback->SetClientData(&count);
    callback->SetCallback([](vtkObject*, unsigned long, void* clientData, void*) {
      ++*static_cast<int*>(clientData);
    });
    object->AddObserver(vtkCommand::ModifiedEvent, callback);
  }
  int count = 0;
  vtkNew<vtkCallbackCommand> callback;
};

void fillNonDefault(vtkMRMLReposeParametersNode* node) {
  node->SetInputSegmentationNodeID("vtkMRMLSegmentationNode1");
  node->SetInputSegmentationPath("/data/body seg.nii.gz");
  node->SetBodyPartMapPath("/data/limbs.nrrd");
  node->SetImagePath("/data/ct.nii.gz");
  node->SetCageVertexCount(420);
  node->SetCageDilationMm(7.25);
  node->SetTransferMeshSizeMm(12.5);
  node->SetOutputMemoryBudgetMB(2048);
  node->SetOutputFolder("/out/\"quoted\" folder");
  node->SetPosePath("/poses/elbow90.pose.json");
  node->SetActivePoseNodeID("vtkMRMLReposePoseNode1");
  node->SetActiveGroup("left forearm and hand");
  node->SetSelectedCageVertices({12, 3, 7, 3});
  node->SetSelectedBodyPart(5);
  node->SetLabelOpacity(0.35);
  node->SetShowBodyParts(true);
  node->SetShowJoints(false);
}

void expectEqualFields(vtkMRMLReposeParametersNode* a, vtkMRMLReposeParametersNode* b) {
  EXPECT_EQ(a->GetInputSegmentationNodeID(), b->GetInputSegmentationNodeID());
  EXPECT_EQ(a->GetInputSegmentationPath(), b->GetInputSegmentationPath());
  EXPECT_EQ(a->GetBodyPartMapPath(), b->GetBodyPartMapPath());
  EXPECT_EQ(a->GetImagePath(), b->GetImagePath());
  EXPECT_EQ(a->GetCageVertexCount(), b->GetCageVertexCount());
  EXPECT_EQ(a->GetCageDilationMm(), b->GetCageDilationMm());
  EXPECT_EQ(a->GetTransferMeshSizeMm(), b->GetTransferMeshSizeMm());
  EXPECT_EQ(a->GetOutputMemoryBudgetMB(), b->GetOutputMemoryBudgetMB());
  EXPECT_EQ(a->GetOutputFolder(), b->GetOutputFolder());
  EXPECT_EQ(a->GetPosePath(), b->GetPosePath());
  EXPECT_EQ(a->GetActivePoseNodeID(), b->GetActivePoseNodeID());
  EXPECT_EQ(a->GetActiveGroup(), b->GetActiveGroup());
  EXPECT_EQ(a->GetSelectedCageVertices(), b->GetSelectedCageVertices());
  EXPECT_EQ(a->GetSelectedBodyPart(), b->GetSelectedBodyPart());
  EXPECT_EQ(a->GetLabelOpacity(), b->GetLabelOpacity());
  EXPECT_EQ(a->GetShowBodyParts(), b->GetShowBodyParts());
  EXPECT_EQ(a->GetShowJoints(), b->GetShowJoints());
}

const char* const kFieldNames[] = {"InputSegmentationNodeID",
                                   "InputSegmentationPath",
                                   "BodyPartMapPath",
                                   "ImagePath",
                                   "CageVertexCount",
                                   "CageDilationMm",
                                   "TransferMeshSizeMm",
                                   "OutputMemoryBudgetMB",
                                   "OutputFolder",
                                   "PosePath",
                                   "ActivePoseNodeID",
                                   "ActiveGroup",
                                   "SelectedCageVertices",
                                   "SelectedBodyPart",
                                   "LabelOpacity",
                                   "ShowBodyParts",
                                   "ShowJoints"};

}  // namespace

TEST(vtkMRMLReposeParametersNode, DefaultsAndSetGet) {
  vtkNew<vtkMRMLReposeParametersNode> node;
  EXPECT_EQ(node->GetCageVertexCount(), 300);
  EXPECT_EQ(node->GetCageDilationMm(), 10.0);
  EXPECT_EQ(node->GetTransferMeshSizeMm(), 0.0);
  EXPECT_EQ(node->GetOutputMemoryBudgetMB(), 0);  // automatic: half the physical memory
  EXPECT_FALSE(node->GetShowBodyParts());         // the labels alone until asked
  EXPECT_TRUE(node->GetShowJoints());
  EXPECT_TRUE(node->GetInputSegmentationPath().empty());
  fillNonDefault(node);
  EXPECT_EQ(node->GetInputSegmentationNodeID(), "vtkMRMLSegmentationNode1");
  EXPECT_EQ(node->GetInputSegmentationPath(), "/data/body seg.nii.gz");
  EXPECT_EQ(node->GetCageVertexCount(), 420);
  EXPECT_EQ(node->GetCageDilationMm(), 7.25);
  EXPECT_EQ(node->GetOutputFolder(), "/out/\"quoted\" folder");
}

TEST(vtkMRMLReposeParametersNode, ClampsToRanges) {
  vtkNew<vtkMRMLReposeParametersNode> node;
  for (int v : {-5, 0, 49}) {
    node->SetCageVertexCount(v);
    EXPECT_EQ(node->GetCageVertexCount(), 50) << v;
  }
  for (int v : {2001, 100000, std::numeric_limits<int>::max()}) {
    node->SetCageVertexCount(v);
    EXPECT_EQ(node->GetCageVertexCount(), 2000) << v;
  }
  node->SetCageVertexCount(50);
  EXPECT_EQ(node->GetCageVertexCount(), 50);
  node->SetCageDilationMm(-1.0);
  EXPECT_EQ(node->GetCageDilationMm(), 0.0);
  node->SetTransferMeshSizeMm(1e9);
  EXPECT_EQ(node->GetTransferMeshSizeMm(), 1000.0);
  node->SetOutputMemoryBudgetMB(1);
  EXPECT_EQ(node->GetOutputMemoryBudgetMB(), 64);
  node->SetOutputMemoryBudgetMB(-3);
  EXPECT_EQ(node->GetOutputMemoryBudgetMB(), 0);
  node->SetLabelOpacity(1.5);
  EXPECT_EQ(node->GetLabelOpacity(), 1.0);
  node->SetLabelOpacity(-0.5);
  EXPECT_EQ(node->GetLabelOpacity(), 0.0);
  // A selection is a set of indices: sorted, no repeats, no negatives.
  node->SetSelectedCageVertices({9, -1, 2, 9, 4});
  EXPECT_EQ(node->GetSelectedCageVertices(), (std::vector<int>{2, 4, 9}));
  // NaN and infinity are refused: the value stays.
  node->SetCageDilationMm(3.0);
  node->SetCageDilationMm(std::nan(""));
  node->SetCageDilationMm(std::numeric_limits<double>::infinity());
  EXPECT_EQ(node->GetCageDilationMm(), 3.0);
}

TEST(vtkMRMLReposeParametersNode, ModifiedOnlyOnChange) {
  vtkNew<vtkMRMLReposeParametersNode> node;
  ModifiedCounter counter(node);
  node->SetCageVertexCount(300);  // the default: no change
  node->SetInputSegmentationPath("");
  node->SetCageDilationMm(std::nan(""));
  EXPECT_EQ(counter.count, 0);
  node->SetCageVertexCount(301);
  EXPECT_EQ(counter.count, 1);
  node->SetCageVertexCount(5000);  // clamps to 2000: a change
  node->SetCageVertexCount(9999);  // clamps to 2000 again: no change
  EXPECT_EQ(counter.count, 2);
  node->SetInputSegmentationPath("a.nii");
  node->SetInputSegmentationPath("a.nii");
  EXPECT_EQ(counter.count, 3);
  // Batched changes fire once, and nested batches fire at the outermost end.
  const int outer = node->StartModify();
  const int inner = node->StartModify();
  node->SetImagePath("x");
  node->SetOutputFolder("y");
  node->EndModify(inner);
  EXPECT_EQ(counter.count, 3);
  node->EndModify(outer);
  EXPECT_EQ(counter.count, 4);
}

TEST(vtkMRMLReposeParametersNode, CopyCopiesEveryFieldAndFiresOnce) {
  vtkNew<vtkMRMLReposeParametersNode> source, target;
  fillNonDefault(source);
  ModifiedCounter counter(target);
  target->Copy(source);
  expectEqualFields(source, target);
  EXPECT_EQ(counter.count, 1);
  target->Copy(source);  // identical: nothing changes
  EXPECT_EQ(counter.count, 1);
  target->Copy(nullptr);
  EXPECT_EQ(counter.count, 1);
}

TEST(vtkMRMLReposeParametersNode, JsonRoundTrip) {
  vtkNew<vtkMRMLReposeParametersNode> source, target;
  fillNonDefault(source);
  source->SetCageDilationMm(0.1 + 0.2);  // needs all 17 digits to survive
  const std::string json = source->WriteJSON();
  std::string error;
  ModifiedCounter counter(target);
  ASSERT_TRUE(target->ReadJSON(json, &error)) << error;
  expectEqualFields(source, target);
  EXPECT_EQ(counter.count, 1);
  EXPECT_EQ(target->WriteJSON(), json);
  // Keys appear in field order.
  std::size_t last = 0;
  for (const char* name : kFieldNames) {
    const std::size_t at = json.find(std::string("\"") + name + "\"");
    ASSERT_NE(at, std::string::npos) << name;
    EXPECT_GT(at, last) << name;
    last = at;
  }
}

TEST(vtkMRMLReposeParametersNode, ReadJsonPartialClampsAndRejectsBadInput) {
  vtkNew<vtkMRMLReposeParametersNode> node;
  fillNonDefault(node);
  ASSERT_TRUE(node->ReadJSON(R"({"CageVertexCount": 1000000000000, "ImagePath": "b"})"));
  EXPECT_EQ(node->GetCageVertexCount(), 2000);
  EXPECT_EQ(node->GetImagePath(), "b");
  EXPECT_EQ(node->GetBodyPartMapPath(), "/data/limbs.nrrd");  // absent keys keep their value

  const std::string before = node->WriteJSON();
  ModifiedCounter counter(node);
  std::string error;
  EXPECT_FALSE(node->ReadJSON("{not json", &error));
  EXPECT_NE(error.find("not valid JSON"), std::string::npos) << error;
  EXPECT_FALSE(node->ReadJSON("[1, 2]", &error));
  EXPECT_FALSE(node->ReadJSON(R"({"ImagePath": "c", "CageVertexCount": "many"})", &error));
  EXPECT_NE(error.find("CageVertexCount"), std::string::npos) << error;
  EXPECT_FALSE(node->ReadJSON(R"({"CageVertexCount": 3.5})", &error));
  EXPECT_FALSE(node->ReadJSON(R"({"ShowJoints": 1})", &error));  // a switch is true or false
  EXPECT_NE(error.find("ShowJoints"), std::string::npos) << error;
  EXPECT_FALSE(node->ReadJSON(R"({"SelectedCageVertices": [1, "two"]})", &error));
  EXPECT_NE(error.find("SelectedCageVertices"), std::string::npos) << error;
  EXPECT_FALSE(node->ReadJSON(R"({"ImagePath": "c", "CageVertexCont": 7})", &error));
  EXPECT_NE(error.find("CageVertexCont"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  EXPECT_EQ(node->WriteJSON(), before);  // a rejected read changes nothing
  EXPECT_EQ(counter.count, 0);
}

TEST(vtkMRMLReposeParametersNode, PrintListsEveryFieldInOrder) {
  vtkNew<vtkMRMLReposeParametersNode> node;
  fillNonDefault(node);
  std::ostringstream out;
  node->Print(out);
  const std::string text = out.str();
  std::size_t last = 0;
  for (const char* name : kFieldNames) {
    const std::size_t at = text.find(std::string(name) + ": ");
    ASSERT_NE(at, std::string::npos) << name;
    EXPECT_GT(at, last) << name;
    last = at;
  }
  EXPECT_NE(text.find("CageVertexCount: 420"), std::string::npos);
  EXPECT_NE(text.find("InputSegmentationPath: /data/body seg.nii.gz"), std::string::npos);
}

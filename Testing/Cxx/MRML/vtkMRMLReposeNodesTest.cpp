// The data nodes and their scene, tested as Slicer tests its nodes: every field set to a
// non-default value survives write/read and copy, print lists every field the JSON has, bulk
// data is deep-copied, Modified fires once per batch and never without a change, and bad JSON
// names the field and changes nothing. The scene gives IDs, resolves references and refuses a
// file with a dangling reference.
#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"

#include "repose/schema/SceneSchema.h"

#include <gtest/gtest.h>

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>

#include <functional>
#include <sstream>

namespace {

// A pose file's text (docs/POSES.md): one group turned, the rest fixed.
constexpr const char* kPoseText = R"({"format": "repose-pose", "version": 1, "name": "p",
  "groups": [{"name": "raise", "select": {"cage_vertices": [0, 1]},
              "rotation": {"axis": [1, 0, 0], "angle_deg": 30, "pivot": [0, 0, 0]}},
             {"name": "body", "select": {"rest": true}, "fixed": true}]})";

struct ModifiedCounter {
  explicit ModifiedCounter(vtkObject* object) {
    callback->SetClientData(&count);
    callback->SetCallback(
        [](vtkObject*, unsigned long, void* data, void*) { ++*static_cast<int*>(data); });
    object->AddObserver(vtkCommand::ModifiedEvent, callback);
  }
  int count = 0;
  vtkNew<vtkCallbackCommand> callback;
};

vtkSmartPointer<vtkImageData> image(int value) {
  auto im = vtkSmartPointer<vtkImageData>::New();
  im->SetDimensions(3, 2, 1);
  im->SetSpacing(2, 2, 2);
  im->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  for (int i = 0; i < 6; ++i) static_cast<unsigned char*>(im->GetScalarPointer())[i] = value;
  return im;
}

struct NodeCase {
  std::string name;
  std::function<vtkSmartPointer<vtkMRMLReposeNode>()> create;
  std::function<void(vtkMRMLReposeNode*)> fill;  // every field non-default, data set
  std::function<void(vtkMRMLReposeNode*, vtkMRMLReposeNode*)> expectSameData;
  std::string badJSON, badField;  // a field of the wrong type and the name the error must give
};

std::vector<NodeCase> cases() {
  return {
      {"segmentation", [] { return vtkSmartPointer<vtkMRMLReposeSegmentationNode>::New(); },
       [](vtkMRMLReposeNode* n) {
         auto* s = vtkMRMLReposeSegmentationNode::SafeDownCast(n);
         s->SetLabelMapFileName("G.nii.gz");
         s->SetBodyPartMapFileName("S.nii.gz");
         s->SetImageFileName("CT \"head\".nii.gz");
         s->SetLabelMap(image(7));
         s->SetBodyPartMap(image(2));
         s->SetImage(image(100));
         s->SetLabelMapReadNotes({"G.dcm: a note of its reader"});
         s->SetSourceStamp("/data/G.dcm\t1\t4096\t17\n\n\n");
       },
       [](vtkMRMLReposeNode* a, vtkMRMLReposeNode* b) {
         auto *x = vtkMRMLReposeSegmentationNode::SafeDownCast(a),
              *y = vtkMRMLReposeSegmentationNode::SafeDownCast(b);
         // The reader's notes are copied, and not written (a scene's G is read again).
         EXPECT_EQ(y->GetLabelMapReadNotes(), x->GetLabelMapReadNotes());
         EXPECT_EQ(x->ToJSON().dump().find("a note of its reader"), std::string::npos);
         // So is the stamp of the files it was read from (an opened scene's are its own).
         EXPECT_EQ(y->GetSourceStamp(), x->GetSourceStamp());
         EXPECT_EQ(x->ToJSON().dump().find("/data/G.dcm"), std::string::npos);
         for (auto [p, q] : {std::pair{x->GetLabelMap(), y->GetLabelMap()},
                             std::pair{x->GetBodyPartMap(), y->GetBodyPartMap()},
                             std::pair{x->GetImage(), y->GetImage()}}) {
           ASSERT_TRUE(p && q);
           EXPECT_NE(p, q);  // deep copy
           EXPECT_EQ(*static_cast<unsigned char*>(p->GetScalarPointer()),
                     *static_cast<unsigned char*>(q->GetScalarPointer()));
         }
       },
       R"({"ImageFileName": 3})", "ImageFileName"},
      {"cage", [] { return vtkSmartPointer<vtkMRMLReposeCageNode>::New(); },
       [](vtkMRMLReposeNode* n) {
         auto* c = vtkMRMLReposeCageNode::SafeDownCast(n);
         c->SetFileName("cage.vtk");
         c->SetTargetVertexCount(420);
         c->SetDilationMm(7.5);
         c->SetHandleGroups({{"left arm", {1, 5, 9}}, {"body", {0, 2}}});
         vtkNew<vtkPoints> points;
         points->InsertNextPoint(1, 2, 3);
         auto mesh = vtkSmartPointer<vtkPolyData>::New();
         mesh->SetPoints(points);
         c->SetMesh(mesh);
       },
       [](vtkMRMLReposeNode* a, vtkMRMLReposeNode* b) {
         auto *x = vtkMRMLReposeCageNode::SafeDownCast(a),
              *y = vtkMRMLReposeCageNode::SafeDownCast(b);
         ASSERT_TRUE(x->GetMesh() && y->GetMesh());
         EXPECT_NE(x->GetMesh(), y->GetMesh());
         EXPECT_EQ(y->GetMesh()->GetNumberOfPoints(), 1);
       },
       R"({"HandleGroups": [{"name": "a", "vertices": [-1]}]})", "HandleGroups[0].vertices"},
      {"transfer mesh", [] { return vtkSmartPointer<vtkMRMLReposeTransferMeshNode>::New(); },
       [](vtkMRMLReposeNode* n) {
         auto* t = vtkMRMLReposeTransferMeshNode::SafeDownCast(n);
         t->SetFileName("tm.vtu");
         t->SetSizeMm(12.5);
         vtkNew<vtkPoints> points;
         points->InsertNextPoint(0, 0, 0);
         auto mesh = vtkSmartPointer<vtkUnstructuredGrid>::New();
         mesh->SetPoints(points);
         t->SetMesh(mesh);
       },
       [](vtkMRMLReposeNode* a, vtkMRMLReposeNode* b) {
         auto *x = vtkMRMLReposeTransferMeshNode::SafeDownCast(a),
              *y = vtkMRMLReposeTransferMeshNode::SafeDownCast(b);
         ASSERT_TRUE(x->GetMesh() && y->GetMesh());
         EXPECT_NE(x->GetMesh(), y->GetMesh());
         EXPECT_EQ(y->GetMesh()->GetNumberOfPoints(), 1);
       },
       R"({"SizeMm": "big"})", "SizeMm"},
      {"pose", [] { return vtkSmartPointer<vtkMRMLReposePoseNode>::New(); },
       [](vtkMRMLReposeNode* n) {
         auto* p = vtkMRMLReposePoseNode::SafeDownCast(n);
         p->SetFileName("elbow.pose.json");
         p->SetCurrentFrame(3);
         std::string error;
         ASSERT_TRUE(p->SetPoseJSON(kPoseText, &error)) << error;
         // Text that is no pose is refused with the parser's line; the pose stays.
         const auto before = p->GetPose();
         EXPECT_FALSE(p->SetPoseJSON(R"({"format": "repose-pose"})", &error));
         EXPECT_NE(error.find("version"), std::string::npos) << error;
         EXPECT_EQ(p->GetPose(), before);
       },
       [](vtkMRMLReposeNode* a, vtkMRMLReposeNode* b) {
         auto *x = vtkMRMLReposePoseNode::SafeDownCast(a),
              *y = vtkMRMLReposePoseNode::SafeDownCast(b);
         ASSERT_TRUE(x->GetPose());
         EXPECT_EQ(x->GetPose(), y->GetPose());  // one immutable snapshot, shared
         EXPECT_EQ(x->GetPoseJSON(), y->GetPoseJSON());
         EXPECT_NE(y->GetPoseJSON().find("\"raise\""), std::string::npos);
       },
       R"({"CurrentFrame": 1.5})", "CurrentFrame"},
  };
}

// The JSON without the ID (which Copy and ReadJSON keep).
std::string withoutID(vtkMRMLReposeNode* n) {
  auto j = n->ToJSON();
  j.erase("id");
  return j.dump();
}

}  // namespace

TEST(vtkMRMLReposeNodes, EveryFieldSurvivesWriteReadCopyAndIsPrinted) {
  for (const NodeCase& c : cases()) {
    SCOPED_TRACE(c.name);
    auto a = c.create();
    const std::string defaults = withoutID(a);
    a->SetName("my " + c.name);
    a->SetNodeReferenceID("segmentation", "vtkMRMLReposeSegmentationNode1");
    c.fill(a);
    EXPECT_NE(withoutID(a), defaults);

    auto b = c.create();
    ModifiedCounter modified(b);
    ASSERT_TRUE(b->ReadJSON(a->WriteJSON()));
    EXPECT_EQ(withoutID(b), withoutID(a));
    EXPECT_EQ(modified.count, 1);
    ASSERT_TRUE(b->ReadJSON(a->WriteJSON()));
    EXPECT_EQ(modified.count, 1);  // nothing changed

    auto d = c.create();
    ModifiedCounter copied(d);
    d->Copy(a);
    EXPECT_EQ(withoutID(d), withoutID(a));
    EXPECT_EQ(copied.count, 1);
    c.expectSameData(a, d);

    std::ostringstream printed;
    a->Print(printed);
    const auto json = a->ToJSON();
    for (const auto& [key, value] : json.items())
      EXPECT_NE(printed.str().find(key + ": " + value.dump()), std::string::npos) << key;

    std::string error;
    const std::string before = withoutID(d);
    EXPECT_FALSE(d->ReadJSON(c.badJSON, &error));
    EXPECT_NE(error.find(c.badField), std::string::npos) << error;
    EXPECT_FALSE(d->ReadJSON(R"({"name": "x", "class": "vtkMRMLOther"})", &error));
    EXPECT_FALSE(d->ReadJSON("{", &error));
    EXPECT_EQ(withoutID(d), before);
  }
}

TEST(vtkMRMLReposeScene, GivesIDsResolvesReferencesAndRoundTrips) {
  vtkNew<vtkMRMLReposeScene> scene;
  vtkNew<vtkMRMLReposeSegmentationNode> seg;
  vtkNew<vtkMRMLReposeCageNode> cage, cage2;
  vtkNew<vtkMRMLReposePoseNode> pose;
  EXPECT_EQ(scene->AddNode(seg), "vtkMRMLReposeSegmentationNode1");
  EXPECT_EQ(scene->AddNode(cage), "vtkMRMLReposeCageNode1");
  EXPECT_EQ(scene->AddNode(cage2), "vtkMRMLReposeCageNode2");
  EXPECT_EQ(scene->AddNode(cage), "vtkMRMLReposeCageNode1");  // already in
  scene->AddNode(pose);
  cage->SetNodeReferenceID("segmentation", seg->GetID());
  pose->SetNodeReferenceID("cage", cage->GetID());
  EXPECT_EQ(scene->GetReferencedNode(pose, "cage"), cage.GetPointer());
  EXPECT_EQ(scene->GetReferencedNode(scene->GetReferencedNode(pose, "cage"), "segmentation"),
            seg.GetPointer());
  EXPECT_EQ(scene->GetNodesByClass("vtkMRMLReposeCageNode").size(), 2u);
  cage->SetHandleGroups({{"arm", {3, 4}}});

  vtkNew<vtkMRMLReposeScene> loaded;
  std::string error;
  ASSERT_TRUE(loaded->ReadJSON(scene->WriteJSON(), &error)) << error;
  EXPECT_EQ(loaded->WriteJSON(), scene->WriteJSON());
  EXPECT_EQ(loaded->GetNumberOfNodes(), 4);
  auto* loadedCage = vtkMRMLReposeCageNode::SafeDownCast(loaded->GetNodeByID(cage->GetID()));
  ASSERT_TRUE(loadedCage);
  EXPECT_EQ(loadedCage->GetHandleGroups(), cage->GetHandleGroups());

  scene->RemoveNode(seg);
  EXPECT_FALSE(loaded->ReadJSON(scene->WriteJSON(), &error));  // dangling reference
  EXPECT_NE(error.find("references.segmentation"), std::string::npos) << error;
  EXPECT_EQ(loaded->GetNumberOfNodes(), 4);  // unchanged
  EXPECT_FALSE(loaded->ReadJSON(
      R"({"format":"repose-scene","version":2,"nodes":[{"class":"X","id":"a"}]})", &error));
  EXPECT_NE(error.find("unknown node class"), std::string::npos);
}

// The nodes are the classes scene.json names (repose/schema/SceneSchema.h, which Core's scene
// folders write and read too), and a scene's document carries the schema's format and version.
TEST(vtkMRMLReposeScene, NodesAndDocumentFollowTheSceneSchema) {
  namespace sc = repose::scene_schema;
  EXPECT_STREQ(vtkNew<vtkMRMLReposeSegmentationNode>()->GetNodeClassName(),
               sc::segmentation::kClassName);
  EXPECT_STREQ(vtkNew<vtkMRMLReposeCageNode>()->GetNodeClassName(), sc::cage::kClassName);
  EXPECT_STREQ(vtkNew<vtkMRMLReposeTransferMeshNode>()->GetNodeClassName(),
               sc::transfer_mesh::kClassName);
  EXPECT_STREQ(vtkNew<vtkMRMLReposePoseNode>()->GetNodeClassName(), sc::pose::kClassName);
  for (const char* name : {sc::segmentation::kClassName, sc::cage::kClassName,
                           sc::transfer_mesh::kClassName, sc::pose::kClassName})
    EXPECT_TRUE(vtkMRMLReposeScene::CreateNodeByClass(name)) << name;
  vtkNew<vtkMRMLReposeScene> scene;
  vtkNew<vtkMRMLReposeCageNode> cage;
  cage->SetFileName("cage.vtk");
  scene->AddNode(cage);
  const nlohmann::json doc = nlohmann::json::parse(scene->WriteJSON());
  EXPECT_EQ(doc[sc::kFormatKey], sc::kFormat);
  EXPECT_EQ(doc[sc::kVersionKey], sc::kVersion);
  ASSERT_EQ(doc[sc::kNodes].size(), 1u);
  EXPECT_EQ(doc[sc::kNodes][0][sc::kClass], sc::cage::kClassName);
  EXPECT_EQ(doc[sc::kNodes][0][sc::cage::kFile], "cage.vtk");
}

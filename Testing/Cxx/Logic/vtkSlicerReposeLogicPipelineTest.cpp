// The Logic's pipeline on nodes, on the 8 mm phantom: rig and pose jobs on a worker with progress,
// their nodes committed on this thread; a cancelled job leaves the scene and the output folder as
// they were; pose edits undo and redo; a saved scene folder loaded into a new logic poses the
// body bit for bit as the original did.
#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeLogic.h"
#include "vtkSlicerReposeLogicRead.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include "CommandRunner.h"
#include "TestDicomSeg.h"
#include "TestPaths.h"

#include <repose/io/AtomicOutput.h>
#include <repose/io/VolumeIO.h>
#include <repose/phantom/Phantom.h>
#include <repose/pose/SceneFolder.h>
#include <repose/util/Memory.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <vtkNew.h>
#include <vtkPointData.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <thread>

using namespace repose::test;

namespace {

std::string suite(const std::string& name) {
  return std::string(REPOSE_SOURCE_DIR) + "/bench/poses/" + name + ".pose.json";
}

struct PhantomFiles {
  ScratchDir dir{"logic"};
  std::string G, S;
  PhantomFiles() {
    repose::PhantomOptions po;
    po.voxelMm = 8;
    const repose::Phantom phantom(po);
    const auto [organs, parts] = phantom.makeVolumes();
    G = dir.file("G.nii.gz"), S = dir.file("S.nii.gz");
    repose::writeVolume(organs, G);
    repose::writeVolume(parts, S);
    repose::writeTextFileAtomically(dir.file("skeleton.json"), phantom.skeletonJson());
  }
};

bool sameVoxels(vtkImageData* a, vtkImageData* b) {
  if (!a || !b) return false;
  int da[3], db[3];
  a->GetDimensions(da);
  b->GetDimensions(db);
  if (!std::equal(da, da + 3, db)) return false;
  vtkDataArray *x = a->GetPointData()->GetScalars(), *y = b->GetPointData()->GetScalars();
  return x->GetDataType() == y->GetDataType() && x->GetDataSize() == y->GetDataSize() &&
         std::memcmp(x->GetVoidPointer(0), y->GetVoidPointer(0),
                     std::size_t(x->GetDataSize()) * std::size_t(x->GetDataTypeSize())) == 0;
}

}  // namespace

TEST(vtkSlicerReposeLogicPipeline, RigPoseCancelUndoAndSceneRoundTrip) {
  PhantomFiles files;
  vtkNew<vtkSlicerReposeLogic> logic;
  vtkMRMLReposeScene* scene = logic->GetScene();
  auto* seg = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(seg) << logic->GetLastErrorMessage();
  auto* pose = logic->AddPose(suite("elbow90"));
  ASSERT_TRUE(pose) << logic->GetLastErrorMessage();
  EXPECT_EQ(scene->GetNumberOfNodes(), 2);

  // Posing before the rig exists is refused with a message, nothing starts.
  EXPECT_FALSE(logic->GetJobs()->StartApplyPose(pose));
  EXPECT_NE(logic->GetLastErrorMessage().find("build the rig"), std::string::npos);

  // The rig on the worker; progress is visible while it runs; nodes appear only at commit.
  ASSERT_TRUE(logic->GetJobs()->StartBuildRig(seg, pose)) << logic->GetLastErrorMessage();
  EXPECT_FALSE(logic->GetJobs()->StartBuildRig(seg, pose));  // one job at a time
  double last = 0;
  while (logic->GetJobs()->IsJobRunning() &&
         logic->GetJobs()->PollJob() == vtkSlicerReposeJobsLogic::JobRunning) {
    EXPECT_EQ(scene->GetNumberOfNodes(), 2);
    last = std::max(last, logic->GetJobs()->GetJobProgress());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(scene->GetNodesByClass("vtkMRMLReposeCageNode").size(), 1u);
  EXPECT_EQ(scene->GetNodesByClass("vtkMRMLReposeTransferMeshNode").size(), 1u);
  auto* cage = vtkMRMLReposeCageNode::SafeDownCast(scene->GetReferencedNode(pose, "cage"));
  ASSERT_TRUE(cage);
  ASSERT_EQ(cage->GetHandleGroups().size(), 2u);
  EXPECT_EQ(cage->GetHandleGroups()[0].name, "left forearm and hand");
  EXPECT_EQ(
      std::size_t(cage->GetMesh()->GetNumberOfPoints()),
      cage->GetHandleGroups()[0].vertices.size() + cage->GetHandleGroups()[1].vertices.size());

  // A cancelled pose job: no new node, no output folder.
  const std::string cancelledOut = files.dir.file("cancelled");
  ASSERT_TRUE(logic->GetJobs()->StartApplyPose(pose, cancelledOut));
  logic->GetJobs()->CancelJob();
  EXPECT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobCancelled);
  EXPECT_EQ(scene->GetNumberOfNodes(), 4);
  EXPECT_FALSE(std::filesystem::exists(cancelledOut));
  EXPECT_EQ(logic->GetJobs()->GetLastPosedSegmentation(), nullptr);

  // The pose: a posed segmentation node and the files.
  const std::string out = files.dir.file("posed");
  ASSERT_TRUE(logic->GetJobs()->StartApplyPose(pose, out));
  ASSERT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  vtkMRMLReposeSegmentationNode* posed = logic->GetJobs()->GetLastPosedSegmentation();
  ASSERT_TRUE(posed);
  EXPECT_EQ(scene->GetReferencedNode(posed, "source"), seg);
  for (const char* f : {"posed_G.nii.gz", "posed_S.nii.gz", "transform.nrrd"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  const repose::Volume written = repose::readVolume(out + "/posed_G.nii.gz");
  EXPECT_EQ(written.dims()[0], posed->GetLabelMap()->GetDimensions()[0]);

  // Undo and redo of a pose edit.
  const std::string original = pose->GetPoseJSON();
  EXPECT_FALSE(logic->GetPoseEdits()->CanUndo());
  ASSERT_TRUE(logic->GetPoseEdits()->SetPoseGroupTransform(pose, "left forearm and hand", {1, 0, 0},
                                                           45, {-176, -14, 806}, {0, 0, 0}));
  const std::string edited = pose->GetPoseJSON();
  EXPECT_NE(edited, original);
  EXPECT_NE(edited.find("45"), std::string::npos);
  EXPECT_TRUE(logic->GetPoseEdits()->Undo());
  EXPECT_EQ(pose->GetPoseJSON(), original);
  EXPECT_TRUE(logic->GetPoseEdits()->CanRedo());
  EXPECT_TRUE(logic->GetPoseEdits()->Redo());
  EXPECT_EQ(pose->GetPoseJSON(), edited);
  EXPECT_TRUE(logic->GetPoseEdits()->Undo());
  EXPECT_FALSE(logic->GetPoseEdits()->SetPoseGroupTransform(pose, "body", {1, 0, 0}, 10, {0, 0, 0},
                                                            {0, 0, 0}));
  EXPECT_NE(logic->GetLastErrorMessage().find("fixed"), std::string::npos);
  EXPECT_FALSE(logic->GetPoseEdits()->SetPoseGroupTransform(pose, "tail", {1, 0, 0}, 10, {0, 0, 0},
                                                            {0, 0, 0}));
  EXPECT_EQ(pose->GetPoseJSON(), original);

  // Save, load into a new logic, pose again: bit-identical.
  const std::string sceneDir = files.dir.file("scene");
  ASSERT_TRUE(logic->SaveScene(sceneDir)) << logic->GetLastErrorMessage();
  EXPECT_TRUE(std::filesystem::exists(sceneDir + "/scene.json"));
  // And a 3D Slicer scene of it (docs/SLICER.md; its conventions: test_slicer_scene.py): every
  // file it names is in the folder, the input and the posed label maps and both meshes among them.
  {
    std::ifstream in(sceneDir + "/scene.mrml");
    const std::string mrml((std::istreambuf_iterator<char>(in)), {});
    std::regex file(R"re(fileName="([^"]+)")re");
    std::set<std::string> named;
    for (auto it = std::sregex_iterator(mrml.begin(), mrml.end(), file);
         it != std::sregex_iterator(); ++it) {
      named.insert((*it)[1]);
      EXPECT_TRUE(std::filesystem::exists(sceneDir + "/" + (*it)[1].str())) << (*it)[1];
    }
    EXPECT_TRUE(named.count(std::string(seg->GetID()) + "_G.nii.gz"));
    EXPECT_TRUE(named.count(std::string(posed->GetID()) + "_G.nii.gz"));
    EXPECT_TRUE(named.count(cage->GetFileName()));
    auto count = [&](const std::string& tag) {
      std::size_t n = 0;
      for (std::size_t at = mrml.find(tag); at != std::string::npos; at = mrml.find(tag, at + 1))
        ++n;
      return n;
    };
    EXPECT_EQ(count("<LabelMapVolume\n"), 2u);  // the input and the posed G
    EXPECT_EQ(count("<Model\n"), 2u);           // the cage and the transfer mesh
    EXPECT_EQ(count("<ColorTable\n"), 1u);
  }
  vtkNew<vtkSlicerReposeLogic> other;
  ASSERT_TRUE(other->LoadScene(sceneDir)) << other->GetLastErrorMessage();
  EXPECT_EQ(other->GetScene()->GetNumberOfNodes(), scene->GetNumberOfNodes());
  auto* loadedPose =
      vtkMRMLReposePoseNode::SafeDownCast(other->GetScene()->GetNodeByID(pose->GetID()));
  ASSERT_TRUE(loadedPose);
  ASSERT_TRUE(other->GetJobs()->StartApplyPose(loadedPose));
  ASSERT_EQ(other->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << other->GetLastErrorMessage();
  EXPECT_TRUE(sameVoxels(other->GetJobs()->GetLastPosedSegmentation()->GetLabelMap(),
                         posed->GetLabelMap()));
  EXPECT_TRUE(sameVoxels(other->GetJobs()->GetLastPosedSegmentation()->GetBodyPartMap(),
                         posed->GetBodyPartMap()));

  // A scene folder with a missing data file is refused and the scene kept.
  const int nodesBefore = other->GetScene()->GetNumberOfNodes();
  std::filesystem::remove(sceneDir + "/" + cage->GetFileName());
  EXPECT_FALSE(other->LoadScene(sceneDir));
  EXPECT_NE(other->GetLastErrorMessage().find(cage->GetFileName()), std::string::npos);
  EXPECT_EQ(other->GetScene()->GetNumberOfNodes(), nodesBefore);
}

// A scene folder written by `repose pose --scene` is a module scene: the Logic loads it (the
// inputs named where they are) and poses the body exactly as the command line did.
TEST(vtkSlicerReposeLogicPipeline, LoadsTheSceneTheCommandLineWrote) {
  PhantomFiles files;
  const std::string scene = files.dir.file("scene"), out = files.dir.file("cli");
  const CommandResult cli = runCommand(
      "repose", "pose --input " + shellQuote(files.G) + " --parts " + shellQuote(files.S) +
                    " --pose " + shellQuote(suite("elbow90")) + " --scene " + shellQuote(scene) +
                    " --out " + shellQuote(out) + " --json");
  ASSERT_EQ(cli.exitCode, 0) << cli.err;
  vtkNew<vtkSlicerReposeLogic> logic;
  ASSERT_TRUE(logic->LoadScene(scene)) << logic->GetLastErrorMessage();
  const auto poses = logic->GetScene()->GetNodesByClass("vtkMRMLReposePoseNode");
  ASSERT_EQ(poses.size(), 1u);
  auto* cage = vtkMRMLReposeCageNode::SafeDownCast(
      logic->GetScene()->GetNodesByClass("vtkMRMLReposeCageNode").at(0));
  EXPECT_EQ(cage->GetHandleGroups().size(), 2u);
  const std::string logicOut = files.dir.file("logic");
  ASSERT_TRUE(
      logic->GetJobs()->StartApplyPose(vtkMRMLReposePoseNode::SafeDownCast(poses[0]), logicOut));
  ASSERT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  const repose::Volume expected = repose::readVolume(out + "/posed_G.nii.gz");
  vtkImageData* got = logic->GetJobs()->GetLastPosedSegmentation()->GetLabelMap();
  int dims[3];
  got->GetDimensions(dims);
  ASSERT_EQ(dims[0], expected.dims()[0]);
  ASSERT_EQ(dims[2], expected.dims()[2]);
  std::int64_t different = 0;
  for (std::int64_t v = 0; v < expected.numVoxels(); ++v) {
    const int a = static_cast<const std::uint8_t*>(got->GetScalarPointer())[v],
              b = expected.data<std::uint8_t>()[v];
    different += a != b;
  }
  EXPECT_EQ(different, 0);
  // The same report as the command line's: volumes, masses, distortion, bones, quality.
  std::ifstream cliReport(out + "/report.json"), logicReport(logicOut + "/report.json");
  ASSERT_TRUE(logicReport.good());
  const nlohmann::json a = nlohmann::json::parse(cliReport), b = nlohmann::json::parse(logicReport);
  for (const char* key : {"labels", "body", "distortion", "tet_volume_change", "mesh",
                          "rigid_tissues", "holes", "quality"})
    EXPECT_EQ(a[key], b[key]) << key;
  // The Logic read the Green coordinates the command line saved in the scene (tm.green), and
  // saving the scene elsewhere takes them along.
  EXPECT_TRUE(b["green_coordinates"]["read"].get<bool>()) << b["green_coordinates"];
  const std::string saved = files.dir.file("saved");
  ASSERT_TRUE(logic->SaveScene(saved)) << logic->GetLastErrorMessage();
  auto* mesh = vtkMRMLReposeTransferMeshNode::SafeDownCast(
      logic->GetScene()->GetNodesByClass("vtkMRMLReposeTransferMeshNode").at(0));
  EXPECT_EQ(mesh->GetCoordinatesFile(),
            saved + "/" + std::filesystem::path(mesh->GetFileName()).stem().string() + ".green");
  EXPECT_TRUE(std::filesystem::exists(mesh->GetCoordinatesFile()));
  // The other way: what the workbench saved, Core reads (Python's load_scene): the same inputs,
  // cage, transfer mesh and pose, through the one scene schema (repose/schema/SceneSchema.h).
  {
    const repose::SceneContents read = repose::readSceneFolder(saved);
    auto* segNode = vtkMRMLReposeSegmentationNode::SafeDownCast(
        logic->GetScene()->GetNodesByClass("vtkMRMLReposeSegmentationNode").at(0));
    auto* cageNode = vtkMRMLReposeCageNode::SafeDownCast(
        logic->GetScene()->GetNodesByClass("vtkMRMLReposeCageNode").at(0));
    auto* poseNode = vtkMRMLReposePoseNode::SafeDownCast(
        logic->GetScene()->GetNodesByClass("vtkMRMLReposePoseNode").at(0));
    EXPECT_TRUE(std::filesystem::equivalent(read.inputs.organs,
                                            saved + "/" + segNode->GetLabelMapFileName()))
        << read.inputs.organs;
    EXPECT_TRUE(std::filesystem::equivalent(read.inputs.parts,
                                            saved + "/" + segNode->GetBodyPartMapFileName()))
        << read.inputs.parts;
    EXPECT_EQ(read.geometry.cage.vertices.rows(), cageNode->GetMesh()->GetNumberOfPoints());
    EXPECT_EQ(read.geometry.mesh.tets.rows(), mesh->GetMesh()->GetNumberOfCells());
    EXPECT_EQ(read.geometry.coordinatesFile, mesh->GetCoordinatesFile());
    EXPECT_EQ(read.pose.groups.size(), poseNode->GetPose()->groups.size());
    EXPECT_EQ(read.key, "");  // the workbench records no command-line rig key
  }
  vtkNew<vtkSlicerReposeLogic> reloaded;
  ASSERT_TRUE(reloaded->LoadScene(saved)) << reloaded->GetLastErrorMessage();
  const std::string reloadedOut = files.dir.file("reloaded");
  ASSERT_TRUE(reloaded->GetJobs()->StartApplyPose(
      vtkMRMLReposePoseNode::SafeDownCast(
          reloaded->GetScene()->GetNodesByClass("vtkMRMLReposePoseNode").at(0)),
      reloadedOut));
  ASSERT_EQ(reloaded->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << reloaded->GetLastErrorMessage();
  std::ifstream reloadedReport(reloadedOut + "/report.json");
  EXPECT_TRUE(nlohmann::json::parse(reloadedReport)["green_coordinates"]["read"].get<bool>());

  // Opening the folder as a user does (the module's File > Open): the parameter node follows the
  // scene, its files named where they are (the workbench saved them relative to the folder), G
  // shown as reading its file shows it, and the rigged pose goes live.
  vtkNew<vtkSlicerReposeLogic> opened;
  vtkNew<vtkMRMLReposeParametersNode> parameters;
  opened->SetParameterNode(parameters);
  ASSERT_TRUE(opened->OpenScene(saved)) << opened->GetLastErrorMessage();
  auto* openedPose = vtkMRMLReposePoseNode::SafeDownCast(
      opened->GetScene()->GetNodesByClass("vtkMRMLReposePoseNode").at(0));
  EXPECT_EQ(parameters->GetActivePoseNodeID(), openedPose->GetID());
  EXPECT_TRUE(std::filesystem::exists(parameters->GetPosePath())) << parameters->GetPosePath();
  EXPECT_TRUE(std::filesystem::exists(parameters->GetBodyPartMapPath()))
      << parameters->GetBodyPartMapPath();
  EXPECT_EQ(parameters->GetActiveGroup(),
            opened->GetPoseEdits()->GetPoseSummary(openedPose).movableGroups.at(0));
  ASSERT_EQ(opened->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << opened->GetLastErrorMessage();
  EXPECT_EQ(opened->GetLive()->GetLivePose(), openedPose);
  vtkNew<vtkSlicerReposeLogic> fromFile;
  ASSERT_TRUE(fromFile->LoadVolume(parameters->GetInputSegmentationPath()))
      << fromFile->GetLastErrorMessage();
  EXPECT_EQ(opened->GetVolumeSummary(), fromFile->GetVolumeSummary());
  EXPECT_EQ(opened->GetVolumeLabelNames().size(), fromFile->GetVolumeLabelNames().size());
}

// Output > Memory budget: without an output folder, an export whose posed volumes would not fit
// is refused before any work, with the numbers. With one it is made slab by slab there (issue
// 56): the same files as an export within the budget, and a node holding G and S read back as a
// coarser preview, saying so in its name and a warning. The rig of the 8 mm phantom serves the
// 3 mm phantom's segmentation (both are in the same RAS millimetres), so the test needs no 3 mm
// rig.
TEST(vtkSlicerReposeLogicPipeline, AnExportAboveTheMemoryBudgetIsRefusedOrMadeSlabBySlab) {
  PhantomFiles coarse;
  repose::PhantomOptions po;
  po.voxelMm = 3;
  const auto [organs, parts] = repose::Phantom(po).makeVolumes();
  const std::string G3 = coarse.dir.file("G3.nii.gz"), S3 = coarse.dir.file("S3.nii.gz");
  repose::writeVolume(organs, G3);
  repose::writeVolume(parts, S3);

  vtkNew<vtkSlicerReposeLogic> logic;
  vtkNew<vtkMRMLReposeParametersNode> parameters;
  logic->SetParameterNode(parameters);
  auto* seg = logic->AddSegmentation(coarse.G, coarse.S);
  auto* pose = logic->AddPose(suite("elbow90"));
  ASSERT_TRUE(seg && pose);
  ASSERT_TRUE(logic->GetJobs()->StartBuildRig(seg, pose)) << logic->GetLastErrorMessage();
  ASSERT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded);
  auto* fine = logic->AddSegmentation(G3, S3);
  ASSERT_TRUE(fine);
  pose->SetNodeReferenceID("segmentation", fine->GetID());

  // The 3 mm posed maps need about 84 MiB (14 bytes a voxel): a budget that leaves half of that
  // beside what the process holds is refused without an output folder.
  const double need = 14.0 * double(organs.numVoxels());
  int budgetMb = int((repose::residentBytes() + need / 2) / 1048576);
  parameters->SetOutputMemoryBudgetMB(budgetMb);
  EXPECT_FALSE(logic->GetJobs()->StartApplyPose(pose));
  const std::string message = logic->GetLastErrorMessage();
  // The rule `repose pose` has (repose::checkFrameMemory): the posed volumes beside what the
  // process holds.
  EXPECT_NE(message.find("more than the memory budget of"), std::string::npos) << message;
  EXPECT_NE(message.find(std::to_string(organs.numVoxels()) + " output voxels beyond the "),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("or an output folder"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_FALSE(logic->GetJobs()->IsJobRunning());

  // With a folder: the budget raised 16 MiB at a time from there until the export runs (what
  // the worker holds beside the frame, its rig and the heap of its setup, is the process's to
  // say); until then each try is refused for want of a slab, and leaves nothing. The first
  // budget it runs at is below what the frame needs whole beside it: made slab by slab.
  const std::string slabs = coarse.dir.file("slabs");
  for (int tries = 0;; ++tries, budgetMb += 16) {
    ASSERT_LT(tries, 32) << logic->GetLastErrorMessage();
    parameters->SetOutputMemoryBudgetMB(budgetMb);
    ASSERT_TRUE(logic->GetJobs()->StartApplyPose(pose, slabs)) << logic->GetLastErrorMessage();
    if (logic->GetJobs()->WaitForJob() == vtkSlicerReposeJobsLogic::JobSucceeded) break;
    ASSERT_NE(logic->GetLastErrorMessage().find("for a slab of one slice"), std::string::npos)
        << logic->GetLastErrorMessage();
    ASSERT_FALSE(std::filesystem::exists(slabs));
  }
  vtkMRMLReposeSegmentationNode* preview = logic->GetJobs()->GetLastPosedSegmentation();
  ASSERT_TRUE(preview);
  const std::string name = preview->GetName();
  const std::smatch ratio = [&] {
    std::smatch m;
    std::regex_search(name, m, std::regex(R"(\(preview 1:(\d+)\)$)"));
    return m;
  }();
  ASSERT_FALSE(ratio.empty()) << name;
  const int factor = std::stoi(ratio[1]);
  EXPECT_GE(factor, 2) << "the preview fits what the budget leaves";
  const nlohmann::json report = nlohmann::json::parse(preview->GetPoseReportJSON());
  const auto dims = report["grid"]["dims"].get<std::vector<int>>();
  int previewDims[3];
  preview->GetLabelMap()->GetDimensions(previewDims);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(previewDims[a], (dims[a] + factor - 1) / factor) << a;
  EXPECT_TRUE(report.contains("streamed"));
  const auto warnings = logic->GetJobs()->GetLastPoseWarnings();
  ASSERT_FALSE(warnings.empty());
  EXPECT_NE(warnings.back().find("the full-resolution frame is in " + slabs), std::string::npos)
      << warnings.back();

  parameters->SetOutputMemoryBudgetMB(0);  // half the physical memory
  const std::string whole = coarse.dir.file("whole");
  ASSERT_TRUE(logic->GetJobs()->StartApplyPose(pose, whole)) << logic->GetLastErrorMessage();
  ASSERT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  EXPECT_EQ(std::string(logic->GetJobs()->GetLastPosedSegmentation()->GetName()).find("preview"),
            std::string::npos);
  auto bytes = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const char* file : {"posed_G.nii.gz", "posed_S.nii.gz", "transform.nrrd"})
    EXPECT_TRUE(bytes(whole + "/" + file) == bytes(slabs + "/" + file)) << file;
}

// "Rig from organ map" on an ICRP 110 array without a label table: the job writes S, the
// skeleton, the tissue table and rig.json and points the parameter node at S; the segmentation
// added next has the convention's organ names and the rig's part names. A folder that cannot be
// made fails the job with one line naming it, and a G that is not a label map is refused before
// any job starts.
// What G's reader said about its file (here a DICOM SEG whose SpacingBetweenSlices its frames do
// not keep) is in the export's report as "input_notes", as `repose pose` keeps it
// (PoseSlicerOutputsTest), and in the input box: the segmentation node keeps the notes of the file
// it was read from. A saved scene holds G as NIfTI on the grid the reader chose; opened, it has
// nothing more to say, and its exports say nothing.
TEST(vtkSlicerReposeLogicPipeline, AnExportsReportKeepsWhatTheReaderSaidAboutG) {
  PhantomFiles files;
  const std::string dcm = files.dir.file("G.dcm");
  repose::writeVolume(repose::readVolume(files.G), dcm);
  ASSERT_TRUE(setSegSpacingBetweenSlices(dcm, "7.5"));
  const std::string said = dcm + ": its frames are not 7.5";
  auto notesOf = [](const std::string& reportPath) {
    std::ifstream in(reportPath);
    const nlohmann::json report = nlohmann::json::parse(in);
    return report.value("input_notes", std::vector<std::string>());
  };

  // As the module's panel does it: the file shown in the input box, then a segmentation of it.
  vtkNew<vtkSlicerReposeLogic> logic;
  vtkNew<vtkMRMLReposeParametersNode> parameters;
  logic->SetParameterNode(parameters);
  ASSERT_TRUE(logic->LoadVolume(dcm)) << logic->GetLastErrorMessage();
  EXPECT_NE(logic->GetVolumeSummary().find("Note: its frames are not 7.5"), std::string::npos)
      << logic->GetVolumeSummary();
  auto* seg = logic->AddSegmentation(dcm, files.S);
  ASSERT_TRUE(seg) << logic->GetLastErrorMessage();
  ASSERT_EQ(seg->GetLabelMapReadNotes().size(), 1u);
  EXPECT_EQ(seg->GetLabelMapReadNotes()[0].rfind(said, 0), 0u) << seg->GetLabelMapReadNotes()[0];
  auto* pose = logic->AddPose(suite("elbow90"));
  ASSERT_TRUE(pose) << logic->GetLastErrorMessage();
  ASSERT_TRUE(logic->GetJobs()->StartBuildRig(seg, pose)) << logic->GetLastErrorMessage();
  ASSERT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  const std::string out = files.dir.file("posed");
  ASSERT_TRUE(logic->GetJobs()->StartApplyPose(pose, out));
  ASSERT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  EXPECT_EQ(notesOf(out + "/report.json"), seg->GetLabelMapReadNotes());

  // A segmentation read from a file the reader had nothing to say about gets none, whatever the
  // input box shows.
  auto* quiet = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(quiet) << logic->GetLastErrorMessage();
  EXPECT_TRUE(quiet->GetLabelMapReadNotes().empty());

  // Saved and opened again: G is the scene's NIfTI now, read without a note.
  const std::string saved = files.dir.file("saved");
  logic->GetScene()->RemoveNode(quiet);
  ASSERT_TRUE(logic->SaveScene(saved)) << logic->GetLastErrorMessage();
  vtkNew<vtkSlicerReposeLogic> opened;
  vtkNew<vtkMRMLReposeParametersNode> openedParameters;
  opened->SetParameterNode(openedParameters);
  ASSERT_TRUE(opened->OpenScene(saved)) << opened->GetLastErrorMessage();
  ASSERT_EQ(opened->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << opened->GetLastErrorMessage();
  auto* openedSeg = vtkMRMLReposeSegmentationNode::SafeDownCast(
      opened->GetScene()->GetNodesByClass("vtkMRMLReposeSegmentationNode").at(0));
  EXPECT_EQ(std::filesystem::path(openedSeg->GetLabelMapFileName()).extension(), ".gz");
  EXPECT_TRUE(openedSeg->GetLabelMapReadNotes().empty());
  EXPECT_EQ(opened->GetVolumeSummary().find("Note: "), std::string::npos)
      << opened->GetVolumeSummary();
  const std::string reposed = files.dir.file("reposed");
  ASSERT_TRUE(opened->GetJobs()->StartApplyPose(
      vtkMRMLReposePoseNode::SafeDownCast(
          opened->GetScene()->GetNodesByClass("vtkMRMLReposePoseNode").at(0)),
      reposed));
  ASSERT_EQ(opened->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << opened->GetLastErrorMessage();
  EXPECT_TRUE(notesOf(reposed + "/report.json").empty());
}

// A segmentation node knows the files it was read from as they were then, so the panel builds
// the rig on it again instead of reading G, S and the image anew into one more node; a path
// changed, or a file rewritten, is read again; an opened scene's node is of its own files, with
// the paths OpenScene gives the panel.
TEST(vtkSlicerReposeLogicPipeline, ASegmentationIsOfTheFilesItWasReadFromUntilOneChanges) {
  namespace fs = std::filesystem;
  PhantomFiles files;
  vtkNew<vtkSlicerReposeLogic> logic;
  vtkNew<vtkMRMLReposeParametersNode> parameters;
  logic->SetParameterNode(parameters);
  auto* seg = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(seg) << logic->GetLastErrorMessage();
  EXPECT_TRUE(logic->IsSegmentationOf(seg, files.G, files.S, ""));
  EXPECT_FALSE(logic->IsSegmentationOf(seg, files.G, "", ""));
  EXPECT_FALSE(logic->IsSegmentationOf(seg, files.S, files.S, ""));
  EXPECT_FALSE(logic->IsSegmentationOf(seg, files.G, files.S, files.G));
  EXPECT_FALSE(logic->IsSegmentationOf(nullptr, files.G, files.S, ""));
  EXPECT_FALSE(logic->IsSegmentationOf(seg, files.G, files.dir.file("gone.nii.gz"), ""));
  // A copy of the node is of the same files.
  vtkNew<vtkMRMLReposeSegmentationNode> copy;
  copy->Copy(seg);
  EXPECT_TRUE(logic->IsSegmentationOf(copy, files.G, files.S, ""));

  // G rewritten (re-exported from Slicer, say) with the same bytes but a later time: read again.
  const fs::file_time_type before = fs::last_write_time(files.G);
  fs::last_write_time(files.G, before + std::chrono::seconds(2));
  EXPECT_FALSE(logic->IsSegmentationOf(seg, files.G, files.S, ""));
  fs::last_write_time(files.G, before);
  EXPECT_TRUE(logic->IsSegmentationOf(seg, files.G, files.S, ""));
  // A file that grew (another size): read again too.
  {
    std::ofstream grow(files.S, std::ios::app | std::ios::binary);
    grow << '\0';
  }
  EXPECT_FALSE(logic->IsSegmentationOf(seg, files.G, files.S, ""));

  // A folder (a DICOM series): a file added to it changes its stamp.
  const std::string series = files.dir.file("series");
  fs::create_directories(series);
  std::ofstream(series + "/1.dcm") << "a";
  const std::string one = vtkSlicerReposeLogicRead::FilesStamp({series});
  EXPECT_FALSE(one.empty());
  EXPECT_EQ(one, vtkSlicerReposeLogicRead::FilesStamp({series}));
  std::ofstream(series + "/2.dcm") << "b";
  EXPECT_NE(one, vtkSlicerReposeLogicRead::FilesStamp({series}));
  EXPECT_EQ(vtkSlicerReposeLogicRead::FilesStamp({series + "/none"}), "");

  // Saved and opened: the opened node is of the scene folder's own files, as OpenScene puts
  // them in the parameter node, so a build there reads nothing again.
  auto* fresh = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(fresh) << logic->GetLastErrorMessage();
  logic->GetScene()->RemoveNode(seg);
  const std::string saved = files.dir.file("saved");
  ASSERT_TRUE(logic->SaveScene(saved)) << logic->GetLastErrorMessage();
  EXPECT_TRUE(logic->IsSegmentationOf(fresh, files.G, files.S, ""))
      << "saving does not change what the node was read from";
  vtkNew<vtkSlicerReposeLogic> opened;
  vtkNew<vtkMRMLReposeParametersNode> openedParameters;
  opened->SetParameterNode(openedParameters);
  ASSERT_TRUE(opened->OpenScene(saved)) << opened->GetLastErrorMessage();
  auto* openedSeg = vtkMRMLReposeSegmentationNode::SafeDownCast(
      opened->GetScene()->GetNodeByID(openedParameters->GetInputSegmentationNodeID()));
  ASSERT_TRUE(openedSeg);
  EXPECT_TRUE(opened->IsSegmentationOf(openedSeg, openedParameters->GetInputSegmentationPath(),
                                       openedParameters->GetBodyPartMapPath(),
                                       openedParameters->GetImagePath()));
  EXPECT_FALSE(opened->IsSegmentationOf(openedSeg, files.G, files.S, ""));
}

// The panel shows G in its input box, then builds on a segmentation of the same file: the node
// shares the box's image instead of reading G again, with the same voxels and names a read gives;
// once the file is rewritten, or the tissue table that names the labels changes, it is read.
TEST(vtkSlicerReposeLogicPipeline, ASegmentationOfTheFileTheInputBoxShowsSharesItsImage) {
  namespace fs = std::filesystem;
  PhantomFiles files;
  vtkNew<vtkSlicerReposeLogic> logic;
  vtkNew<vtkMRMLReposeParametersNode> parameters;
  logic->SetParameterNode(parameters);
  ASSERT_TRUE(logic->LoadVolume(files.G)) << logic->GetLastErrorMessage();
  auto* shared = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(shared) << logic->GetLastErrorMessage();
  EXPECT_EQ(shared->GetLabelMap(), logic->GetVolumeImageData());
  EXPECT_TRUE(logic->IsSegmentationOf(shared, files.G, files.S, ""));

  // What a read gives: another logic that never showed the file.
  vtkNew<vtkSlicerReposeLogic> reader;
  vtkNew<vtkMRMLReposeParametersNode> readerParameters;
  reader->SetParameterNode(readerParameters);
  auto* read = reader->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(read);
  EXPECT_TRUE(sameVoxels(shared->GetLabelMap(), read->GetLabelMap()));
  const repose::Volume a = vtkSlicerReposeVolumeConversion::FromImageData(shared->GetLabelMap());
  const repose::Volume b = vtkSlicerReposeVolumeConversion::FromImageData(read->GetLabelMap());
  EXPECT_TRUE(a.geometry().ijkToRas.isApprox(b.geometry().ijkToRas, 1e-12));
  ASSERT_EQ(a.labels().labels().size(), b.labels().labels().size());
  for (std::size_t i = 0; i < a.labels().labels().size(); ++i)
    EXPECT_EQ(a.labels().labels()[i].name, b.labels().labels()[i].name);
  // S on another grid is still refused against the shared G's grid.
  const std::string coarse = files.dir.file("S_coarse.nii.gz");
  {
    repose::Volume S = repose::readVolume(files.S);
    repose::VolumeGeometry g = S.geometry();
    g.ijkToRas(0, 3) += 1.0;
    repose::Volume moved(g, S.scalarType());
    repose::writeVolume(moved, coarse);
  }
  EXPECT_FALSE(logic->AddSegmentation(files.G, coarse));
  EXPECT_NE(logic->GetLastErrorMessage().find("not on the grid of"), std::string::npos)
      << logic->GetLastErrorMessage();

  // G rewritten since the box read it: read again, not shared.
  fs::last_write_time(files.G, fs::last_write_time(files.G) + std::chrono::seconds(2));
  auto* reread = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(reread) << logic->GetLastErrorMessage();
  EXPECT_NE(reread->GetLabelMap(), logic->GetVolumeImageData());
  EXPECT_TRUE(sameVoxels(reread->GetLabelMap(), read->GetLabelMap()));

  // Shown again, then a tissue table set (it names the labels): read again too.
  ASSERT_TRUE(logic->LoadVolume(files.G)) << logic->GetLastErrorMessage();
  auto* again = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->GetLabelMap(), logic->GetVolumeImageData());
  const std::string tissues = files.dir.file("tissues.csv");
  repose::writeTextFileAtomically(tissues, "label,name,density,rigid,bone\n1,skin,1100,0,0\n");
  logic->GetParameterNode()->SetTissueTablePath(tissues);
  auto* named = logic->AddSegmentation(files.G, files.S);
  ASSERT_TRUE(named) << logic->GetLastErrorMessage();
  EXPECT_NE(named->GetLabelMap(), logic->GetVolumeImageData());
}

TEST(vtkSlicerReposeLogicPipeline, RigFromOrganMapWritesTheRigAndNamesTheLabels) {
  ScratchDir dir("organrig");
  repose::PhantomOptions po;
  po.voxelMm = 8;
  po.armsResting = true;
  po.labels = repose::PhantomLabelling::Icrp110;
  const auto [organs, parts] = repose::Phantom(po).makeVolumes();
  ASSERT_TRUE(organs.labels().empty());
  const std::string G = dir.file("AF.nii.gz");
  repose::writeVolume(organs, G);
  vtkNew<vtkSlicerReposeLogic> logic;
  vtkNew<vtkMRMLReposeParametersNode> node;
  logic->SetParameterNode(node);

  const std::string rig = dir.file("AF_rig");
  ASSERT_TRUE(logic->GetJobs()->StartRigFromOrganMap(G, rig)) << logic->GetLastErrorMessage();
  ASSERT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobSucceeded)
      << logic->GetLastErrorMessage();
  for (const char* f : {"S.nii.gz", "skeleton.json", "tissues.csv", "rig.json"})
    EXPECT_TRUE(std::filesystem::exists(rig + "/" + f)) << f;
  EXPECT_EQ(node->GetBodyPartMapPath(), rig + "/S.nii.gz");
  EXPECT_EQ(logic->GetJobs()->GetLastRigSummary().rfind("icrp110 (AF) convention, ", 0), 0u)
      << logic->GetJobs()->GetLastRigSummary();

  vtkMRMLReposeSegmentationNode* seg = logic->AddSegmentation(G, node->GetBodyPartMapPath());
  ASSERT_NE(seg, nullptr) << logic->GetLastErrorMessage();
  EXPECT_FALSE(seg->GetSkeletonJSON().empty());  // skeleton.json beside S
  const repose::Volume named = vtkSlicerReposeVolumeConversion::FromImageData(seg->GetLabelMap());
  ASSERT_TRUE(named.labels().find(13));
  EXPECT_EQ(named.labels().find(13)->name, "Humeri, upper half, cortical");
  const repose::Volume S = vtkSlicerReposeVolumeConversion::FromImageData(seg->GetBodyPartMap());
  ASSERT_TRUE(S.labels().find(repose::kPartHandLeft));
  EXPECT_EQ(S.labels().find(repose::kPartHandLeft)->name, "hand_left");

  // A folder under a file cannot be made: the job fails, naming it; nothing else changes.
  node->SetBodyPartMapPath("");
  const std::string bad = G + "/rig";
  ASSERT_TRUE(logic->GetJobs()->StartRigFromOrganMap(G, bad)) << logic->GetLastErrorMessage();
  EXPECT_EQ(logic->GetJobs()->WaitForJob(), vtkSlicerReposeJobsLogic::JobFailed);
  EXPECT_NE(logic->GetLastErrorMessage().find(bad), std::string::npos)
      << logic->GetLastErrorMessage();
  EXPECT_EQ(logic->GetLastErrorMessage().find('\n'), std::string::npos);
  EXPECT_EQ(node->GetBodyPartMapPath(), "");
  // An image is no organ map.
  repose::writeVolume(repose::syntheticCT(organs), dir.file("CT.nii.gz"));
  EXPECT_FALSE(logic->GetJobs()->StartRigFromOrganMap(dir.file("CT.nii.gz"), dir.file("ct_rig")));
  EXPECT_NE(logic->GetLastErrorMessage().find("not a label map"), std::string::npos)
      << logic->GetLastErrorMessage();
  EXPECT_FALSE(std::filesystem::exists(dir.file("ct_rig")));
}

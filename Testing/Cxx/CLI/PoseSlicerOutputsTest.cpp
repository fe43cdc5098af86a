// What `repose pose` writes for 3D Slicer (issue 22): a .seg.nrrd input with named, coloured
// segments comes out as .seg.nrrd with the same names, colours and terminology
// (vtkMRMLSegmentationStorageNode.cxx reads them); NIfTI outputs get a colour table beside them
// (Slicer ignores a NIfTI's label table: vtkMRMLColorTableStorageNode.cxx reads the .ctbl);
// --output-format chooses, and a re-run never leaves another run's files beside its report.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestDicomSeg.h"
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/io/VolumeIO.h"
#include "repose/volume/SegmentTerminology.h"

// clang-format off
#include <dcmtk/config/osconfig.h>
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;

namespace {

std::set<std::string> filesIn(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

// The names of the label maps, tables and segmentations the report's "outputs" lists.
std::set<std::string> reportedFiles(const nlohmann::json& outputs) {
  std::set<std::string> out;
  for (const auto& [key, value] : outputs.items()) {
    if (value.is_string()) out.insert(value.get<std::string>());
    if (value.is_array())
      for (const auto& v : value) out.insert(v.get<std::string>());
  }
  return out;
}

}  // namespace

TEST(PoseSlicerOutputs, ASegmentationComesBackWithItsNamesColoursAndTerminology) {
  ScratchDir dir("pose-slicer");
  ASSERT_EQ(
      runCommand("repose", "phantom --voxel 4 --out " + shellQuote(dir.path().string())).exitCode,
      0);
  // The user's segmentation: the phantom's labels renamed, recoloured and coded as a Slicer user
  // would have them, plus a segment with no voxels (a structure the user made but left empty).
  Volume G = readVolume(dir.file("G.nii.gz"));
  LabelTable table;
  for (const Label& l : G.labels().labels()) {
    Label user = l;
    user.name = "patient " + l.name;
    user.color = {(l.value % 7) / 7.0, (l.value % 5) / 5.0, (l.value % 3) / 3.0};
    user.colorGenerated = false;
    user.id = "user_" + std::to_string(l.value);
    user.tags =
        "TerminologyEntry:Segmentation category and type - 3D Slicer General Anatomy "
        "list~SCT^123037004^Anatomical Structure~SCT^" +
        std::to_string(10000 + l.value) + "^" + l.name + "~^^~Anatomic codes~^^~^^|";
    table.set(user);
  }
  Label empty;
  empty.value = 250, empty.name = "planned implant", empty.color = {0.1, 0.9, 0.3};
  empty.id = "implant";
  empty.tags = "Segmentation.Status:completed|";
  table.set(empty);
  G.labels() = table;
  writeVolume(G, dir.file("G.seg.nrrd"));

  const std::string common = "pose --input " + shellQuote(dir.file("G.seg.nrrd")) + " --parts " +
                             shellQuote(dir.file("S.nii.gz")) + " --pose " +
                             shellQuote(suitePoseFile("elbow90")) + " --out " +
                             shellQuote(dir.file("out")) + " --json";
  const CommandResult run = runCommand("repose", common);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  // auto: a .seg.nrrd input gives .seg.nrrd outputs, and only those.
  std::set<std::string> files = filesIn(dir.file("out"));
  EXPECT_EQ(files, (std::set<std::string>{"posed_G.seg.nrrd", "posed_S.seg.nrrd", "transform.nrrd",
                                          "report.json"}));
  nlohmann::json report = readJsonFile(dir.file("out/report.json"));
  EXPECT_EQ(report["outputs"]["posed_labels"], "posed_G.seg.nrrd");
  for (const std::string& f : reportedFiles(report["outputs"])) EXPECT_TRUE(files.count(f)) << f;

  const Volume posed = readVolume(dir.file("out/posed_G.seg.nrrd"));
  ASSERT_EQ(posed.labels().size(), table.size());
  for (const Label& l : table.labels()) {
    const Label* p = posed.labels().find(l.value, l.layer);
    ASSERT_NE(p, nullptr) << l.name;
    EXPECT_EQ(p->name, l.name);
    EXPECT_EQ(p->id, l.id);
    EXPECT_EQ(p->tags, l.tags);
    EXPECT_FALSE(p->colorGenerated) << l.name;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p->color[c], l.color[c], 1e-6) << l.name;
  }
  // The posed body-part map names its parts too.
  const Volume posedS = readVolume(dir.file("out/posed_S.seg.nrrd"));
  EXPECT_NE(posedS.labels().find(4), nullptr);

  // Re-run into the same folder as NIfTI: a colour table beside each map, the segmentations of the
  // first run gone.
  const CommandResult nifti = runCommand("repose", common + " --output-format nii.gz");
  ASSERT_EQ(nifti.exitCode, 0) << nifti.err;
  files = filesIn(dir.file("out"));
  EXPECT_EQ(files, (std::set<std::string>{"posed_G.nii.gz", "posed_G.ctbl", "posed_S.nii.gz",
                                          "posed_S.ctbl", "transform.nrrd", "report.json"}));
  report = readJsonFile(dir.file("out/report.json"));
  EXPECT_EQ(reportedFiles(report["outputs"]),
            (std::set<std::string>{"posed_G.nii.gz", "posed_G.ctbl", "posed_S.nii.gz",
                                   "posed_S.ctbl", "transform.nrrd"}));
  std::ifstream ctbl(dir.file("out/posed_G.ctbl"));
  std::string line, liverLine;
  while (std::getline(ctbl, line))
    if (line.rfind("250 ", 0) == 0) liverLine = line;
  EXPECT_EQ(liverLine, "250 planned_implant 26 230 77 255");

  // DICOM SEG in and out: the segmentation as a DICOM SEG of liver.dcm's patient, posed into
  // posed_G.dcm: the same posed voxels, names, colours and codes, and the same patient.
  WriteOptions asDicom;
  asDicom.sourceDicom = dataPath("dcmqi_ct3slice/liver.dcm");
  writeVolume(G, dir.file("G.dcm"), asDicom);
  // With a SpacingBetweenSlices its frames do not keep (copied from another series): the reader
  // places the frames by their own spacing and says so, and the report keeps what it said.
  ASSERT_TRUE(setSegSpacingBetweenSlices(dir.file("G.dcm"), "7.5"));
  std::string dicomCommon = common;
  dicomCommon.replace(dicomCommon.find(shellQuote(dir.file("G.seg.nrrd"))),
                      shellQuote(dir.file("G.seg.nrrd")).size(), shellQuote(dir.file("G.dcm")));
  const CommandResult dcm = runCommand("repose", dicomCommon + " --output-format dcmseg");
  ASSERT_EQ(dcm.exitCode, 0) << dcm.err;
  EXPECT_EQ(filesIn(dir.file("out")),
            (std::set<std::string>{"posed_G.dcm", "posed_S.dcm", "transform.nrrd", "report.json"}));
  report = readJsonFile(dir.file("out/report.json"));
  EXPECT_EQ(report["outputs"]["posed_labels"], "posed_G.dcm");
  ASSERT_EQ(report["input_notes"].size(), 1u) << report.dump();
  const std::string note = report["input_notes"][0].get<std::string>();
  EXPECT_NE(note.find("G.dcm: its frames are not 7.5"), std::string::npos) << note;
  EXPECT_NE(dcm.err.find("repose: note: " + note), std::string::npos) << dcm.err;
  {
    DcmFileFormat in, out;
    ASSERT_TRUE(in.loadFile(asDicom.sourceDicom.c_str()).good());
    ASSERT_TRUE(out.loadFile(dir.file("out/posed_G.dcm").c_str()).good());
    OFString a, b;
    in.getDataset()->findAndGetOFString(DCM_PatientID, a);
    out.getDataset()->findAndGetOFString(DCM_PatientID, b);
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(std::string(a.c_str()), std::string(b.c_str()));
  }
  const Volume posedDicom = readVolume(dir.file("out/posed_G.dcm"));
  EXPECT_TRUE(sameVoxels(posedDicom, posed));
  EXPECT_LT(matrixDifference(posedDicom.geometry().ijkToRas, posed.geometry().ijkToRas), 1e-6);
  ASSERT_EQ(posedDicom.labels().size(), table.size());
  for (const Label& l : table.labels()) {
    const Label* p = posedDicom.labels().find(l.value, l.layer);
    ASSERT_NE(p, nullptr) << l.name;
    EXPECT_EQ(p->name, l.name);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p->color[c], l.color[c], 0.5 / 255) << l.name;
    // DICOM needs codes: a segment without them is coded SCT Tissue.
    EXPECT_EQ(terminologyFromTags(p->tags),
              terminologyFromTags(l.tags).value_or(genericTissueTerminology()))
        << l.name;
  }

  // Both.
  const CommandResult both = runCommand("repose", common + " --output-format both");
  ASSERT_EQ(both.exitCode, 0) << both.err;
  EXPECT_EQ(filesIn(dir.file("out")).size(), 8u);

  // A format that does not exist: a usage error, nothing touched.
  const CommandResult bad = runCommand("repose", common + " --output-format png");
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.err.find("--output-format must be"), std::string::npos) << bad.err;
  EXPECT_EQ(filesIn(dir.file("out")).size(), 8u);
  const CommandResult badRounding = runCommand("repose", common + " --label-volumes cubic");
  EXPECT_EQ(badRounding.exitCode, 2);
  EXPECT_NE(badRounding.err.find("--label-volumes must be"), std::string::npos) << badRounding.err;
  EXPECT_EQ(filesIn(dir.file("out")).size(), 8u);
}

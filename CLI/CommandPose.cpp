// `repose pose --input G --parts S --pose P.pose.json --out DIR`: the whole job. Builds the cage
// and transfer mesh (with the separations the pose asks for) or reuses them from a scene folder,
// then for each frame of the pose (one, or one per keyframe): poses the cage (handle groups
// rigidly, free vertices by ARAP), deforms the mesh (Green coordinates, the handles' influence,
// the rigidity solver), rasterizes G, S (and the image) at full resolution, exports the
// displacement field and writes report.json with the quality checks of docs/QUALITY.md.
#include "ArgParser.h"
#include "StderrLine.h"
#include "Commands.h"
#include "FolderClaim.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "SlabRanksCli.h"
#include "SlicerModuleXml.h"
#include "TerminalProgress.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/MeshIO.h"
#include "repose/io/NrrdIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/pose/Pose.h"
#include "repose/pose/PoseFrame.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseReport.h"
#include "repose/pose/PoseRig.h"
#include "repose/pose/PoseRun.h"
#include "repose/pose/SceneFolder.h"
#include "repose/raster/PocketFilling.h"
#include "repose/raster/Rasterizer.h"
#include "repose/rig/Rig.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include <stdlib.h>

namespace repose::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The frame a 3D Slicer CLI module (or a script) takes back as single files, and the report's
// headline figures as Slicer's return parameters.
struct FrameOutputs {
  std::string labels, parts, image, transform, returnParameters;
  std::size_t frame = 0;
  bool any() const {
    return !labels.empty() || !parts.empty() || !image.empty() || !transform.empty();
  }
};

std::string formatFixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

void writeFrameOutputs(const FrameOutputs& o, const PosedFrame& posed) {
  if (!o.labels.empty()) writeVolume(posed.organs, o.labels);
  if (!o.parts.empty()) writeVolume(posed.parts, o.parts);
  if (!o.image.empty() && posed.image) writeVolume(*posed.image, o.image);
  if (!o.transform.empty()) writeDisplacementFieldNrrd(posed.field, posed.grid, o.transform);
}

// "name = value" lines, as ModuleDescription::ReadParameterFile reads them; the names are the
// return parameters of the module's XML (SlicerModuleXml.cpp).
void writeReturnParameters(const std::string& path, const json& report) {
  const json& q = report["quality"];
  std::ostringstream out;
  out.precision(6);
  out << "bodyVolumeChangePercent = " << report["body"]["volume_change_percent"].get<double>()
      << "\nworstLabelChangePercent = "
      << q["labels_within_1_percent"]["worst_change_percent"].get<double>()
      << "\nlabelsLost = " << report["labels_lost"].get<std::int64_t>() << "\n";
  if (q.contains("bones_rigid"))
    out << "bonesMinDice = " << q["bones_rigid"]["min_dice"].get<double>() << "\n";
  std::string missed;
  for (const auto& line : report["targets"]["missed"])
    missed += (missed.empty() ? "" : "; ") + line.get<std::string>();
  out << "targetsMissed = " << missed << "\n";
  writeTextFileAtomically(path, out.str());
}

// A hidden folder for the frames when the caller wants only single files (no --out): beside the
// first of them, removed at the end.
struct ScratchFolder {
  std::string path;
  explicit ScratchFolder(const std::string& besideFile) {
    std::string pattern =
        (fs::absolute(besideFile).parent_path() / ".repose-frames-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw Error(besideFile + ": cannot write in its folder");
    path = pattern;
  }
  ~ScratchFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

// What setUpPose reads and checks, held for the frames (the job refers to the volumes: not
// moved once made).
struct PoseSetup {
  FrameOutputs single;
  bool quiet = false;
  std::function<void(const std::string&)> say;
  std::optional<ScratchFolder> scratch;
  std::string outDir;
  LabelMapFiles labelMapFiles = LabelMapFiles::Nifti;
  std::optional<FolderClaim> outClaim, sceneClaim;
  double budget = 0, spacingMm = 0;
  int threads = 0;
  std::optional<double> background;
  std::optional<Volume> organs, parts, image;
  std::unique_ptr<PoseJob> job;
  SceneRig sceneRig;
};

// Everything `repose pose` reads and checks before its frames: the request, the inputs, the job
// and its rig. `speak`: say what it does (a rank of an MPI job other than 0 does not); `claim`:
// claim the output and scene folders, build and save the rig when the scene has none (over MPI
// rank 0 does, before the other ranks read the scene it left).
void setUpPose(const ArgParser& p, PoseSetup& s, bool speak, bool claim) {
  FrameOutputs& single = s.single;
  single.labels = p.get("posed-labels"), single.parts = p.get("posed-parts");
  single.image = p.get("posed-image"), single.transform = p.get("transform");
  single.returnParameters = p.get("returnparameterfile");
  if (p.getInt("frame") < 0) throw UsageError{"--frame must be >= 0"};
  if (p.has("out-of-core") && !(single.labels.empty() && single.parts.empty() &&
                                single.image.empty() && single.transform.empty()))
    throw UsageError{
        "--out-of-core writes the frames into --out only: not with --posed-labels, "
        "--posed-parts, --posed-image or --transform"};
  single.frame = static_cast<std::size_t>(p.getInt("frame"));
  for (const char* required : {"input", "parts", "pose"})
    if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
  if (!p.has("out") && !single.any())
    throw UsageError{"--out is required (or --posed-labels, --posed-parts, --transform)"};
  if (!single.transform.empty() && formatForPath(single.transform) != FileFormat::Nrrd)
    throw UsageError{"--transform must name a .nrrd file"};
  for (const std::string& f : {single.labels, single.parts, single.image})
    if (!f.empty()) formatForPath(f);  // an unknown extension is refused before the work
  if (!single.image.empty() && !p.has("image")) throw UsageError{"--posed-image needs --image"};
  if (speak && p.has("slicer-progress"))
    startSlicerProgress("repose pose", "posing " + p.get("input"));
  s.quiet = p.has("json") || !speak;
  s.say = [quiet = s.quiet](const std::string& text) {
    if (!quiet) std::cout << text << std::endl;
  };
  const bool quiet = s.quiet;
  const auto& say = s.say;

  // Everything that can be refused is checked before the work.
  Pose pose = readPoseFile(p.get("pose"));
  PoseJobRequest request;
  request.organsName = p.get("input");
  request.partsPath = p.get("parts");
  if (p.has("image")) request.imageName = p.get("image");
  request.tissuesPath = p.has("tissues") ? p.get("tissues") : "";
  // Read first, so a bad skeleton file is refused before the volumes are read.
  request.skeleton = skeletonFor(p.get("parts"), p.get("skeleton"));
  request.jointRings = static_cast<int>(p.getInt("joint-rings"));
  request.autoSeparate = !p.has("no-auto-separate");
  request.volumeRestoration = !p.has("no-volume-restoration");
  s.spacingMm = p.getDouble("spacing-mm");
  if (!(s.spacingMm >= 0)) throw UsageError{"--spacing-mm must be >= 0"};
  s.background = p.getDoubleUnless("background", "min");
  std::optional<ScratchFolder>& scratch = s.scratch;
  if (!p.has("out"))
    scratch.emplace(!single.labels.empty()      ? single.labels
                    : !single.parts.empty()     ? single.parts
                    : !single.transform.empty() ? single.transform
                                                : single.image);
  s.outDir = scratch ? scratch->path + "/frames" : p.get("out");
  const std::string& outDir = s.outDir;
  if (p.get("label-volumes") != "preserve" && p.get("label-volumes") != "nearest")
    throw UsageError{"--label-volumes must be preserve or nearest"};
  const std::string format = p.get("output-format");
  if (format != "auto" && format != "nii.gz" && format != "seg.nrrd" && format != "both" &&
      format != "dcmseg")
    throw UsageError{"--output-format must be auto, nii.gz, seg.nrrd, both or dcmseg"};
  s.labelMapFiles = labelMapFilesFor(format, p.get("input"));
  for (const char* in : {"input", "parts", "image", "pose"})
    if (p.has(in) && fs::exists(p.get(in)) && fs::exists(outDir) &&
        fs::equivalent(p.get(in), outDir))
      throw UsageError{"--out names an input"};
  if (!fs::exists(fs::absolute(outDir).parent_path()))
    throw Error(outDir + ": its parent folder does not exist");
  // One run at a time into this output folder and this scene: a second run refuses at once,
  // instead of interleaving its frames or its rig files with the first's.
  // (Over MPI rank 0 claims them for every rank.)
  if (claim) {
    s.outClaim.emplace(outDir);
    if (p.has("scene") && !s.outClaim->holds(p.get("scene"))) s.sceneClaim.emplace(p.get("scene"));
    for (const std::string& name : s.outClaim->staleRemoved())
      say("removed " + (fs::path(outDir) / name).string() + ", left by a run that was killed");
  }
  const double budget = s.budget =
      p.has("mpi") ? rankMemoryBudget(p.get("memory")) : parseMemoryBudget(p.get("memory"));
  const int threads = s.threads = p.has("mpi") ? rankThreads(static_cast<int>(p.getInt("threads")))
                                               : static_cast<int>(p.getInt("threads"));
  RigSettings& rs = request.settings;
  rs.cageVertices = static_cast<int>(p.getInt("cage-vertices"));
  rs.dilateMm = p.getDouble("dilate-mm");
  rs.meshMm = p.getDouble("mesh-mm");
  rs.threads = threads;
  rs.wholeOrgans = !p.has("bend-organs");
  if (rs.meshMm < 0) throw UsageError{"--mesh-mm must be >= 0"};
  if (p.getInt("joint-rings") < -1 || p.getInt("joint-rings") > 8)
    throw UsageError{"--joint-rings must be -1..8"};

  // The inputs are held in core for the whole job: each read refuses, with the numbers, what the
  // budget cannot hold; the frames are checked against what is left (checkGrid below).
  // What the reader decided about the input (a DICOM SEG's grid, a fractional SEG thresholded):
  // said at once, and kept in each frame's report ("input_notes").
  ReadOptions organsRead = readOptionsWithin(budget, !quiet);
  organsRead.note = [&request, say = organsRead.note](const std::string& n) {
    request.organsNotes.push_back(n);
    if (say) say(n);
  };
  const Volume& organs = s.organs.emplace(readVolume(p.get("input"), organsRead));
  Volume& parts = s.parts.emplace(readVolume(p.get("parts"), readOptionsWithin(budget, !quiet)));
  if (const std::string w = nameBodyPartsByRigConvention(parts, p.get("parts"));
      !w.empty() && speak)
    stderrLine("repose pose: warning: " + w);
  requirePoseableLabels(organs, p.get("input"));
  requirePoseableLabels(parts, p.get("parts"));
  if (speak) {
    warnUnnamedLabels(organs, p.get("input"), "pose");
    warnUnnamedLabels(parts, p.get("parts"), "pose");
  }
  std::optional<Volume>& image = s.image;
  if (p.has("image")) image = readVolume(p.get("image"), readOptionsWithin(budget, !quiet));
  // The job's policy (Core): tissues, skeleton and joints, separations, how the rig is built.
  s.job = std::make_unique<PoseJob>(std::move(pose), organs, parts, std::move(request),
                                    image ? &*image : nullptr);
  const PoseJob& job = *s.job;
  if (speak)
    for (const std::string& line : job.warnings()) stderrLine("repose pose: warning: " + line);
  for (const ContactSeparation& c : job.separations().automatic.made)
    say("separating " + c.names[0] + " from " + c.names[1] +
        (c.touchingVoxels > 0
             ? " where they touch (" + std::to_string(c.touchingVoxels) + " touching, "
             : " across a gap of " + formatFixed(c.gapMm, 1) + " mm (") +
        std::to_string(c.contactVoxels) + " voxels within " +
        formatFixed(job.separations().automatic.reachMm, 0) + " mm" +
        (c.joint.empty() ? std::string() : ", outside the " + c.joint + " joint") + ")");
  // Cage and transfer mesh: from the scene when it matches, else built (and saved there).
  SceneRigRun sceneRun;
  if (p.has("scene")) sceneRun.folder = p.get("scene");
  sceneRun.inputs = {p.get("input"), p.get("parts"), p.has("image") ? p.get("image") : ""};
  sceneRun.threads = threads;
  sceneRun.buildProgress = quiet ? ProgressFn{} : terminalProgress();
  sceneRun.say = say;
  sceneRun.note = [speak](const std::string& line) {
    if (speak) stderrLine("repose pose: note: " + line);
  };
  s.sceneRig = rigForScene(job, sceneRun);
  const PoseRig& rig = *s.sceneRig.rig;
  if (single.frame >= rig.frameCount())
    throw Error(p.get("pose") + ": has " + std::to_string(rig.frameCount()) +
                " frame(s); --frame " + std::to_string(single.frame) + " is not one of them");
  if (claim) fs::create_directories(outDir);
}

// The frames of a set-up job, each made, written and said; over `ranks` (--mpi) every rank runs
// them and rank 0 writes and says. Returns the exit status.
int poseFrames(const ArgParser& p, const PoseSetup& s, SlabRanks* ranks,
               std::chrono::steady_clock::time_point start) {
  const FrameOutputs& single = s.single;
  const auto& say = s.say;
  const bool quiet = s.quiet;
  const std::string& outDir = s.outDir;
  const std::optional<ScratchFolder>& scratch = s.scratch;
  const LabelMapFiles labelMapFiles = s.labelMapFiles;
  const double budget = s.budget, spacingMm = s.spacingMm;
  const std::optional<double> background = s.background;
  const Volume &organs = *s.organs, &parts = *s.parts;
  const std::optional<Volume>& image = s.image;
  const PoseJob& job = *s.job;
  const PoseRig& rig = *s.sceneRig.rig;
  const bool reused = s.sceneRig.reused;
  const bool oneFrame = rig.frameCount() == 1;
  // The frame step is Core's (pose/PoseRun.h): this command says what it was asked and what
  // came back.
  FrameRun run;
  run.ranks = ranks;
  run.image = image ? &*image : nullptr;
  run.background = background;  // unset: the image's minimum (Core's rule)
  run.spacingMm = spacingMm;
  run.fillPockets = !p.has("keep-pockets");
  run.preserveLabelVolumes = p.get("label-volumes") == "preserve";
  run.labelMapFiles = labelMapFiles;
  run.memoryBudget = budget;
  // A frame beyond the budget is made slab by slab into its folder (Core's poseFrameToFolder),
  // unless a single-file output asks for the frame whole in memory.
  run.outOfCore = single.labels.empty() && single.parts.empty() && single.image.empty() &&
                  single.transform.empty();
  run.alwaysOutOfCore = p.has("out-of-core") || ranks;
  run.budgetHint =
      "--memory; without --posed-labels, --posed-parts, --posed-image and "
      "--transform the frame is made slab by slab";
  run.sceneReused = reused;
  if (labelMapFiles == LabelMapFiles::DicomSeg)
    run.write.sourceDicom = dicomSourceOf(p.get("input"));
  if (p.has("scene")) {  // a Slicer scene of the frame, with the rig kept in the scene folder
    const fs::path scene = fs::absolute(p.get("scene"));
    run.write.sceneInputLabels = fs::absolute(p.get("input")).string();
    run.write.sceneCage = (scene / "cage.vtk").string();
    run.write.sceneTransferMesh = (scene / "tm.vtu").string();
  }
  json summary = json::array();
  int missedFrames = 0;
  for (std::size_t index = 0; index < rig.frameCount(); ++index) {
    const std::string frameName = rig.frameName(index);
    const fs::path dir = oneFrame ? fs::path(outDir) : fs::path(outDir) / frameName;
    run.folder = dir.string();
    run.budgetWhat = outDir + ": frame " + frameName;
    run.onGrid = [&](const VolumeGeometry& grid) {
      say("frame " + frameName + ": " + std::to_string(grid.dims[0]) + " x " +
          std::to_string(grid.dims[1]) + " x " + std::to_string(grid.dims[2]) + " voxels");
    };
    run.progress = quiet ? ProgressFn{} : terminalProgress();
    // What a pose can do wrong (the body volume the posed mesh predicts, bones run into each
    // other, folds), said on stderr as soon as it is known (stdout may be JSON).
    run.warn = [&](const std::string& line) {
      if (!ranks || ranks->root())  // every rank starts the frame; rank 0 says
        stderrLine("repose pose: warning: frame " + frameName + ": " + line);
    };
    const FrameOutcome outcome = runPoseFrame(job, rig, index, organs, parts, run);
    if (ranks && !ranks->root()) continue;  // rank 0 writes and says
    const PosedFrame& posed = outcome.frame;
    const json report = json::parse(outcome.reportJson);
    if (index == single.frame) {
      writeFrameOutputs(single, posed);
      if (!single.returnParameters.empty()) writeReturnParameters(single.returnParameters, report);
    }
    if (outcome.streamed)
      say(std::string("  made slab by slab") +
          (ranks                 ? " over " + std::to_string(ranks->size()) + " ranks (--mpi): "
           : run.alwaysOutOfCore ? std::string(" (--out-of-core): ")
                                 : std::string(" (its posed volumes exceed --memory): ")) +
          std::to_string(report["streamed"]["slabs"].get<std::int64_t>()) + " slabs of " +
          std::to_string(report["streamed"]["slab_slices"].get<std::int64_t>()) + " slices");
    const json& q = report["quality"];
    say("  body volume " + std::to_string(report["body"]["volume_change_percent"].get<double>()) +
        " %, worst label " +
        std::to_string(q["labels_within_1_percent"]["worst_change_percent"].get<double>()) + " %" +
        (q.contains("bones_rigid")
             ? ", bones min Dice " + std::to_string(q["bones_rigid"]["min_dice"].get<double>())
             : std::string()) +
        "; quality targets " + (q["all_met"].get<bool>() ? "met" : "NOT all met") + " -> " +
        (dir / "report.json").string());
    // A frame that missed a target is written all the same (users may want it), and said so in
    // one line naming what missed; the exit status says it too.
    if (!outcome.targetsMet) {
      stderrLine("repose pose: frame " + frameName +
                 " written, but it missed its targets: " + outcome.missedLine());
      ++missedFrames;
    }
    summary.push_back(report);
  }
  if (ranks && !ranks->root()) return 0;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (quiet)
    std::cout << (oneFrame ? summary[0] : json{{"frames", summary}, {"seconds", seconds}}).dump(2)
              << "\n";
  else
    say("done in " + std::to_string(int(seconds)) + " s: " + (scratch ? "" : outDir));
  endSlicerProgress("repose pose");
  // In 3D Slicer a non-zero exit loads nothing: there the miss is the stderr line and the
  // targetsMissed return parameter (the module completes "with errors" and loads the frame).
  return missedFrames > 0 && !p.has("slicer-progress") ? kExitTargetsMissed : 0;
}

}  // namespace

int runPose(const Args& args) {
  if (printSlicerModuleXml(args, "pose")) return 0;  // 3D Slicer asking for the description
  ArgParser p("pose",
              "The whole job: pose a label map G (with its body-part map S, and an image) by a\n"
              "pose file. Writes, per frame (one, or one per keyframe, in DIR/<frame>/):\n"
              "posed_G and posed_S (--output-format), posed_image.nii.gz (with --image),\n"
              "transform.nrrd (displacement field, LPS, output->input) and report.json.\n"
              "Exit status 0 when every frame met its quality targets, 4 when every frame was\n"
              "written but some missed (one line each on stderr; report.json's \"targets\"),\n"
              "1 on an error (nothing written), 2 on a usage error.");
  p.option("input", "FILE", "label map G (NIfTI, NRRD, .seg.nrrd)")
      .option("parts", "FILE", "body-part map S on G's grid (the cage and mesh follow it)")
      .option("image", "FILE", "optional intensity image on G's grid, posed alongside")
      .option("background", "VALUE",
              "image value where no tissue is (with --image): a number, or min for the image's "
              "minimum (air in a CT)",
              "min")
      .option("pose", "FILE", "pose file (*.pose.json, docs/POSES.md)")
      .option("out", "DIR",
              "output folder (created if missing; its parent must exist); may be left out when "
              "--posed-labels, --posed-parts or --transform take the results")
      .option("scene", "DIR",
              "reuse the cage and mesh saved here when they match S and the settings, else "
              "build them and save them here; each frame then also gets scene.mrml, a 3D Slicer "
              "scene of G, the posed G, the transform, the cage and the mesh")
      .option("tissues", "CSV",
              "label,name,density_kg_m3,rigid[,bone] (default: tissues.csv beside S, as "
              "`repose rig` writes it, else the phantom's table when G's labels are the "
              "phantom's)")
      .option("skeleton", "JSON",
              "the joints a pose file names (default: skeleton.json beside S, as `repose rig` "
              "and `repose phantom` write it)")
      .option("spacing-mm", "MM",
              "write the posed maps on an isotropic grid of this voxel size (0: the input's "
              "spacing; a finer grid keeps thin structures of thick-slice inputs)",
              "0")
      .option("output-format", "FORMAT",
              "the posed label maps as nii.gz (each with a 3D Slicer colour table, .ctbl), "
              "seg.nrrd (Slicer segmentations: names, colours, terminology), both, dcmseg "
              "(DICOM SEG, patient and study from a DICOM input), or auto (seg.nrrd when "
              "--input is a .seg.nrrd, else nii.gz)",
              "auto")
      .option("cage-vertices", "N",
              "cage size; a cage that fails its checks is built again with more vertices, then "
              "other dilations (report.json's \"cage\" says which)",
              "300")
      .option("dilate-mm", "MM", "cage distance from the body", "10")
      .option("mesh-mm", "MM", "transfer-mesh tet size (0: 5% of S's diagonal)", "0")
      .option("joint-rings", "N",
              "widen each joint's transition by N rings of mesh vertices (-1: the pose file's "
              "joint_rings; docs/QUALITY.md)",
              "-1")
      .option("threads", "N", "worker threads (0: all cores)", "0")
      .flag("bend-organs",
            "mesh the organs with the soft tissue around them, so a joint's bend may reach them "
            "(by default bones and organs that lie in one body part move as whole pieces; "
            "docs/QUALITY.md)")
      .flag("no-auto-separate",
            "do not cut apart the body parts that move with different groups where they touch "
            "(by default they are, except across their own joint: docs/POSES.md)")
      .flag("no-volume-restoration",
            "leave each frame's mesh as the solve and the joint bends place it (by default the "
            "soft tissue's vertices at the joints are relaxed so every body part keeps its "
            "volume: docs/ARCHITECTURE.md)")
      .option("label-volumes", "MODE",
              "preserve: round each soft label of G to the volume the deformation gives it "
              "(label borders relabelled; docs/QUALITY.md); nearest: plain nearest-neighbour "
              "sampling",
              "preserve")
      .flag("keep-pockets",
            "keep the background pockets a bent joint traps inside the body (by default they "
            "are filled from their neighbours; docs/QUALITY.md)")
      .flag("json", "print the frames' reports as JSON on stdout")
      .option("posed-labels", "FILE", "also write the posed G of frame --frame here (any format)")
      .option("posed-parts", "FILE", "also write the posed S of frame --frame here")
      .option("posed-image", "FILE", "also write the posed image of frame --frame here")
      .option("transform", "FILE", "also write frame --frame's displacement field here (.nrrd)")
      .option("frame", "K", "the frame the four options above take (0: the first)", "0")
      .option("returnparameterfile", "FILE",
              "write frame --frame's headline figures here as 3D Slicer's return parameters "
              "(name = value lines)")
      .option("processinformationaddress", "ADDRESS",
              "passed by 3D Slicer to in-process modules; ignored")
      .flag("out-of-core",
            "make every frame slab by slab and write it as it goes, slabs sized to --memory "
            "(what a frame whose posed volumes exceed --memory gets anyway): the same files "
            "and report")
      .flag("mpi",
            "under mpirun: the ranks share each frame's slabs (ranks 1..N-1 make them, rank 0 "
            "writes the frame as it goes): the same files as one process. Needs --scene, the "
            "rig every rank reads; each rank's --memory default is its share of half the RAM")
      .flag("slicer-progress",
            "progress as the <filter-progress> lines 3D Slicer's CLI modules print on stdout "
            "(the installed ReposePose module sets it)");
  declareMemoryOption(p,
                      "a frame whose posed volumes need more is made slab by slab and written as "
                      "it goes (the same files and report), unless --posed-labels, --posed-parts, "
                      "--posed-image or --transform ask for it whole");
  if (!p.parse(args)) return 0;
  const auto start = std::chrono::steady_clock::now();
  PoseSetup s;
  if (!p.has("mpi")) {
    setUpPose(p, s, true, true);
    return poseFrames(p, s, nullptr, start);
  }
  // Over MPI: rank 0 sets up first (claims the folders, builds or checks the scene's rig), then
  // the others read the same inputs and the rig from the scene. A failure anywhere ends every
  // rank, said once by rank 0.
  const std::unique_ptr<SlabRanks> ranks = makeSlabRanks();
  ranks->together([&] {
    if (!p.has("scene"))
      throw UsageError{"--mpi needs --scene DIR: the ranks share the rig saved there"};
    if (p.has("posed-labels") || p.has("posed-parts") || p.has("posed-image") || p.has("transform"))
      throw UsageError{
          "--mpi writes the frames into --out only: not with --posed-labels, --posed-parts, "
          "--posed-image or --transform"};
    if (ranks->root()) setUpPose(p, s, true, true);
  });
  ranks->together([&] {
    if (!ranks->root()) setUpPose(p, s, false, false);
  });
  return poseFrames(p, s, ranks.get(), start);
}

}  // namespace repose::cli

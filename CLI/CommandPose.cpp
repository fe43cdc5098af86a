// `repose pose --input G --parts S --pose P.pose.json --out DIR`: the whole job. Builds the cage
// and transfer mesh (with the separations the pose asks for) or reuses them from a scene folder,
// then for each frame of the pose (one, or one per keyframe): poses the cage (handle groups
// rigidly, free vertices by ARAP), deforms the mesh (Green coordinates, the handles' influence,
// the rigidity solver), rasterizes G, S (and the image) at full resolution, exports the
// displacement field and writes report.json with the quality checks of docs/QUALITY.md.
#include "ArgParser.h"
#include "Commands.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
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
#include "repose/pose/SceneFolder.h"
#include "repose/raster/PocketFilling.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

namespace repose::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

}  // namespace

int runPose(const Args& args) {
  ArgParser p("pose",
              "The whole job: pose a label map G (with its body-part map S, and an image) by a\n"
              "pose file. Writes, per frame (one, or one per keyframe, in DIR/<frame>/):\n"
              "posed_G.nii.gz, posed_S.nii.gz, posed_image.nii.gz (with --image),\n"
              "transform.nrrd (displacement field, LPS, output->input) and report.json.");
  p.option("input", "FILE", "label map G (NIfTI, NRRD, .seg.nrrd)")
      .option("parts", "FILE", "body-part map S on G's grid (the cage and mesh follow it)")
      .option("image", "FILE", "optional intensity image on G's grid, posed alongside")
      .option("background", "VALUE", "image value where no tissue is (with --image)", "0")
      .option("pose", "FILE", "pose file (*.pose.json, docs/POSES.md)")
      .option("out", "DIR", "output folder (created if missing; its parent must exist)")
      .option("scene", "DIR",
              "reuse the cage and mesh saved here when they match S and the settings, else "
              "build them and save them here")
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
      .option("cage-vertices", "N", "cage size", "300")
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
      .flag("keep-pockets",
            "keep the background pockets a bent joint traps inside the body (by default they "
            "are filled from their neighbours; docs/QUALITY.md)")
      .flag("json", "print the frames' reports as JSON on stdout");
  declareMemoryOption(p, "a pose that would need more is refused before the work");
  if (!p.parse(args)) return 0;
  for (const char* required : {"input", "parts", "pose", "out"})
    if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
  const auto start = std::chrono::steady_clock::now();
  const bool quiet = p.has("json");
  auto say = [&](const std::string& text) {
    if (!quiet) std::cout << text << std::endl;
  };

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
  const double spacingMm = p.getDouble("spacing-mm");
  if (!(spacingMm >= 0)) throw UsageError{"--spacing-mm must be >= 0"};
  const std::string outDir = p.get("out");
  for (const char* in : {"input", "parts", "image", "pose"})
    if (p.has(in) && fs::exists(p.get(in)) && fs::exists(outDir) &&
        fs::equivalent(p.get(in), outDir))
      throw UsageError{"--out names an input"};
  if (!fs::exists(fs::absolute(outDir).parent_path()))
    throw Error(outDir + ": its parent folder does not exist");
  const double budget = parseMemoryBudget(p.get("memory"));
  const int threads = static_cast<int>(p.getInt("threads"));
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
  const Volume organs = readVolume(p.get("input"), readOptionsWithin(budget, !quiet));
  const Volume parts = readVolume(p.get("parts"), readOptionsWithin(budget, !quiet));
  requirePoseableLabels(organs, p.get("input"));
  requirePoseableLabels(parts, p.get("parts"));
  warnUnnamedLabels(organs, p.get("input"), "pose");
  warnUnnamedLabels(parts, p.get("parts"), "pose");
  std::optional<Volume> image;
  if (p.has("image")) image = readVolume(p.get("image"), readOptionsWithin(budget, !quiet));
  // The job's policy (Core): tissues, skeleton and joints, separations, how the rig is built.
  const PoseJob job(std::move(pose), organs, parts, std::move(request), image ? &*image : nullptr);
  for (const std::string& line : job.warnings())
    std::cerr << "repose pose: warning: " << line << "\n";
  for (const ContactSeparation& c : job.separations().automatic.made)
    say("separating " + c.names[0] + " from " + c.names[1] + " where they touch (" +
        std::to_string(c.contactVoxels) + " contact voxels" +
        (c.joint.empty() ? std::string() : ", outside the " + c.joint + " joint") + ")");
  // Cage and transfer mesh: from the scene when it matches, else built (and saved there).
  const std::string key = job.sceneKey();
  std::optional<RigGeometry> fromScene;
  if (p.has("scene")) fromScene = readSceneRig(p.get("scene"), key);
  const bool reused = fromScene.has_value();
  RigGeometry geometry;
  if (reused) {
    geometry = std::move(*fromScene);
    say("reusing the cage and transfer mesh of " + p.get("scene"));
  } else {
    say("building the cage (" + std::to_string(rs.cageVertices) + " vertices) and the mesh");
    geometry = job.buildGeometry(quiet ? ProgressFn{} : terminalProgress());
  }
  say("embedding the mesh in the cage");
  const std::unique_ptr<PoseRig> rigHolder = job.makeRig(std::move(geometry), threads);
  const PoseRig& rig = *rigHolder;
  if (p.has("scene") && !reused)
    writeSceneFolder(p.get("scene"), rig, key,
                     {p.get("input"), p.get("parts"), p.has("image") ? p.get("image") : ""},
                     job.settings());
  const bool oneFrame = rig.frameCount() == 1;
  fs::create_directories(outDir);
  PoseFrameOptions fo = job.frameOptions();
  fo.image = image ? &*image : nullptr;
  fo.background = p.getDouble("background");
  fo.spacingMm = spacingMm;
  fo.fillPockets = !p.has("keep-pockets");
  json summary = json::array();
  for (std::size_t index = 0; index < rig.frameCount(); ++index) {
    const std::string frameName = rig.frameName(index);
    // Memory: the posed G and S, the image and the field beside the inputs, refused above the
    // budget before anything is allocated.
    fo.checkGrid = [&](const VolumeGeometry& grid) {
      const double need = double(grid.numVoxels()) * posedBytesPerVoxel(organs, parts, fo.image);
      if (peakResidentBytes() + need > budget)
        throw Error(outDir + ": frame " + frameName + " needs " + gib(need) + " for " +
                    std::to_string(grid.numVoxels()) + " output voxels beyond the " +
                    gib(peakResidentBytes()) + " in use, more than the budget of " + gib(budget) +
                    " (out-of-core posing: `repose warp`)");
      say("frame " + frameName + ": " + std::to_string(grid.dims[0]) + " x " +
          std::to_string(grid.dims[1]) + " x " + std::to_string(grid.dims[2]) + " voxels");
    };
    fo.progress = quiet ? ProgressFn{} : terminalProgress();
    // What a pose can do wrong (the body volume the posed mesh predicts, bones run into each
    // other, folds), said on stderr as soon as it is known (stdout may be JSON).
    fo.warn = [&](const std::string& line) {
      std::cerr << "repose pose: warning: frame " << frameName << ": " << line << std::endl;
    };
    PosedFrame posed = poseFrame(rig, index, organs, parts, fo);
    posed.reportJson = job.completeReport(posed.reportJson, reused);
    const json report = json::parse(posed.reportJson);
    const fs::path dir = oneFrame ? fs::path(outDir) : fs::path(outDir) / frameName;
    writePosedFrame(posed, dir.string());
    const json& q = report["quality"];
    say("  body volume " + std::to_string(report["body"]["volume_change_percent"].get<double>()) +
        " %, worst label " +
        std::to_string(q["labels_within_1_percent"]["worst_change_percent"].get<double>()) + " %" +
        (q.contains("bones_rigid")
             ? ", bones min Dice " + std::to_string(q["bones_rigid"]["min_dice"].get<double>())
             : std::string()) +
        "; quality targets " + (q["all_met"].get<bool>() ? "met" : "NOT all met") + " -> " +
        (dir / "report.json").string());
    summary.push_back(report);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (quiet)
    std::cout << (oneFrame ? summary[0] : json{{"frames", summary}, {"seconds", seconds}}).dump(2)
              << "\n";
  else
    say("done in " + std::to_string(int(seconds)) + " s: " + outDir);
  return 0;
}

}  // namespace repose::cli

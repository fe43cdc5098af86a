// `repose phantom`: writes the synthetic mannequin (organ map G, part map S, skeleton JSON) to a
// folder, streaming slab by slab so any voxel size fits in memory.
#include "ArgParser.h"
#include "Commands.h"
#include "TerminalProgress.h"

#include "repose/phantom/Phantom.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace repose::cli {

namespace {

namespace fs = std::filesystem;

// Below this the grid grows past billions of voxels for no modelling benefit: the phantom's
// thinnest structures are millimetres thick.
constexpr double kMinVoxelMm = 0.2;

std::string humanBytes(double bytes) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB"};
  int u = 0;
  while (bytes >= 1024 && u < 4) bytes /= 1024, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, u ? "%.1f %s" : "%.0f %s", bytes, units[u]);
  return buf;
}

nlohmann::json labelsJson(const LabelTable& table) {
  nlohmann::json out = nlohmann::json::array();
  for (const Label& l : table.labels())
    out.push_back({{"value", l.value}, {"name", l.name}, {"color", l.color}});
  return out;
}

// The output folder is created if missing, but never its parents: a typo should not grow a tree.
void prepareOutputFolder(const std::string& out) {
  std::error_code ec;
  if (fs::is_directory(out, ec)) return;
  if (fs::exists(out, ec)) throwFileError(out, "exists and is not a folder");
  fs::path parent = fs::path(out).parent_path();
  if (parent.empty()) parent = ".";
  if (!fs::is_directory(parent, ec))
    throwFileError(out, "its parent folder " + parent.string() + " does not exist");
  if (!fs::create_directory(out, ec) && !fs::is_directory(out))
    throwFileError(out, "cannot create the folder: " + ec.message());
}

}  // namespace

int runPhantom(const Args& args) {
  ArgParser parser("phantom",
                   "Generates the synthetic whole-body mannequin: an organ map G (skin, fat, "
                   "muscle, bones, organs), a body-part map S (head, torso, limb segments) and the "
                   "skeleton of named joints (RAS mm, JSON). Streams slab by slab, so memory does "
                   "not grow with the voxel count.");
  parser.option("out", "DIR", "output folder (created if missing; its parent must exist)")
      .option("voxel", "MM", "isotropic voxel size in mm (1 mm gives ~160M voxels)", "2")
      .option("spacing", "X,Y,Z",
              "voxel size per axis instead, e.g. 1.8,1.8,4.8 for thick slices like a "
              "reference phantom's")
      .flag("arms-touching", "hands pressed against the hips (the limb-separation case)")
      .flag("arms-resting",
            "real anatomy's contacts and scales: arms against the trunk along their length, hands "
            "on the thighs, thighs touching; long bones as cortical shells around marrow, blood "
            "vessels of a few mm")
      .option("gap-mm", "HAND[,FOREARM]",
              "with --arms-resting, the near contacts of real reference phantoms: each hand HAND "
              "mm off its thigh (a voxel or three) and each forearm FOREARM mm off the trunk and "
              "hip (default 15); the gaps stay air")
      .option("vessel-mm", "D",
              "with --arms-resting, every limb vessel D mm across (about a voxel on a reference "
              "phantom's grid) instead of its anatomical 4-10 mm; they cross the axilla, the "
              "elbow, the groin and the knee",
              "0")
      .flag("girdles-touching",
            "with --arms-resting, the clavicles' medial ends meet over the manubrium, so the two "
            "shoulder girdles touch across the sternum (as on reference phantoms whose clavicles "
            "reach the midline); both arms raised pull them apart")
      .option("labels", "NAME",
              "phantom (its own labels, named in the file), icrp110 (ICRP 110 organ IDs on "
              "ICRP's array order, no label table: a converted reference phantom) or coarse (a "
              "dosimetry user's coarse map, no label table: 1 body, 2 the whole skeleton, 3 "
              "brain, 4 lungs, 5 liver)",
              "phantom")
      .flag("image",
            "also a CT-like image <P>CT.<ext> (int16 HU per tissue, small fixed noise) to pose "
            "alongside G and show under the labels")
      .option("margin", "MM", "empty border around the body in mm", "10")
      .option("format", "EXT", "nii.gz or nii", "nii.gz")
      .option("prefix", "P",
              "file name prefix: <P>G.<ext>, <P>S.<ext>, <P>skeleton.json, <P>CT.<ext>")
      .option("threads", "N", "worker threads (0: all cores)", "0")
      .flag("json", "print a JSON summary on stdout");
  if (!parser.parse(args)) return 0;
  if (!parser.has("out")) throw UsageError{"--out DIR is required"};

  PhantomOptions options;
  options.voxelMm = parser.getDouble("voxel");
  options.marginMm = parser.getDouble("margin");
  options.armsTouching = parser.has("arms-touching");
  options.armsResting = parser.has("arms-resting");
  if (options.armsTouching && options.armsResting)
    throw UsageError{"--arms-touching and --arms-resting exclude each other"};
  if (parser.has("gap-mm")) {
    const std::string text = parser.get("gap-mm");
    double hand = 0, forearm = 15;
    char tail = 0;
    const int n = std::sscanf(text.c_str(), "%lf,%lf%c", &hand, &forearm, &tail);
    if (n < 1 || n > 2 || !std::isfinite(hand) || !std::isfinite(forearm) || hand <= 0 ||
        forearm <= 0 || hand > 100 || forearm > 100)
      throw UsageError{"--gap-mm expects HAND[,FOREARM] in mm (each above 0, at most 100), not " +
                       text};
    if (!options.armsResting) throw UsageError{"--gap-mm needs --arms-resting"};
    options.handGapMm = hand;
    options.forearmGapMm = forearm;
  }
  options.limbVesselMm = parser.getDouble("vessel-mm");
  if (!std::isfinite(options.limbVesselMm) || options.limbVesselMm < 0 || options.limbVesselMm > 20)
    throw UsageError{"--vessel-mm expects a diameter of 0 to 20 mm, not " +
                     parser.get("vessel-mm")};
  if (options.limbVesselMm > 0 && !options.armsResting)
    throw UsageError{"--vessel-mm needs --arms-resting"};
  options.girdlesTouching = parser.has("girdles-touching");
  if (options.girdlesTouching && !options.armsResting)
    throw UsageError{"--girdles-touching needs --arms-resting"};
  if (parser.has("spacing")) {
    const std::string text = parser.get("spacing");
    double v[3];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3)
      throw UsageError{"--spacing expects X,Y,Z in mm, not " + text};
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(v[c]) || v[c] < kMinVoxelMm)
        throw UsageError{"--spacing " + text + ": each size must be at least 0.2 mm"};
    options.spacingMm = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  const std::string labels = parser.get("labels");
  if (labels == "icrp110")
    options.labels = PhantomLabelling::Icrp110;
  else if (labels == "coarse")
    options.labels = PhantomLabelling::Coarse;
  else if (labels != "phantom")
    throw UsageError{"--labels must be phantom, icrp110 or coarse, not " + labels};
  options.threads = static_cast<int>(parser.getInt("threads"));
  if (!std::isfinite(options.voxelMm) || options.voxelMm <= 0)
    throw UsageError{"--voxel must be a positive size in mm, not " + parser.get("voxel")};
  if (options.voxelMm < kMinVoxelMm)
    throw UsageError{"--voxel " + parser.get("voxel") + " mm is too small (at least 0.2 mm)"};
  if (!std::isfinite(options.marginMm) || options.marginMm < 0)
    throw UsageError{"--margin must be zero or more mm, not " + parser.get("margin")};
  if (options.threads < 0) throw UsageError{"--threads cannot be negative"};
  const std::string format = parser.get("format");
  if (format != "nii.gz" && format != "nii")
    throw UsageError{"--format must be nii.gz or nii, not " + format};
  const std::string prefix = parser.get("prefix");
  if (prefix.find('/') != std::string::npos)
    throw UsageError{"--prefix names files, not folders: " + prefix};
  const std::string out = parser.get("out");
  const bool json = parser.has("json");
  if (parser.has("image") && options.labels != PhantomLabelling::Phantom)
    throw UsageError{"--image needs the phantom's own labels (not --labels icrp110)"};

  const Phantom phantom(options);
  const VolumeGeometry& g = phantom.geometry();
  const bool image = parser.has("image");
  const double rawBytes = (image ? 4.0 : 2.0) * g.numVoxels();
  // Label maps of smooth shapes gzip about 40:1; the estimate only has to be the right size.
  const double estimate = format == "nii" ? rawBytes : rawBytes / 40;
  prepareOutputFolder(out);
  std::error_code ec;
  const auto space = fs::space(out, ec);
  if (!ec && format == "nii" && static_cast<double>(space.available) < rawBytes)
    throwFileError(out, "not enough free space: the phantom needs " + humanBytes(rawBytes) + ", " +
                            humanBytes(static_cast<double>(space.available)) + " are free");
  if (!json)
    std::cout << "phantom " << g.dims[0] << " x " << g.dims[1] << " x " << g.dims[2] << " = "
              << g.numVoxels() << " voxels of " << options.spacing().x() << " x "
              << options.spacing().y() << " x " << options.spacing().z() << " mm; writing about "
              << humanBytes(estimate) << (format == "nii" ? "" : " (gzip, estimated)") << " to "
              << out << std::endl;

  const auto start = std::chrono::steady_clock::now();
  const PhantomFiles files =
      writePhantom(phantom, out, "." + format, terminalProgress(), prefix, image);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::uintmax_t written = 0;
  for (const auto& f : {files.organs, files.parts, files.skeleton, files.image})
    if (!f.empty()) written += fs::file_size(f, ec);

  if (json) {
    const Eigen::Vector3d o = g.origin();
    nlohmann::json doc = {
        {"files",
         {{"organs", files.organs},
          {"parts", files.parts},
          {"skeleton", files.skeleton},
          {"image", files.image}}},
        {"dims", g.dims},
        {"voxelMm", options.spacing().maxCoeff()},
        {"spacingMm", {options.spacing().x(), options.spacing().y(), options.spacing().z()}},
        {"armsResting", options.armsResting},
        {"handGapMm", options.handGapMm},
        {"forearmGapMm", options.forearmGapMm},
        {"limbVesselMm", options.limbVesselMm},
        {"girdlesTouching", options.girdlesTouching},
        {"labels", labels},
        {"originRas", {o.x(), o.y(), o.z()}},
        {"numVoxels", g.numVoxels()},
        {"armsTouching", options.armsTouching},
        {"bytesWritten", written},
        {"seconds", seconds},
        {"organLabels", labelsJson(phantom.organLabels())},
        {"partLabels", labelsJson(phantom.partLabels())}};
    std::cout << doc.dump(2) << "\n";
  } else {
    std::cout << "wrote " << files.organs << "\n      " << files.parts << "\n      "
              << files.skeleton << "\n"
              << phantom.organLabels().size() << " organ labels, " << phantom.partLabels().size()
              << " body parts, " << phantom.joints().size() << " joints; "
              << humanBytes(static_cast<double>(written)) << " in " << seconds << " s\n";
  }
  return 0;
}

}  // namespace repose::cli

// A long workbench session through the Logic, without the GUI (issue 30): cycle after cycle it
// opens a scene folder as a user does (OpenScene: G shown, the rigged pose live), drags a group
// through 50 edits (each re-solving the frame and the three slice views), exports the posed frame
// to a folder, and closes the scene. Every tenth cycle it is also fed corrupt files (five volumes
// the readers refuse and a scene folder with a truncated mesh), which must fail with one line.
//
// Resident memory is sampled after every cycle, with glibc's free lists returned to the system
// first (malloc_trim), so that a sample counts what the process holds, not what the allocator
// keeps for reuse. The program runs itself with one malloc arena (glibc.malloc.arena_max=1):
// with an arena per thread, what malloc_trim could not return from the worker threads' arenas
// swung resident memory by megabytes from cycle to cycle, several times the heap in use, which
// would drown a growth of 1 KB a cycle; a leak holds memory in any arena. The slope of a
// least-squares line through the samples after warm-up is the growth per cycle; the program exits 1
// when it is above --max-slope-kb. It prints JSON.
//
//   ReposeLogicSoak [--cycles 500] [--warmup 100] [--edits 50] [--voxel-mm 8] [--pixels 128]
//                   [--max-slope-kb 1] [--work DIR] [--series FILE]
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkSlicerReposeLogic.h"

#include <repose/io/AtomicOutput.h>
#include <repose/io/VolumeIO.h>
#include <repose/phantom/Phantom.h>

#include <nlohmann/json.hpp>

#include <vtkImageData.h>
#include <vtkNew.h>

#include <malloc.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& what) {
  std::cerr << "ReposeLogicSoak: " << what << "\n";
  std::exit(2);
}

// Resident memory in KiB from /proc/self/status, after returning free heap pages to the system:
// the whole set (VmRSS), and its anonymous part (RssAnon: heap, stacks) and file-backed part
// (RssFile: libraries' pages, which the kernel may drop and fault back in).
struct Resident {
  double total = 0, anon = 0, file = 0;
};
Resident resident() {
  malloc_trim(0);
  std::ifstream status("/proc/self/status");
  Resident r;
  for (std::string key; status >> key;) {
    double kb = 0;
    if (key == "VmRSS:" && status >> kb) r.total = kb;
    if (key == "RssAnon:" && status >> kb) r.anon = kb;
    if (key == "RssFile:" && status >> kb) r.file = kb;
  }
  return r;
}

// Bytes the heap has handed out and not taken back (mallinfo2: small blocks and mmapped ones).
double heapKb() {
  const struct mallinfo2 m = mallinfo2();
  return double(m.uordblks + m.hblkhd) / 1024.0;
}

// The least-squares slope of y over its index.
double slope(const std::vector<double>& y) {
  const double n = double(y.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double x = double(i);
    sx += x, sy += y[i], sxx += x * x, sxy += x * y[i];
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// The corrupt inputs of every tenth cycle: volumes the readers refuse, and a scene folder whose
// transfer mesh was cut short.
struct CorruptInputs {
  std::vector<std::string> volumes;
  std::string scene;
};

CorruptInputs makeCorruptInputs(const fs::path& work, const fs::path& G, const fs::path& scene) {
  const fs::path bad = work / "corrupt";
  fs::create_directories(bad);
  CorruptInputs c;
  auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(bad / name, std::ios::binary) << bytes;
    c.volumes.push_back((bad / name).string());
  };
  std::ifstream in(G, std::ios::binary);
  const std::string g((std::istreambuf_iterator<char>(in)), {});
  write("truncated.nii.gz", g.substr(0, g.size() / 2));
  const std::string head =
      "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 8 8 8\n"
      "space directions: (1,0,0) (0,1,0) (0,0,1)\nendian: little\n";
  write("corrupt_gzip.nrrd", head + "encoding: gzip\n\n" + g.substr(g.size() / 3, 4096));
  write("kinds_first.nrrd", "NRRD0004\nkinds: domain domain domain\ndimension: 3\n");
  write("segment.seg.nrrd", head + "encoding: raw\nSegment0_ID:=a\n\n" + std::string(100, 'x'));
  write("garbage.nii", std::string(400, '\x7f'));
  const fs::path broken = bad / "scene";
  fs::remove_all(broken);
  fs::copy(scene, broken, fs::copy_options::recursive);
  for (const auto& entry : fs::directory_iterator(broken))
    if (entry.path().extension() == ".vtu") fs::resize_file(entry.path(), 300);
  c.scene = broken.string();
  return c;
}

}  // namespace

// Runs this program again with one malloc arena, unless it already has it.
void execWithOneArena(char** argv) {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const std::string current = tunables ? tunables : "";
  if (current.find("glibc.malloc.arena_max=1") != std::string::npos) return;
  const std::string value =
      (current.empty() ? "" : current + ":") + std::string("glibc.malloc.arena_max=1");
  ::setenv("GLIBC_TUNABLES", value.c_str(), 1);
  ::execv("/proc/self/exe", argv);
  fail(std::string("cannot run itself again with one malloc arena: ") + std::strerror(errno));
}

int main(int argc, char** argv) {
  execWithOneArena(argv);
  int cycles = 500, warmup = 100, edits = 50, pixels = 128;
  double voxelMm = 8, maxSlopeKb = 1;
  fs::path work = fs::temp_directory_path() / ("repose-logic-soak-" + std::to_string(getpid()));
  std::string seriesFile;
  for (int i = 1; i < argc; i += 2) {
    const std::string key = argv[i];
    if (i + 1 >= argc) fail("option " + key + " needs a value");
    const std::string value = argv[i + 1];
    if (key == "--cycles")
      cycles = std::stoi(value);
    else if (key == "--warmup")
      warmup = std::stoi(value);
    else if (key == "--edits")
      edits = std::stoi(value);
    else if (key == "--voxel-mm")
      voxelMm = std::stod(value);
    else if (key == "--pixels")
      pixels = std::stoi(value);
    else if (key == "--max-slope-kb")
      maxSlopeKb = std::stod(value);
    else if (key == "--work")
      work = value;
    else if (key == "--series")
      seriesFile = value;
    else
      fail("unknown option " + key);
  }
  if (cycles - warmup < 10) fail("--cycles must exceed --warmup by at least 10");
  const auto start = std::chrono::steady_clock::now();

  // The scene: the phantom's G and S, rigged for the elbow pose, saved as the workbench saves.
  fs::create_directories(work);
  const fs::path sceneDir = work / "scene", out = work / "export";
  {
    repose::PhantomOptions po;
    po.voxelMm = voxelMm;
    const repose::Phantom phantom(po);
    const auto [organs, parts] = phantom.makeVolumes();
    repose::writeVolume(organs, (work / "G.nii.gz").string());
    repose::writeVolume(parts, (work / "S.nii.gz").string());
    repose::writeTextFileAtomically((work / "skeleton.json").string(), phantom.skeletonJson());
    vtkNew<vtkSlicerReposeLogic> rigging;
    auto* seg =
        rigging->AddSegmentation((work / "G.nii.gz").string(), (work / "S.nii.gz").string());
    auto* pose =
        rigging->AddPose(std::string(REPOSE_SOURCE_DIR) + "/bench/poses/elbow90.pose.json");
    if (!seg || !pose) fail(rigging->GetLastErrorMessage());
    if (!rigging->GetJobs()->StartBuildRig(seg, pose) ||
        rigging->GetJobs()->WaitForJob() != vtkSlicerReposeJobsLogic::JobSucceeded)
      fail("rig: " + rigging->GetLastErrorMessage());
    if (!rigging->SaveScene(sceneDir.string())) fail(rigging->GetLastErrorMessage());
  }
  const CorruptInputs corrupt = makeCorruptInputs(work, work / "G.nii.gz", sceneDir);

  // One Logic for the whole session, as the workbench keeps one.
  vtkNew<vtkSlicerReposeLogic> logic;
  vtkNew<vtkMRMLReposeParametersNode> parameters;
  logic->SetParameterNode(parameters);
  std::vector<double> rss, anon, file, heap;
  int refused = 0;
  for (int cycle = 0; cycle < cycles; ++cycle) {
    if (!logic->OpenScene(sceneDir.string())) fail("open: " + logic->GetLastErrorMessage());
    if (logic->GetJobs()->WaitForJob() != vtkSlicerReposeJobsLogic::JobSucceeded)
      fail("live pose: " + logic->GetLastErrorMessage());
    vtkMRMLReposePoseNode* pose = logic->GetLive()->GetLivePose();
    if (!pose) fail("the opened scene's pose did not go live");
    const std::string group = parameters->GetActiveGroup();
    const auto rest = logic->GetPoseEdits()->GetPoseGroupTransform(pose, group);
    if (!rest) fail("no movable group " + group);
    const std::array<double, 6> box = logic->GetLive()->GetLiveBounds();
    logic->GetPoseEdits()->BeginPoseInteraction();
    for (int e = 0; e < edits; ++e) {
      const double angle = rest->angleDeg + 30.0 * double(e + 1) / double(edits);
      if (!logic->GetPoseEdits()->SetPoseGroupTransform(pose, group, rest->axis, angle, rest->pivot,
                                                        rest->translation))
        fail("edit: " + logic->GetLastErrorMessage());
      for (int o = 0; o < 3; ++o) {
        const int axis = o == 0 ? 2 : o == 1 ? 1 : 0;
        if (!logic->GetLive()->ComputeLiveSlice(o, (box[2 * axis] + box[2 * axis + 1]) / 2, pixels))
          fail("slice: " + logic->GetLastErrorMessage());
      }
    }
    logic->GetPoseEdits()->EndPoseInteraction();
    if (!logic->GetJobs()->StartApplyPose(pose, out.string()) ||
        logic->GetJobs()->WaitForJob() != vtkSlicerReposeJobsLogic::JobSucceeded)
      fail("export: " + logic->GetLastErrorMessage());
    if (!fs::exists(out / "posed_G.nii.gz")) fail("the export wrote no posed_G.nii.gz");
    // Close: the live pose stopped, the volume cleared, the scene replaced by an empty one.
    logic->GetLive()->StopLivePose();
    logic->ClearVolume();
    logic->SetScene(vtkNew<vtkMRMLReposeScene>());
    // Every tenth cycle (from the first, so warm-up has seen every reader's error path): each
    // corrupt volume, then the corrupt scene.
    if (cycle % 10 == 0) {
      for (const std::string& bad : corrupt.volumes) {
        if (logic->LoadVolume(bad)) fail(bad + " was read");
        if (logic->GetLastErrorMessage().find('\n') != std::string::npos)
          fail("not one line: " + logic->GetLastErrorMessage());
        ++refused;
      }
      if (logic->OpenScene(corrupt.scene)) fail(corrupt.scene + " was opened");
      ++refused;
      logic->ClearVolume();
      logic->SetScene(vtkNew<vtkMRMLReposeScene>());
    }
    const Resident r = resident();
    rss.push_back(r.total);
    anon.push_back(r.anon);
    file.push_back(r.file);
    heap.push_back(heapKb());
  }

  const std::vector<double> rssAfter(rss.begin() + warmup, rss.end()),
      heapAfter(heap.begin() + warmup, heap.end());
  const double rssSlope = slope(rssAfter), heapSlope = slope(heapAfter);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json report = {
      {"cycles", cycles},
      {"warmup", warmup},
      {"edits_per_cycle", edits},
      {"voxel_mm", voxelMm},
      {"pixels", pixels},
      {"corrupt_inputs_refused", refused},
      {"seconds", seconds},
      {"rss_mb_after_warmup", rssAfter.front() / 1024},
      {"rss_mb_last", rss.back() / 1024},
      {"rss_slope_kb_per_cycle", rssSlope},
      {"rss_anon_slope_kb_per_cycle",
       slope(std::vector<double>(anon.begin() + warmup, anon.end()))},
      {"malloc_arenas", 1},
      {"heap_slope_kb_per_cycle", heapSlope},
      {"max_slope_kb_per_cycle", maxSlopeKb},
      {"flat", rssSlope < maxSlopeKb},
  };
  std::cout << report.dump(2) << "\n";
  if (!seriesFile.empty()) {
    std::ofstream series(seriesFile);
    series << "cycle,rss_kb,rss_anon_kb,rss_file_kb,heap_kb\n";
    for (std::size_t i = 0; i < rss.size(); ++i)
      series << i << "," << rss[i] << "," << anon[i] << "," << file[i] << "," << heap[i] << "\n";
  }
  fs::remove_all(work);
  return rssSlope < maxSlopeKb ? 0 : 1;
}

// `repose sweep --subjects LIST --poses LIST --out DIR [--resume]`: every subject in every pose,
// one job per (subject, pose, frame), in one process or spread over MPI ranks (mpirun -np N
// repose sweep ...). Each job writes exactly what `repose pose --scene` writes for it, in
// DIR/<subject>/<pose>[/<frame>]. Three phases, each handing out its items one at a time:
//   1. plan: per (subject, pose), the frames and the scene key of the rig it needs;
//   2. scenes: each distinct rig of a subject built once, by one rank, into DIR/<subject>/scenes;
//   3. jobs: every frame, posed from its scene's rig.
// A failed job is recorded with its one-line error and the others go on; rank 0 writes
// DIR/sweep.json, sweep.csv and sweep.svg.
#include "ArgParser.h"
#include "Commands.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "SweepComm.h"

#include "repose/io/VolumeIO.h"
#include "repose/pose/Pose.h"
#include "repose/pose/PoseFrame.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseRun.h"
#include "repose/pose/SceneFolder.h"
#include "repose/pose/Sweep.h"
#include "repose/rig/Rig.h"
#include "repose/util/Error.h"
#include "repose/util/Memory.h"
#include "repose/util/Parallel.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

namespace repose::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Settings {
  std::string outDir, format;
  double budget = 0;
  int threads = 0;
  bool resume = false, quiet = false;
};

// What phase 1 learns of one (subject, pose).
struct TaskPlan {
  std::vector<std::string> frames;  // frame names; one frame: the pose's name
  std::string key;                  // the rig's scene key ("" when every frame is complete)
  std::string error;                // the pose cannot be done at all
};

// One rank's working set: the subject it holds in memory, the job and rig of the (subject, pose)
// it last worked on. Consecutive items of a phase are mostly the same subject (the lists are
// subject-major), so a rank rarely reads a subject twice.
class Worker {
 public:
  Worker(const std::vector<SweepSubject>& subjects, const std::vector<SweepPose>& poses,
         const Settings& settings)
      : subjects_(subjects), poses_(poses), settings_(settings) {}

  // The pose job of task t (subject t / P, pose t % P), with G and S read.
  const PoseJob& job(std::int64_t task) {
    if (jobTask_ == task && job_) return *job_;
    const SweepSubject& s = subjects_[std::size_t(task / std::int64_t(poses_.size()))];
    rig_.reset();
    job_.reset();
    jobTask_ = -1;
    if (subjectIndex_ != task / std::int64_t(poses_.size())) {
      organs_.reset(), parts_.reset();
      subjectIndex_ = -1;
      // What the reader decides about G (a DICOM SEG's grid...) is said once and kept in the
      // reports of all its jobs, as `repose pose` keeps it.
      organsNotes_.clear();
      ReadOptions organsRead = readOptionsWithin(settings_.budget, false);
      organsRead.note = [this, say = organsRead.note](const std::string& n) {
        organsNotes_.push_back(n);
        if (say) say(n);
      };
      organs_ = readVolume(s.organs, organsRead);
      parts_ = readVolume(s.parts, readOptionsWithin(settings_.budget, false));
      nameBodyPartsByRigConvention(*parts_, s.parts);
      requirePoseableLabels(*organs_, s.organs);
      requirePoseableLabels(*parts_, s.parts);
      subjectIndex_ = task / std::int64_t(poses_.size());
    }
    PoseJobRequest request;
    request.organsName = s.organs;
    request.partsPath = s.parts;
    request.skeleton = skeletonFor(s.parts, "");
    request.settings.threads = settings_.threads;
    request.organsNotes = organsNotes_;
    job_.emplace(readPoseFile(pose(task).path), *organs_, *parts_, std::move(request));
    jobTask_ = task;
    return *job_;
  }

  // The rig of task t: from its scene (reused), else built here (when its scene failed).
  const PoseRig& rig(std::int64_t task, bool& reused) {
    const PoseJob& j = job(task);
    if (!rig_) {
      SceneRigRun run;
      run.folder = sceneFolder(task);
      run.saveBuilt = false;  // phase 2 saved it, or could not
      run.threads = settings_.threads;
      SceneRig r = rigForScene(j, run);
      rigReused_ = r.reused;
      rig_ = std::move(r.rig);
    }
    reused = rigReused_;
    return *rig_;
  }

  const SweepSubject& subject(std::int64_t task) const {
    return subjects_[std::size_t(task / std::int64_t(poses_.size()))];
  }
  const SweepPose& pose(std::int64_t task) const {
    return poses_[std::size_t(task % std::int64_t(poses_.size()))];
  }
  std::string sceneFolder(std::int64_t task) {
    return sweepSceneFolder(settings_.outDir, subject(task), job(task).sceneKey());
  }
  const Volume& organs() const { return *organs_; }
  const Volume& parts() const { return *parts_; }

 private:
  const std::vector<SweepSubject>& subjects_;
  const std::vector<SweepPose>& poses_;
  const Settings& settings_;
  std::int64_t subjectIndex_ = -1, jobTask_ = -1;
  std::vector<std::string> organsNotes_;  // what G's reader said (ReadOptions::note)
  std::optional<Volume> organs_, parts_;
  std::optional<PoseJob> job_;
  std::unique_ptr<PoseRig> rig_;
  bool rigReused_ = false;
};

std::string oneLine(const std::exception& e) {
  std::string s = e.what();
  for (char& c : s)
    if (c == '\n') c = ' ';
  return s;
}

// Phase 1: each task's frames and scene key, known to every rank afterwards.
std::vector<TaskPlan> planTasks(SweepComm& comm, Worker& worker, std::int64_t tasks,
                                const Settings& settings) {
  json mine = json::object();
  comm.beginPhase(tasks);
  for (std::int64_t t; (t = comm.next()) >= 0;) {
    json plan = {{"frames", json::array()}, {"key", ""}};
    try {
      const Pose pose = readPoseFile(worker.pose(t).path);
      std::vector<std::string> frames;
      for (const PoseKeyframe& k : pose.keyframes) frames.push_back(k.name);
      if (frames.empty()) frames.push_back(pose.name);
      plan["frames"] = frames;
      bool complete = settings.resume;
      for (const std::string& f : frames)
        complete = complete &&
                   sweepJobComplete(sweepJobFolder(settings.outDir, worker.subject(t),
                                                   worker.pose(t), f, frames.size() == 1),
                                    worker.subject(t).organs,
                                    labelMapFilesFor(settings.format, worker.subject(t).organs));
      if (!complete) plan["key"] = worker.job(t).sceneKey();
    } catch (const std::exception& e) {
      plan["error"] = oneLine(e);
    }
    mine[std::to_string(t)] = plan;
  }
  comm.endPhase();
  std::vector<TaskPlan> plans(static_cast<std::size_t>(tasks));
  for (const std::string& text : comm.allGather(mine.dump())) {
    const json rankPlans = json::parse(text);  // kept: items() refers into it
    for (const auto& [t, plan] : rankPlans.items()) {
      TaskPlan& p = plans[std::stoul(t)];
      p.frames = plan["frames"].get<std::vector<std::string>>();
      p.key = plan["key"];
      if (plan.contains("error")) p.error = plan["error"];
    }
  }
  return plans;
}

// Phase 2: each distinct rig built once into its scene folder (unless it is there already).
// Returns the errors of the scenes that could not be built, by scene folder, on every rank.
std::map<std::string, std::string> buildScenes(SweepComm& comm, Worker& worker,
                                               const std::vector<TaskPlan>& plans,
                                               const Settings& settings) {
  std::vector<std::int64_t> firstTask;  // one task per distinct scene folder
  std::map<std::string, bool> seen;
  for (std::size_t t = 0; t < plans.size(); ++t) {
    if (plans[t].key.empty()) continue;
    const std::string folder =
        sweepSceneFolder(settings.outDir, worker.subject(std::int64_t(t)), plans[t].key);
    if (!seen.emplace(folder, true).second) continue;
    firstTask.push_back(std::int64_t(t));
  }
  json failed = json::object();
  comm.beginPhase(std::int64_t(firstTask.size()));
  for (std::int64_t i; (i = comm.next()) >= 0;) {
    const std::int64_t t = firstTask[std::size_t(i)];
    const std::string folder = sweepSceneFolder(settings.outDir, worker.subject(t), plans[t].key);
    try {
      if (readSceneRig(folder, plans[t].key)) continue;  // a scene of an earlier run
      const auto start = Clock::now();
      SceneRigRun run;
      run.folder = folder;
      run.inputs = {worker.subject(t).organs, worker.subject(t).parts, ""};
      run.threads = settings.threads;
      fs::create_directories(fs::path(folder).parent_path());
      rigForScene(worker.job(t), run);
      if (!settings.quiet)
        std::cout << "rank " << comm.rank() << ": built the rig of " << worker.subject(t).name
                  << " for " << worker.pose(t).name << " in " << int(secondsSince(start))
                  << " s -> " << folder << std::endl;
    } catch (const std::exception& e) {
      failed[folder] = "building its rig: " + oneLine(e);
    }
  }
  comm.endPhase();
  std::map<std::string, std::string> out;
  for (const std::string& text : comm.allGather(failed.dump())) {
    const json rankErrors = json::parse(text);  // kept: items() refers into it
    for (const auto& [folder, error] : rankErrors.items()) out[folder] = error;
  }
  return out;
}

// Phase 3, one job: pose frame f of task t and write it.
void runJob(Worker& worker, std::int64_t t, std::size_t f, const TaskPlan& plan,
            const Settings& settings, SweepRecord& record) {
  bool reused = false;
  const PoseRig& rig = worker.rig(t, reused);
  const PoseJob& job = worker.job(t);
  if (rig.frameCount() != plan.frames.size())
    throw Error(worker.pose(t).path + ": changed during the sweep");
  // The frame step is Core's (pose/PoseRun.h), with the memory rule every front end has.
  FrameRun run;
  run.labelMapFiles = labelMapFilesFor(settings.format, worker.subject(t).organs);
  run.memoryBudget = settings.budget;
  run.budgetWhat = record.folder;
  run.budgetHint = "--memory";
  run.outOfCore = true;  // a frame beyond the budget is made slab by slab into its folder
  run.sceneReused = reused;
  if (run.labelMapFiles == LabelMapFiles::DicomSeg)
    run.write.sourceDicom = dicomSourceOf(worker.subject(t).organs);
  const fs::path scene = fs::absolute(worker.sceneFolder(t));
  run.write.sceneInputLabels = fs::absolute(worker.subject(t).organs).string();
  run.write.sceneCage = (scene / "cage.vtk").string();
  run.write.sceneTransferMesh = (scene / "tm.vtu").string();
  const std::string dir = (fs::path(settings.outDir) / record.folder).string();
  fs::create_directories(fs::path(dir).parent_path());
  run.folder = dir;
  runPoseFrame(job, rig, f, worker.organs(), worker.parts(), run);
  readSweepFigures(record, (fs::path(dir) / "report.json").string());
}

}  // namespace

int runSweep(const Args& args) {
  ArgParser p("sweep",
              "Every subject in every pose: one job per (subject, pose, frame), each writing\n"
              "what `repose pose --scene` writes, in DIR/<subject>/<pose>[/<frame>]; then\n"
              "DIR/sweep.json, sweep.csv and sweep.svg. Run it under mpirun -np N to spread the\n"
              "jobs over N ranks (docs/PERFORMANCE.md); without MPI it runs them in turn.\n"
              "Exit status 3 when some jobs failed (each recorded with its error), 4 when every\n"
              "job was written but some missed their quality targets (report.json's \"targets\"),\n"
              "1 when the sweep itself could not run.");
  p.option("subjects", "LIST",
           "a file of subject folders, one per line: each with S.nii.gz, skeleton.json and "
           "tissues.csv as `repose rig --out` (or `repose phantom --out`) writes them, and G "
           "(G.nii.gz in the folder, else the input rig.json names)")
      .option("poses", "LIST", "a file of pose files (*.pose.json), one per line")
      .option("out", "DIR", "output folder (created if missing; its parent must exist)")
      .option("output-format", "FORMAT",
              "the posed label maps: nii.gz, seg.nrrd, both, dcmseg or auto", "auto")
      .option("threads", "N", "worker threads per rank (0: all cores / ranks on this machine)", "0")
      .flag("resume", "skip jobs whose outputs are complete (checked against their report.json)")
      .flag("json", "print sweep.json on stdout (rank 0)");
  declareMemoryOption(p, "a job that would need more fails (and the sweep goes on)");
  if (!p.parse(args)) return 0;
  for (const char* required : {"subjects", "poses", "out"})
    if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
  const std::string format = p.get("output-format");
  if (format != "auto" && format != "nii.gz" && format != "seg.nrrd" && format != "both" &&
      format != "dcmseg")
    throw UsageError{"--output-format must be auto, nii.gz, seg.nrrd, both or dcmseg"};

  const std::unique_ptr<SweepComm> comm = makeSweepComm();
  const auto start = Clock::now();
  Settings settings;
  settings.outDir = fs::absolute(p.get("out")).lexically_normal().string();
  settings.format = format;
  settings.budget = parseMemoryBudget(p.get("memory"));
  settings.resume = p.has("resume");
  settings.quiet = p.has("json");
  settings.threads = static_cast<int>(p.getInt("threads"));
  if (settings.threads == 0 && comm->size() > 1)  // ranks on one machine share its cores
    settings.threads = std::max(1, resolveThreads(0) / comm->size());
  // Every rank reads the lists (the same files, so the same answer and the same error).
  const std::vector<SweepSubject> subjects = readSweepSubjects(p.get("subjects"));
  const std::vector<SweepPose> poses = readSweepPoses(p.get("poses"));
  if (!fs::exists(fs::path(settings.outDir).parent_path()))
    throw Error(p.get("out") + ": its parent folder does not exist");
  if (comm->rank() == 0) fs::create_directories(settings.outDir);
  comm->any(false);  // the folder exists for every rank from here

  Worker worker(subjects, poses, settings);
  const std::int64_t tasks = std::int64_t(subjects.size() * poses.size());
  const std::vector<TaskPlan> plans = planTasks(*comm, worker, tasks, settings);
  const std::map<std::string, std::string> sceneErrors =
      buildScenes(*comm, worker, plans, settings);

  // The jobs, in subject-major order; a task that failed in planning is one job, failed.
  struct JobRef {
    std::int64_t task;
    std::size_t frame;  // kNoFrame: the task failed in planning
  };
  constexpr std::size_t kNoFrame = std::size_t(-1);
  std::vector<JobRef> jobs;
  for (std::int64_t t = 0; t < tasks; ++t) {
    if (!plans[std::size_t(t)].error.empty()) jobs.push_back({t, kNoFrame});
    for (std::size_t f = 0; f < plans[std::size_t(t)].frames.size(); ++f) jobs.push_back({t, f});
  }
  json mine = json::array();
  comm->beginPhase(std::int64_t(jobs.size()));
  for (std::int64_t j; (j = comm->next()) >= 0;) {
    const JobRef& ref = jobs[std::size_t(j)];
    const TaskPlan& plan = plans[std::size_t(ref.task)];
    SweepRecord r;
    r.job = j;
    r.rank = comm->rank();
    r.subject = worker.subject(ref.task).name, r.pose = worker.pose(ref.task).name;
    if (ref.frame == kNoFrame) {
      r.status = "failed", r.error = plan.error;
      r.folder = (fs::path(r.subject) / r.pose).string();
      if (!settings.quiet)
        std::cout << "rank " << r.rank << ": " << r.folder << " failed: " << r.error << std::endl;
      mine.push_back(json::parse(sweepRecordToJson(r)));
      continue;
    }
    r.frame = plan.frames[ref.frame];
    const std::string dir = sweepJobFolder(settings.outDir, worker.subject(ref.task),
                                           worker.pose(ref.task), r.frame, plan.frames.size() == 1);
    r.folder = fs::relative(dir, settings.outDir).string();
    const auto jobStart = Clock::now();
    try {
      if (settings.resume &&
          sweepJobComplete(dir, worker.subject(ref.task).organs,
                           labelMapFilesFor(settings.format, worker.subject(ref.task).organs))) {
        r.status = "skipped";
        readSweepFigures(r, (fs::path(dir) / "report.json").string());
      } else {
        if (!plan.key.empty()) {
          const auto e = sceneErrors.find(
              sweepSceneFolder(settings.outDir, worker.subject(ref.task), plan.key));
          if (e != sceneErrors.end()) throw Error(e->second);
        }
        runJob(worker, ref.task, ref.frame, plan, settings, r);
        r.status = "done";
      }
    } catch (const Cancelled&) {
      throw;
    } catch (const std::exception& e) {
      r.status = "failed";
      r.error = oneLine(e);
    }
    r.seconds = secondsSince(jobStart);
    if (!settings.quiet)
      std::cout << "rank " << r.rank << ": " << r.folder << " " << r.status
                << (r.status == "failed" ? ": " + r.error : "") << " (" << int(r.seconds) << " s)"
                << std::endl;
    mine.push_back(json::parse(sweepRecordToJson(r)));
  }
  comm->endPhase();
  const std::vector<std::string> gathered = comm->allGather(mine.dump());
  if (comm->rank() != 0) return 0;

  std::vector<SweepRecord> records;
  for (const std::string& text : gathered)
    for (const json& r : json::parse(text)) records.push_back(sweepRecordFromJson(r.dump()));
  SweepSummary summary;
  summary.ranks = comm->size();
  summary.mpi = comm->mpi();
  summary.seconds = secondsSince(start);
  const std::string summaryJson = writeSweepSummary(settings.outDir, records, summary);
  std::size_t failed = 0, missed = 0;
  for (const SweepRecord& r : records) {
    failed += r.status == "failed";
    missed += r.status != "failed" && r.targetsMet && !*r.targetsMet;
  }
  if (settings.quiet) {
    std::cout << summaryJson;
  } else {
    std::cout << records.size() << " jobs on " << comm->size() << " rank(s) in "
              << int(summary.seconds) << " s, " << failed << " failed, " << missed
              << " written but missed their targets -> " << settings.outDir
              << "/sweep.json, sweep.csv, sweep.svg" << std::endl;
  }
  return failed > 0 ? 3 : missed > 0 ? kExitTargetsMissed : 0;
}

}  // namespace repose::cli

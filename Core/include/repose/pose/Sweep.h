// Posture sweeps (`repose sweep`): many subjects, each rigged as `repose rig` or `repose phantom`
// leave them, posed by many pose files, one job per (subject, pose, frame). What the sweep's
// ranks must agree on lives here, independent of how the jobs are spread (one process or MPI
// ranks): the lists, where each job writes, when a job's outputs are complete, which scene
// folder holds a rig, and the summary rank 0 writes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace repose {

enum class LabelMapFiles;  // repose/pose/PoseFrame.h

struct SweepSubject {
  std::string name;    // the folder's name: DIR/<name>/ holds its outputs
  std::string folder;  // absolute
  std::string organs;  // G: G.nii.gz (or .nii, .nrrd, .seg.nrrd) in the folder, else rig.json's
                       // "input" when that file exists
  std::string parts;   // S.nii.gz in the folder (skeleton.json and tissues.csv are found beside)
};

struct SweepPose {
  std::string name;  // the file's name without .pose.json (or .json)
  std::string path;  // absolute
};

// A list file: one path per line (relative paths from the list's folder); blank lines and lines
// starting with # are skipped. Throws repose::Error "<list>:<line>: <problem>" for a missing
// folder or file, a subject folder without S.nii.gz or G, or two entries of the same name.
std::vector<SweepSubject> readSweepSubjects(const std::string& listPath);
std::vector<SweepPose> readSweepPoses(const std::string& listPath);

// Where a job writes: DIR/<subject>/<pose> for a one-frame pose, else DIR/<subject>/<pose>/<frame>
// (what `repose pose --out DIR/<subject>/<pose>` writes).
std::string sweepJobFolder(const std::string& outDir, const SweepSubject& subject,
                           const SweepPose& pose, const std::string& frameName, bool oneFrame);

// A job's outputs are complete when its report.json reads, names this G as its input, lists the
// label-map files of `files` among its outputs (a job written in another format, say NIfTI
// before a resume asking for DICOM SEG, is done again), and every file of its "outputs" is there
// and not empty (the frame's files are moved in with the report last, so a report only sits
// beside the files it names).
bool sweepJobComplete(const std::string& jobFolder, const std::string& organsPath,
                      LabelMapFiles files);

// The scene folder of a subject's rig: DIR/<subject>/scenes/<16 hex digits of the key's hash>
// (a subject's poses that cut or refine differently need different rigs).
std::string sweepSceneFolder(const std::string& outDir, const SweepSubject& subject,
                             const std::string& sceneKey);

// One job's line in the summary.
struct SweepRecord {
  std::int64_t job = 0;              // its place in the sweep's order (subject, pose, frame)
  std::string subject, pose, frame;  // frame "" when the pose failed before its frames were known
  std::string status;                // "done", "skipped" (complete, --resume) or "failed"
  std::string error;                 // the one-line error of a failed job
  std::string folder;                // relative to DIR
  int rank = 0;
  double seconds = 0;
  std::optional<double> bodyVolumeChangePercent, worstLabelChangePercent, bonesMinDice;
  std::optional<bool> targetsMet;
};
std::string sweepRecordToJson(const SweepRecord& record);
SweepRecord sweepRecordFromJson(const std::string& json);
// The figures of a job's report.json (done or skipped jobs).
void readSweepFigures(SweepRecord& record, const std::string& reportPath);

struct SweepSummary {
  int ranks = 1;
  double seconds = 0;
  bool mpi = false;
};
// DIR/sweep.json (every record and the totals), DIR/sweep.csv (one row per job) and
// DIR/sweep.svg (body volume and worst label change per job, grouped by subject), each written
// atomically. Returns sweep.json's text.
std::string writeSweepSummary(const std::string& outDir, std::vector<SweepRecord> records,
                              const SweepSummary& summary);

}  // namespace repose

// vtkSlicerReposeJob: one long step of the Logic on a worker thread. The work gets a ProgressFn
// (fraction, stage; it returns false once Cancel was asked, and Core then throws Cancelled) and
// returns a commit step; the commit runs on the caller's thread in Wait/Poll, and only if the work
// finished, so a cancelled or failed job changes nothing the caller owns.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <repose/util/Progress.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposeJob {
 public:
  enum Status { Idle, Running, Succeeded, Cancelled, Failed };
  using Commit = std::function<void()>;
  using Work = std::function<Commit(const repose::ProgressFn& progress)>;

  vtkSlicerReposeJob() = default;
  ~vtkSlicerReposeJob();  // cancels and joins a running job; its commit is dropped
  vtkSlicerReposeJob(const vtkSlicerReposeJob&) = delete;
  vtkSlicerReposeJob& operator=(const vtkSlicerReposeJob&) = delete;

  // False (and nothing started) when a job is running or has not been waited for.
  bool Start(const std::string& name, Work work);
  bool IsRunning() const { return this->Thread.joinable(); }
  double GetProgress() const { return this->Fraction.load(); }
  std::string GetStage() const;
  void Cancel() { this->CancelRequested = true; }
  // Joins the worker, commits on success; the job's final status (Idle if none was started).
  Status Wait();
  // Commits and returns the final status if the worker is done, else Running.
  Status Poll();
  Status GetLastStatus() const { return this->LastStatus; }
  const std::string& GetLastError() const { return this->LastError; }

 private:
  Status Finish();
  std::thread Thread;
  std::atomic<bool> Done{false}, CancelRequested{false};
  std::atomic<double> Fraction{0};
  mutable std::mutex StageMutex;
  std::string Name, Stage;
  Commit PendingCommit;
  Status Outcome = Idle, LastStatus = Idle;
  std::string Error, LastError;
};

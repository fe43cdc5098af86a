#include "vtkSlicerReposeJob.h"

#include <repose/util/Error.h>

#include <new>

vtkSlicerReposeJob::~vtkSlicerReposeJob() {
  if (this->Thread.joinable()) {
    this->Cancel();
    this->Thread.join();
  }
}

bool vtkSlicerReposeJob::Start(const std::string& name, Work work) {
  if (this->Thread.joinable()) return false;
  this->Name = name;
  this->Stage = name;
  this->Done = false;
  this->CancelRequested = false;
  this->Fraction = 0;
  this->PendingCommit = nullptr;
  this->Outcome = Running;
  this->Error.clear();
  this->Thread = std::thread([this, work = std::move(work)] {
    const repose::ProgressFn progress = [this](double fraction, const std::string& stage) {
      this->Fraction = fraction;
      {
        std::lock_guard<std::mutex> lock(this->StageMutex);
        this->Stage = stage;
      }
      return !this->CancelRequested.load();
    };
    try {
      Commit commit = work(progress);
      if (this->CancelRequested) {
        this->Outcome = Cancelled;
      } else {
        this->PendingCommit = std::move(commit);
        this->Outcome = Succeeded;
      }
    } catch (const repose::Cancelled&) {
      this->Outcome = Cancelled;
    } catch (const std::bad_alloc&) {
      this->Error = this->Name + ": not enough memory";
      this->Outcome = Failed;
    } catch (const std::exception& e) {
      this->Error = e.what();
      this->Outcome = Failed;
    }
    this->Done = true;
  });
  return true;
}

std::string vtkSlicerReposeJob::GetStage() const {
  std::lock_guard<std::mutex> lock(this->StageMutex);
  return this->Stage;
}

vtkSlicerReposeJob::Status vtkSlicerReposeJob::Finish() {
  this->Thread.join();
  Status status = this->Outcome;
  if (status == Succeeded && this->PendingCommit) {
    try {
      this->PendingCommit();
    } catch (const std::exception& e) {
      this->Error = e.what();
      status = Failed;
    }
  }
  this->PendingCommit = nullptr;
  this->LastStatus = status;
  this->LastError = this->Error;
  if (status == Succeeded) this->Fraction = 1;
  return status;
}

vtkSlicerReposeJob::Status vtkSlicerReposeJob::Wait() {
  if (!this->Thread.joinable()) return Idle;
  return this->Finish();
}

vtkSlicerReposeJob::Status vtkSlicerReposeJob::Poll() {
  if (!this->Thread.joinable()) return Idle;
  if (!this->Done) return Running;
  return this->Finish();
}

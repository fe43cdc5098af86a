#include "vtkSlicerReposePoseHistory.h"

bool vtkSlicerReposePoseHistory::Record(const std::string& nodeID, const std::string& before,
                                        const std::string& after) {
  if (after == before) return false;
  if (this->Interacting && this->InteractionRecorded && !this->UndoSteps.empty() &&
      this->UndoSteps.back().nodeID == nodeID)
    this->UndoSteps.back().after = after;  // the same drag: one step
  else
    this->UndoSteps.push_back({nodeID, before, after});
  this->InteractionRecorded = this->Interacting;
  this->RedoSteps.clear();
  return true;
}

void vtkSlicerReposePoseHistory::BeginInteraction() {
  this->Interacting = true;
  this->InteractionRecorded = false;
}

void vtkSlicerReposePoseHistory::EndInteraction() {
  this->Interacting = false;
  this->InteractionRecorded = false;
}

std::optional<vtkSlicerReposePoseHistory::Step> vtkSlicerReposePoseHistory::Undo() {
  if (this->UndoSteps.empty()) return std::nullopt;
  Step step = this->UndoSteps.back();
  this->UndoSteps.pop_back();
  this->RedoSteps.push_back(step);
  return step;
}

std::optional<vtkSlicerReposePoseHistory::Step> vtkSlicerReposePoseHistory::Redo() {
  if (this->RedoSteps.empty()) return std::nullopt;
  Step step = this->RedoSteps.back();
  this->RedoSteps.pop_back();
  this->UndoSteps.push_back(step);
  return step;
}

void vtkSlicerReposePoseHistory::Clear() {
  this->UndoSteps.clear();
  this->RedoSteps.clear();
  this->Interacting = this->InteractionRecorded = false;
}

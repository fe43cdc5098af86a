// vtkSlicerReposePoseHistory: the undo history of pose edits, a collaborator the Logic owns. Each
// step is one pose node's text before and after; the edits of a drag (between BeginInteraction
// and EndInteraction) on one node are one step, however many there are. It knows no nodes: the
// Logic applies the texts it returns to the node with the step's ID.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <optional>
#include <string>
#include <vector>

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposePoseHistory {
 public:
  struct Step {
    std::string nodeID, before, after;
  };
  // Records node `nodeID` going from `before` to `after` (nothing when they are equal) and
  // forgets what could be redone. False when nothing changed.
  bool Record(const std::string& nodeID, const std::string& before, const std::string& after);
  void BeginInteraction();
  void EndInteraction();
  bool IsInteracting() const { return this->Interacting; }
  // The step to undo (its `before` is to be applied), moved to the redo side; none when empty.
  std::optional<Step> Undo();
  // The step to redo (its `after` is to be applied), moved back; none when empty.
  std::optional<Step> Redo();
  bool CanUndo() const { return !this->UndoSteps.empty(); }
  bool CanRedo() const { return !this->RedoSteps.empty(); }
  void Clear();

 private:
  std::vector<Step> UndoSteps, RedoSteps;
  bool Interacting = false, InteractionRecorded = false;
};

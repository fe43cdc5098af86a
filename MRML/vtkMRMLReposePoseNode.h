// vtkMRMLReposePoseNode: a pose — handle groups with their transforms, keyframes, separations —
// held parsed (repose::Pose, as Slicer's nodes hold their data objects, not their files' text),
// and the keyframe shown. The pose is an immutable snapshot the node shares: an edit sets a new
// one, undo puts an old one back (no copy, nothing to parse), and pose-file text is made only
// where it is written (a saved scene) or read (a file opened). The header names no Core type
// beyond a declaration, so the widgets, which include it, reach no Core header through it.
#pragma once

#include "vtkMRMLReposeNode.h"

#include <memory>

namespace repose {
struct Pose;
}

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposePoseNode : public vtkMRMLReposeNode {
 public:
  static vtkMRMLReposePoseNode* New();
  vtkTypeMacro(vtkMRMLReposePoseNode, vtkMRMLReposeNode);
  const char* GetNodeClassName() const override { return "vtkMRMLReposePoseNode"; }

  // The pose (null before one is set). Setting another snapshot fires ModifiedEvent.
  std::shared_ptr<const repose::Pose> GetPose() const { return this->Pose; }
  void SetPose(std::shared_ptr<const repose::Pose> pose);
  // The pose as a pose file's text (docs/POSES.md), written now: "" without a pose.
  std::string GetPoseJSON() const;
  // Parses pose-file text (named after the node) into the node's pose. False, with the
  // parser's one line in `error`, and the node unchanged, for text that is not a pose.
  bool SetPoseJSON(const std::string& text, std::string* error = nullptr);
  const std::string& GetFileName() const { return this->FileName; }
  void SetFileName(const std::string& name) { this->SetField(this->FileName, name); }
  int GetCurrentFrame() const { return this->CurrentFrame; }  // keyframe index, 0 without
  void SetCurrentFrame(int frame) { this->SetField(this->CurrentFrame, frame < 0 ? 0 : frame); }

 protected:
  vtkMRMLReposePoseNode() = default;
  void WriteFields(nlohmann::ordered_json& json) const override;
  bool ReadFields(const nlohmann::json& json, bool apply, std::string& error) override;
  void CopyContent(vtkMRMLReposeNode* other) override;

 private:
  std::shared_ptr<const repose::Pose> Pose;
  std::string FileName;
  int CurrentFrame = 0;
};

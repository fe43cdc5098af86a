// vtkMRMLReposePoseNode: a pose — handle groups with their transforms, keyframes, separations —
// held as the text of a pose file (docs/POSES.md), which the Logic parses and edits, and the
// keyframe shown. MRML knows no pose semantics; keeping the document whole makes undo a swap of
// two strings and saving a plain write.
#pragma once

#include "vtkMRMLReposeNode.h"

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposePoseNode : public vtkMRMLReposeNode {
 public:
  static vtkMRMLReposePoseNode* New();
  vtkTypeMacro(vtkMRMLReposePoseNode, vtkMRMLReposeNode);
  const char* GetNodeClassName() const override { return "vtkMRMLReposePoseNode"; }

  const std::string& GetPoseJSON() const { return this->PoseJSON; }
  void SetPoseJSON(const std::string& text) { this->SetField(this->PoseJSON, text); }
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
  std::string PoseJSON, FileName;
  int CurrentFrame = 0;
};

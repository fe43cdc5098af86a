#include "vtkMRMLReposePoseNode.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkMRMLReposePoseNode);

// The pose text is the node's bulk data (its file); the JSON carries where it is and the frame.
void vtkMRMLReposePoseNode::WriteFields(nlohmann::ordered_json& json) const {
  json["FileName"] = this->FileName;
  json["CurrentFrame"] = this->CurrentFrame;
}

bool vtkMRMLReposePoseNode::ReadFields(const nlohmann::json& json, bool apply, std::string& error) {
  if (!apply)
    return CheckString(json, "FileName", error) && CheckInteger(json, "CurrentFrame", error);
  if (json.contains("FileName")) this->SetFileName(json["FileName"]);
  if (json.contains("CurrentFrame")) this->SetCurrentFrame(json["CurrentFrame"]);
  return true;
}

void vtkMRMLReposePoseNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposePoseNode*>(other);
  this->SetFileName(o->FileName);
  this->SetCurrentFrame(o->CurrentFrame);
  this->SetPoseJSON(o->PoseJSON);
}

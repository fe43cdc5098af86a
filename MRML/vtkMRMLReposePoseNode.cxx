#include "vtkMRMLReposePoseNode.h"

#include <vtkObjectFactory.h>
#include "repose/schema/SceneSchema.h"

namespace sc = repose::scene_schema;

vtkStandardNewMacro(vtkMRMLReposePoseNode);

// The pose text is the node's bulk data (its file); the JSON carries where it is and the frame.
void vtkMRMLReposePoseNode::WriteFields(nlohmann::ordered_json& json) const {
  json[sc::pose::kFile] = this->FileName;
  json[sc::pose::kCurrentFrame] = this->CurrentFrame;
}

bool vtkMRMLReposePoseNode::ReadFields(const nlohmann::json& json, bool apply, std::string& error) {
  if (!apply)
    return CheckString(json, sc::pose::kFile, error) &&
           CheckInteger(json, sc::pose::kCurrentFrame, error);
  if (json.contains(sc::pose::kFile)) this->SetFileName(json[sc::pose::kFile]);
  if (json.contains(sc::pose::kCurrentFrame)) this->SetCurrentFrame(json[sc::pose::kCurrentFrame]);
  return true;
}

void vtkMRMLReposePoseNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposePoseNode*>(other);
  this->SetFileName(o->FileName);
  this->SetCurrentFrame(o->CurrentFrame);
  this->SetPoseJSON(o->PoseJSON);
}

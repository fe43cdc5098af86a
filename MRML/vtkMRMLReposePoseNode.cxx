#include "vtkMRMLReposePoseNode.h"

#include <vtkObjectFactory.h>
#include "repose/pose/Pose.h"
#include "repose/schema/SceneSchema.h"

#include <exception>

namespace sc = repose::scene_schema;

vtkStandardNewMacro(vtkMRMLReposePoseNode);

void vtkMRMLReposePoseNode::SetPose(std::shared_ptr<const repose::Pose> pose) {
  if (pose == this->Pose) return;
  this->Pose = std::move(pose);
  this->Modified();
}

std::string vtkMRMLReposePoseNode::GetPoseJSON() const {
  return this->Pose ? repose::poseToJson(*this->Pose) : std::string();
}

bool vtkMRMLReposePoseNode::SetPoseJSON(const std::string& text, std::string* error) {
  try {
    this->SetPose(std::make_shared<const repose::Pose>(repose::parsePose(text, this->GetName())));
    return true;
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return false;
  }
}

// The pose is the node's bulk data (its file); the JSON carries where it is and the frame.
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
  this->SetPose(o->Pose);  // a snapshot: shared, never changed in place
}

#include "vtkMRMLReposeSegmentationNode.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkMRMLReposeSegmentationNode);

namespace {
// A deep copy (nodes never share voxels), or null.
vtkSmartPointer<vtkImageData> copyOf(vtkImageData* image) {
  if (!image) return nullptr;
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->DeepCopy(image);
  return copy;
}
const char* const kFileFields[] = {"LabelMapFileName", "BodyPartMapFileName", "ImageFileName",
                                   "SkeletonJSON"};
}  // namespace

void vtkMRMLReposeSegmentationNode::SetLabelMap(vtkImageData* image) {
  this->LabelMap = image;
  this->Modified();
}
void vtkMRMLReposeSegmentationNode::SetBodyPartMap(vtkImageData* image) {
  this->BodyPartMap = image;
  this->Modified();
}
void vtkMRMLReposeSegmentationNode::SetImage(vtkImageData* image) {
  this->Image = image;
  this->Modified();
}

void vtkMRMLReposeSegmentationNode::WriteFields(nlohmann::ordered_json& json) const {
  json["LabelMapFileName"] = this->LabelMapFileName;
  json["BodyPartMapFileName"] = this->BodyPartMapFileName;
  json["ImageFileName"] = this->ImageFileName;
  json["SkeletonJSON"] = this->SkeletonJSON;
}

bool vtkMRMLReposeSegmentationNode::ReadFields(const nlohmann::json& json, bool apply,
                                               std::string& error) {
  if (!apply) {
    for (const char* key : kFileFields)
      if (!CheckString(json, key, error)) return false;
    return true;
  }
  if (json.contains("LabelMapFileName")) this->SetLabelMapFileName(json["LabelMapFileName"]);
  if (json.contains("BodyPartMapFileName"))
    this->SetBodyPartMapFileName(json["BodyPartMapFileName"]);
  if (json.contains("ImageFileName")) this->SetImageFileName(json["ImageFileName"]);
  if (json.contains("SkeletonJSON")) this->SetSkeletonJSON(json["SkeletonJSON"]);
  return true;
}

void vtkMRMLReposeSegmentationNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposeSegmentationNode*>(other);
  this->SetLabelMapFileName(o->LabelMapFileName);
  this->SetBodyPartMapFileName(o->BodyPartMapFileName);
  this->SetImageFileName(o->ImageFileName);
  this->SetSkeletonJSON(o->SkeletonJSON);
  this->SetLabelMap(copyOf(o->LabelMap));
  this->SetBodyPartMap(copyOf(o->BodyPartMap));
  this->SetImage(copyOf(o->Image));
}

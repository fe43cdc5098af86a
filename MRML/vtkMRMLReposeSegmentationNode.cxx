#include "vtkMRMLReposeSegmentationNode.h"

#include <vtkObjectFactory.h>
#include "repose/schema/SceneSchema.h"

#include <algorithm>

namespace sc = repose::scene_schema;

vtkStandardNewMacro(vtkMRMLReposeSegmentationNode);

namespace {
// A deep copy (nodes never share voxels), or null.
vtkSmartPointer<vtkImageData> copyOf(vtkImageData* image) {
  if (!image) return nullptr;
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->DeepCopy(image);
  return copy;
}
const char* const kFileFields[] = {sc::segmentation::kLabelMapFile,
                                   sc::segmentation::kBodyPartMapFile, sc::segmentation::kImageFile,
                                   sc::segmentation::kSkeleton};
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
  json[sc::segmentation::kLabelMapFile] = this->LabelMapFileName;
  json[sc::segmentation::kBodyPartMapFile] = this->BodyPartMapFileName;
  json[sc::segmentation::kImageFile] = this->ImageFileName;
  json[sc::segmentation::kSkeleton] = this->SkeletonJSON;
  if (!this->PoseReportJSON.empty()) json[sc::segmentation::kPoseReport] = this->PoseReportJSON;
  if (!this->PoseWarnings.empty()) json[sc::segmentation::kPoseWarnings] = this->PoseWarnings;
}

bool vtkMRMLReposeSegmentationNode::ReadFields(const nlohmann::json& json, bool apply,
                                               std::string& error) {
  if (!apply) {
    for (const char* key : kFileFields)
      if (!CheckString(json, key, error)) return false;
    if (!CheckString(json, sc::segmentation::kPoseReport, error)) return false;
    if (json.contains(sc::segmentation::kPoseWarnings)) {
      const auto& w = json[sc::segmentation::kPoseWarnings];
      if (!w.is_array() || !std::all_of(w.begin(), w.end(), [](auto& x) { return x.is_string(); }))
        return error = std::string(sc::segmentation::kPoseWarnings) + ": expected an array of text",
               false;
    }
    return true;
  }
  if (json.contains(sc::segmentation::kLabelMapFile))
    this->SetLabelMapFileName(json[sc::segmentation::kLabelMapFile]);
  if (json.contains(sc::segmentation::kBodyPartMapFile))
    this->SetBodyPartMapFileName(json[sc::segmentation::kBodyPartMapFile]);
  if (json.contains(sc::segmentation::kImageFile))
    this->SetImageFileName(json[sc::segmentation::kImageFile]);
  if (json.contains(sc::segmentation::kSkeleton))
    this->SetSkeletonJSON(json[sc::segmentation::kSkeleton]);
  if (json.contains(sc::segmentation::kPoseReport))
    this->SetPoseReportJSON(json[sc::segmentation::kPoseReport]);
  if (json.contains(sc::segmentation::kPoseWarnings))
    this->SetPoseWarnings(json[sc::segmentation::kPoseWarnings].get<std::vector<std::string>>());
  return true;
}

void vtkMRMLReposeSegmentationNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposeSegmentationNode*>(other);
  this->SetLabelMapFileName(o->LabelMapFileName);
  this->SetBodyPartMapFileName(o->BodyPartMapFileName);
  this->SetImageFileName(o->ImageFileName);
  this->SetSkeletonJSON(o->SkeletonJSON);
  this->SetLabelMapReadNotes(o->LabelMapReadNotes);
  this->SetSourceStamp(o->SourceStamp);
  this->SetPoseReportJSON(o->PoseReportJSON);
  this->SetPoseWarnings(o->PoseWarnings);
  this->SetLabelMap(copyOf(o->LabelMap));
  this->SetBodyPartMap(copyOf(o->BodyPartMap));
  this->SetImage(copyOf(o->Image));
}

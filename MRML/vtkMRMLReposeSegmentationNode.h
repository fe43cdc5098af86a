// vtkMRMLReposeSegmentationNode: the input of a posing job. The organ label map G (with its label
// table in the image's field data, as the Logic's volume conversion stores it), the optional
// body-part map S that the cage and transfer mesh follow, and an optional intensity image I posed
// alongside; each a vtkImageData in RAS mm (origin, spacing, direction) and a file name for the
// scene folder. With S comes its skeleton (skeleton.json's text): the joints a pose names.
#pragma once

#include "vtkMRMLReposeNode.h"

#include <vtkImageData.h>
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposeSegmentationNode
    : public vtkMRMLReposeNode {
 public:
  static vtkMRMLReposeSegmentationNode* New();
  vtkTypeMacro(vtkMRMLReposeSegmentationNode, vtkMRMLReposeNode);
  const char* GetNodeClassName() const override { return "vtkMRMLReposeSegmentationNode"; }

  vtkImageData* GetLabelMap() const { return this->LabelMap; }
  void SetLabelMap(vtkImageData* image);
  vtkImageData* GetBodyPartMap() const { return this->BodyPartMap; }  // null: G's body mask
  void SetBodyPartMap(vtkImageData* image);
  vtkImageData* GetImage() const { return this->Image; }  // null: none
  void SetImage(vtkImageData* image);

  // File names inside the scene folder (e.g. "G.nii.gz"); empty when not saved.
  const std::string& GetLabelMapFileName() const { return this->LabelMapFileName; }
  void SetLabelMapFileName(const std::string& name) {
    this->SetField(this->LabelMapFileName, name);
  }
  const std::string& GetBodyPartMapFileName() const { return this->BodyPartMapFileName; }
  void SetBodyPartMapFileName(const std::string& name) {
    this->SetField(this->BodyPartMapFileName, name);
  }
  const std::string& GetImageFileName() const { return this->ImageFileName; }
  void SetImageFileName(const std::string& name) { this->SetField(this->ImageFileName, name); }

  // The body's skeleton as skeleton.json text (`repose rig`, `repose phantom`); empty: none.
  const std::string& GetSkeletonJSON() const { return this->SkeletonJSON; }
  void SetSkeletonJSON(const std::string& text) { this->SetField(this->SkeletonJSON, text); }

  // What G's reader said about the file it read (a DICOM SEG placed on its own grid, a FRACTIONAL
  // SEG thresholded: repose::ReadOptions::note), kept for the export's report ("input_notes",
  // as `repose pose` keeps them). Not written to the scene: a saved scene holds G as NIfTI, on
  // the grid the reader chose, and a scene opened has the notes of reading its own file.
  const std::vector<std::string>& GetLabelMapReadNotes() const { return this->LabelMapReadNotes; }
  void SetLabelMapReadNotes(const std::vector<std::string>& notes) {
    this->SetField(this->LabelMapReadNotes, notes);
  }

  // Which files this node's images were read from, as they were then (the Logic's FilesStamp of
  // G, S and the image): the panel builds the rig on this node again while its paths still
  // stamp the same, instead of reading them anew. Not written to the scene: an opened scene's
  // node is stamped with its own files.
  const std::string& GetSourceStamp() const { return this->SourceStamp; }
  void SetSourceStamp(const std::string& stamp) { this->SetField(this->SourceStamp, stamp); }

  // A posed segmentation (an export of a pose): the report.json its job wrote and the job's
  // warnings (separations not made, a tissue table that does not fit). Empty for an input.
  // Saved with the scene, so the panel shows the export's quality again when it is reopened.
  const std::string& GetPoseReportJSON() const { return this->PoseReportJSON; }
  void SetPoseReportJSON(const std::string& text) { this->SetField(this->PoseReportJSON, text); }
  const std::vector<std::string>& GetPoseWarnings() const { return this->PoseWarnings; }
  void SetPoseWarnings(const std::vector<std::string>& warnings) {
    this->SetField(this->PoseWarnings, warnings);
  }

 protected:
  vtkMRMLReposeSegmentationNode() = default;
  void WriteFields(nlohmann::ordered_json& json) const override;
  bool ReadFields(const nlohmann::json& json, bool apply, std::string& error) override;
  void CopyContent(vtkMRMLReposeNode* other) override;

 private:
  vtkSmartPointer<vtkImageData> LabelMap, BodyPartMap, Image;
  std::string LabelMapFileName, BodyPartMapFileName, ImageFileName, SkeletonJSON, SourceStamp;
  std::string PoseReportJSON;
  std::vector<std::string> PoseWarnings;
  std::vector<std::string> LabelMapReadNotes;
};

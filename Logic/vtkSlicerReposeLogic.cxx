// vtkSlicerReposeLogic: loading the input volume named by the parameter node, and describing it.
#include "vtkSlicerReposeLogic.h"

#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposeVolumeConversion.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkSlicerReposeJob.h"
#include "vtkSlicerReposeLogicContext.h"
#include "vtkSlicerReposeLogicRead.h"

#include <repose/io/VolumeIO.h>
#include <repose/util/Error.h>
#include <repose/volume/LabelStatistics.h>

#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>

#include <algorithm>
#include <iomanip>
#include <new>
#include <sstream>

vtkStandardNewMacro(vtkSlicerReposeLogic);

vtkSlicerReposeLogic::vtkSlicerReposeLogic()
    : Context(std::make_shared<vtkSlicerReposeLogicContext>()),
      Jobs(vtkSmartPointer<vtkSlicerReposeJobsLogic>::New()),
      Live(vtkSmartPointer<vtkSlicerReposeLiveLogic>::New()),
      PoseEdits(vtkSmartPointer<vtkSlicerReposePoseEditLogic>::New()) {
  this->Context->Live = this->Live;
  this->Jobs->SetContext(this->Context);
  this->Live->SetContext(this->Context);
  this->PoseEdits->SetContext(this->Context);
  // A part's news is the module's: the panel and the views observe this logic only.
  for (vtkObject* part : {static_cast<vtkObject*>(this->Jobs), static_cast<vtkObject*>(this->Live),
                          static_cast<vtkObject*>(this->PoseEdits)})
    part->AddObserver(vtkCommand::ModifiedEvent, this, &vtkSlicerReposeLogic::Modified);
  this->SetParameterNode(nullptr);  // a node of its own
}

vtkSlicerReposeLogic::~vtkSlicerReposeLogic() {
  if (this->Context->ParameterNode)
    this->Context->ParameterNode->RemoveObserver(this->ParameterNodeObserverTag);
  // A running job is cancelled and its commit dropped before the rest goes.
  this->Context->Job.reset();
  for (vtkObject* part : {static_cast<vtkObject*>(this->Jobs), static_cast<vtkObject*>(this->Live),
                          static_cast<vtkObject*>(this->PoseEdits)})
    part->RemoveObservers(vtkCommand::ModifiedEvent);
  this->Live->ReleaseLivePose();
  this->Context->Live = nullptr;
}

vtkMRMLReposeParametersNode* vtkSlicerReposeLogic::GetParameterNode() const {
  return this->Context->ParameterNode;
}

const std::string& vtkSlicerReposeLogic::GetLastErrorMessage() const {
  return this->Context->LastErrorMessage;
}

void vtkSlicerReposeLogic::SetParameterNode(vtkMRMLReposeParametersNode* node) {
  vtkSmartPointer<vtkMRMLReposeParametersNode>& current = this->Context->ParameterNode;
  if (node && node == current) return;
  if (current) current->RemoveObserver(this->ParameterNodeObserverTag);
  current = node ? vtkSmartPointer<vtkMRMLReposeParametersNode>(node)
                 : vtkSmartPointer<vtkMRMLReposeParametersNode>::New();
  this->ParameterNodeObserverTag = current->AddObserver(
      vtkCommand::ModifiedEvent, this, &vtkSlicerReposeLogic::OnParameterNodeModified);
  this->OnParameterNodeModified();  // bring the volume in line with the new node
  this->Modified();
}

void vtkSlicerReposeLogic::OnParameterNodeModified() {
  const std::string& path = this->Context->ParameterNode->GetInputSegmentationPath();
  if (path == this->VolumePath) return;
  if (path.empty())
    this->ClearVolume();
  else
    this->LoadVolume(path);
}

namespace {
// Error texts from the OS or libraries may span lines; an info box and a log want one.
std::string oneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}
}  // namespace

bool vtkSlicerReposeLogic::LoadVolume(const std::string& path) {
  return this->ShowVolume(path, nullptr);
}

void vtkSlicerReposeLogic::ResetVolume() {
  this->VolumeImageData = nullptr;
  this->VolumeIJKToRASMatrix = nullptr;
  this->VolumeLookupTable = nullptr;
  this->VolumeLabelNames.clear();
  this->VolumeLabelNote.clear();
  this->VolumeReadNotes.clear();
  this->VolumeStamp.clear();
  this->VolumeLabelsPresent = -1;
  this->VolumePath.clear();
}

bool vtkSlicerReposeLogic::ShowVolume(const std::string& path, vtkImageData* held) {
  this->ResetVolume();
  this->VolumePath = path;  // before the node is told, so its Modified does not reload
  std::string& message = this->Context->LastErrorMessage;
  message.clear();
  const std::string tissues = this->Context->TissueTablePath();
  try {
    if (path.empty()) throw repose::Error("no input file given");
    std::vector<std::string> readNotes;
    // Before reading: a file changed during the read does not match it afterwards.
    const std::string stamp =
        held ? std::string() : vtkSlicerReposeLogicRead::FilesStamp({path, tissues});
    repose::Volume volume = held ? vtkSlicerReposeVolumeConversion::FromImageData(held)
                                 : vtkSlicerReposeLogicRead::ReadVolume(path, &readNotes);
    for (const repose::Label& l : volume.labels().labels())
      this->VolumeLabelNames.push_back({l.layer, l.value, l.name});
    // Counted once: naming the labels, telling their convention and the lookup table's values
    // present all read these counts (each had made its own pass over the whole map).
    const std::vector<repose::LabelCount> counts =
        volume.isLabelMap() ? repose::countLabels(volume) : std::vector<repose::LabelCount>();
    // The display's names and colours of labels the file left without (the file's names above).
    this->VolumeLabelNote = vtkSlicerReposeLogicRead::NameLabels(volume, tissues, path, &counts);
    this->VolumeReadNotes = readNotes;  // a SEG's grid, a fractional SEG thresholded
    this->VolumeImageData = held ? vtkSmartPointer<vtkImageData>(held)
                                 : vtkSlicerReposeVolumeConversion::ToImageData(volume);
    this->VolumeIJKToRASMatrix =
        vtkSlicerReposeVolumeConversion::ToMatrix(volume.geometry().ijkToRas);
    std::vector<int> present;  // layer 0's values, coloured even when the table lacks them
    if (volume.isLabelMap()) {
      this->VolumeLabelsPresent = static_cast<int>(counts.size());
      for (const repose::LabelCount& c : counts)
        if (c.layer == 0) present.push_back(c.value);
    }
    this->VolumeLookupTable =
        vtkSlicerReposeVolumeConversion::ToLookupTable(volume.labels(), 0, present);
    if (volume.isLabelMap()) this->VolumeStamp = stamp;
  } catch (const repose::Error& e) {
    message = oneLine(e.what());
  } catch (const std::bad_alloc&) {
    message = path + ": not enough memory to load the volume";
  } catch (const std::exception& e) {
    message = oneLine(path + ": " + e.what());
  }
  if (!message.empty()) this->VolumeImageData = nullptr, this->VolumeStamp.clear();
  this->Context->ParameterNode->SetInputSegmentationPath(path);
  this->Modified();
  return message.empty();
}

void vtkSlicerReposeLogic::ClearVolume() {
  this->ResetVolume();
  this->Context->LastErrorMessage.clear();
  this->Modified();
}

vtkSmartPointer<vtkLookupTable> vtkSlicerReposeLogic::GetLabelLookupTable(vtkImageData* labelMap) {
  if (!labelMap) return nullptr;
  const repose::Volume volume = vtkSlicerReposeVolumeConversion::FromImageData(labelMap);
  std::vector<int> present;
  for (const repose::LabelCount& c : repose::countLabels(volume))
    if (c.layer == 0) present.push_back(c.value);
  return vtkSlicerReposeVolumeConversion::ToLookupTable(volume.labels(), 0, present);
}

std::string vtkSlicerReposeLogic::GetVolumeSummary() const {
  if (!this->VolumeImageData) return {};
  const repose::VolumeGeometry geometry =
      vtkSlicerReposeVolumeConversion::GetGeometry(this->VolumeImageData);
  vtkDataArray* scalars = this->VolumeImageData->GetPointData()->GetScalars();
  const repose::ScalarType type =
      vtkSlicerReposeVolumeConversion::FromVTKScalarType(scalars->GetDataType());
  const Eigen::Vector3d spacing = geometry.spacing();
  std::ostringstream out;
  out << "Dimensions: " << geometry.dims[0] << " x " << geometry.dims[1] << " x "
      << geometry.dims[2] << "\n";
  out << "Spacing: " << std::setprecision(6) << spacing[0] << " x " << spacing[1] << " x "
      << spacing[2] << " mm\n";
  out << "Orientation: " << geometry.axisCodes() << "\n";
  out << "Scalar type: " << repose::scalarTypeName(type) << "\n";
  out << "Layers: " << scalars->GetNumberOfComponents() << "\n";
  if (this->VolumeLabelsPresent < 0)
    out << "Labels: none (not a label map)";
  else
    out << "Labels: " << this->VolumeLabelsPresent << " present, " << this->VolumeLabelNames.size()
        << " named";
  if (!this->VolumeLabelNote.empty()) {
    // The note without its leading "<path>: " (the box names the file already).
    const std::size_t colon = this->VolumeLabelNote.find(": ", this->VolumePath.size());
    out << "\nNames: "
        << (colon == std::string::npos ? this->VolumeLabelNote
                                       : this->VolumeLabelNote.substr(colon + 2));
  }
  for (const std::string& note : this->VolumeReadNotes) {  // the same, for what the reader said
    const bool named = note.rfind(this->VolumePath + ": ", 0) == 0;
    out << "\nNote: " << (named ? note.substr(this->VolumePath.size() + 2) : note);
  }
  return out.str();
}

void vtkSlicerReposeLogic::PrintSelf(ostream& os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ParameterNode: " << this->Context->ParameterNode.GetPointer() << "\n";
  os << indent << "VolumePath: " << this->VolumePath << "\n";
  os << indent << "VolumeImageData: " << this->VolumeImageData.GetPointer() << "\n";
  os << indent << "LastErrorMessage: " << this->Context->LastErrorMessage << "\n";
}

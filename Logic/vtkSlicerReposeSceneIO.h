// vtkSlicerReposeSceneIO: the Logic's scene folders on disk, a collaborator of the Logic (which
// guards the calls and owns the scene they fill). Save writes every node's data file (G, S and
// image as .nii.gz, cage .vtk, transfer mesh .vtu with its Green coordinates, poses .pose.json)
// atomically, then scene.mrml for 3D Slicer and scene.json last, naming the files relative to the
// folder. Load reads scene.json and every file it names into a new scene, or throws
// repose::Error with one line naming the file; nothing is half loaded. scene.json also keeps the
// module's parameter node (its JSON, under "parameters"), so a scene reopens with the panel as
// it was saved.
#pragma once

#include <vtkSmartPointer.h>

#include <string>

class vtkMRMLReposeScene;

namespace vtkSlicerReposeSceneIO {
// `parameters`: the parameter node's JSON object ("" for none).
void Save(vtkMRMLReposeScene* scene, const std::string& folder, const std::string& parameters);
struct Loaded {
  vtkSmartPointer<vtkMRMLReposeScene> scene;
  std::string parameters;  // the saved parameter node's JSON object, "" when none was saved
};
Loaded Load(const std::string& folder);
}  // namespace vtkSlicerReposeSceneIO

// vtkSlicerReposeSceneIO: the Logic's scene folders on disk, a collaborator of the Logic (which
// guards the calls and owns the scene they fill). Save writes every node's data file (G, S and
// image as .nii.gz, cage .vtk, transfer mesh .vtu with its Green coordinates, poses .pose.json)
// atomically, then scene.mrml for 3D Slicer and scene.json last, naming the files relative to the
// folder. Load reads scene.json and every file it names into a new scene, or throws
// repose::Error with one line naming the file; nothing is half loaded.
#pragma once

#include <vtkSmartPointer.h>

#include <string>

class vtkMRMLReposeScene;

namespace vtkSlicerReposeSceneIO {
void Save(vtkMRMLReposeScene* scene, const std::string& folder);
vtkSmartPointer<vtkMRMLReposeScene> Load(const std::string& folder);
}  // namespace vtkSlicerReposeSceneIO

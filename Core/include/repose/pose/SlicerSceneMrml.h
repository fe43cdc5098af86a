// A 3D Slicer scene (scene.mrml) beside a posed frame: the input label map, the posed one, the
// displacement field as a grid transform, and the rig's cage and transfer mesh as models, each a
// node with the storage node Slicer reads its file with, so File > Add Data of one file opens the
// whole result (Libs/MRML/Core/vtkMRMLScene.cxx writes and reads this XML).
#pragma once

#include <string>

namespace repose {

// The files a scene names, written relative to the scene's folder as Slicer writes them (it
// resolves a relative fileName against the folder holding the .mrml).
struct SlicerSceneFiles {
  std::string inputLabels;   // G: a .seg.nrrd opens as a segmentation, else as a label map volume
  std::string posedLabels;   // posed_G.nii.gz or posed_G.seg.nrrd
  std::string colorTable;    // a .ctbl for the label map volumes ("" : Slicer's generic colours)
  std::string transform;     // transform.nrrd (a displacement field, resampling)
  std::string cage;          // cage.vtk (SPACE=RAS)
  std::string transferMesh;  // tm.vtu (SPACE=RAS)
};

// The scene's XML text, for a scene file in `sceneFolder`. Empty entries are left out.
std::string formatSlicerScene(const SlicerSceneFiles& files, const std::string& sceneFolder);

}  // namespace repose

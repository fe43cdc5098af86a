// Core <-> VTK conversion of volumes: repose::Volume to vtkImageData (RAS mm geometry in
// origin/spacing/direction, layers as components, label table as field data) and back, losslessly.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <repose/volume/Volume.h>

#include <vtkSmartPointer.h>

class vtkImageData;
class vtkLookupTable;
class vtkMatrix4x4;

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposeVolumeConversion {
 public:
  // Field-data array names that carry what vtkImageData has no slot for.
  static constexpr const char* LabelValueArrayName = "ReposeLabelValue";
  static constexpr const char* LabelLayerArrayName = "ReposeLabelLayer";
  static constexpr const char* LabelNameArrayName = "ReposeLabelName";
  static constexpr const char* LabelColorArrayName = "ReposeLabelColor";
  static constexpr const char* LabelIDArrayName = "ReposeLabelID";
  static constexpr const char* LabelTagsArrayName = "ReposeLabelTags";
  // 1 where the colour was made up (Label::colorGenerated); optional on reading.
  static constexpr const char* LabelColorGeneratedArrayName = "ReposeLabelColorGenerated";
  static constexpr const char* LabelMapFlagArrayName = "ReposeIsLabelMap";

  // A copy of the voxels: layer l of the volume becomes component l of the point scalars.
  // Throws repose::Error if a dimension does not fit VTK's int extents.
  static vtkSmartPointer<vtkImageData> ToImageData(const repose::Volume& volume);
  // The inverse. A non-zero extent start is folded into the origin. Throws repose::Error for
  // scalar types Repose does not keep (e.g. double) or an image without point scalars.
  static repose::Volume FromImageData(vtkImageData* image);

  // Geometry alone (no voxel copy): origin, spacing and direction of `image` in RAS mm.
  static void SetGeometry(vtkImageData* image, const repose::VolumeGeometry& geometry);
  static repose::VolumeGeometry GetGeometry(vtkImageData* image);
  static vtkSmartPointer<vtkMatrix4x4> ToMatrix(const Eigen::Matrix4d& m);

  // Label table alone: stored in / read from the image's field data (empty if absent).
  static void SetLabelTable(vtkImageData* image, const repose::LabelTable& labels);
  static repose::LabelTable GetLabelTable(vtkImageData* image);
  // An indexed lookup table for display: one annotated colour per label of `layer`, and for each
  // value of `present` the table does not name its own distinct colour
  // (repose::LabelTable::defaultColor) and its number as the name, so a label map read with no
  // colour table (or an incomplete one) does not draw every label in the lookup's one "unknown"
  // colour.
  static vtkSmartPointer<vtkLookupTable> ToLookupTable(const repose::LabelTable& labels,
                                                       int layer = 0,
                                                       const std::vector<int>& present = {});

  // VTK_UNSIGNED_CHAR, VTK_UNSIGNED_SHORT, VTK_SHORT, VTK_INT, VTK_FLOAT.
  static int ToVTKScalarType(repose::ScalarType type);
  // Throws repose::Error naming the VTK type when Repose has no equivalent.
  static repose::ScalarType FromVTKScalarType(int vtkType);
};

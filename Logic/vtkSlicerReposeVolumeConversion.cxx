// Core <-> VTK volume conversion. Voxels are copied (Core owns its buffer); layers are planar in
// Core and interleaved as components in VTK, so multi-layer copies transpose.
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/util/Error.h>

#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkLookupTable.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkPointData.h>
#include <vtkStringArray.h>
#include <vtkVariant.h>

#include <climits>
#include <cstring>

using repose::ScalarType;

int vtkSlicerReposeVolumeConversion::ToVTKScalarType(ScalarType type) {
  switch (type) {
    case ScalarType::UInt8:
      return VTK_UNSIGNED_CHAR;
    case ScalarType::UInt16:
      return VTK_UNSIGNED_SHORT;
    case ScalarType::Int16:
      return VTK_SHORT;
    case ScalarType::Int32:
      return VTK_INT;
    case ScalarType::Float32:
      break;
  }
  return VTK_FLOAT;
}

ScalarType vtkSlicerReposeVolumeConversion::FromVTKScalarType(int vtkType) {
  switch (vtkType) {
    case VTK_UNSIGNED_CHAR:
      return ScalarType::UInt8;
    case VTK_UNSIGNED_SHORT:
      return ScalarType::UInt16;
    case VTK_SHORT:
      return ScalarType::Int16;
    case VTK_INT:
      return ScalarType::Int32;
    case VTK_FLOAT:
      return ScalarType::Float32;
    default:
      break;
  }
  throw repose::Error(std::string("VTK scalar type ") + vtkImageScalarTypeNameMacro(vtkType) +
                      " is not one Repose keeps (uint8, uint16, int16, int32, float32)");
}

vtkSmartPointer<vtkMatrix4x4> vtkSlicerReposeVolumeConversion::ToMatrix(const Eigen::Matrix4d& m) {
  auto matrix = vtkSmartPointer<vtkMatrix4x4>::New();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) matrix->SetElement(r, c, m(r, c));
  return matrix;
}

void vtkSlicerReposeVolumeConversion::SetGeometry(vtkImageData* image,
                                                  const repose::VolumeGeometry& geometry) {
  for (auto d : geometry.dims)
    if (d <= 0 || d > INT_MAX)
      throw repose::Error("dimension " + std::to_string(d) + " does not fit a VTK image extent");
  image->SetExtent(0, static_cast<int>(geometry.dims[0] - 1), 0,
                   static_cast<int>(geometry.dims[1] - 1), 0,
                   static_cast<int>(geometry.dims[2] - 1));
  const Eigen::Vector3d spacing = geometry.spacing(), origin = geometry.origin();
  // The direction keeps the linear part divided by the spacing, so VTK's index-to-physical
  // matrix (direction * diag(spacing)) is the IJK->RAS matrix, shear included.
  const Eigen::Matrix3d direction = geometry.directions();
  image->SetSpacing(spacing.data());
  image->SetOrigin(origin.data());
  double d[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) d[3 * r + c] = direction(r, c);
  image->SetDirectionMatrix(d);
}

repose::VolumeGeometry vtkSlicerReposeVolumeConversion::GetGeometry(vtkImageData* image) {
  int extent[6];
  image->GetExtent(extent);
  const double* spacing = image->GetSpacing();
  const double* origin = image->GetOrigin();
  vtkMatrix3x3* direction = image->GetDirectionMatrix();
  repose::VolumeGeometry geometry;
  Eigen::Matrix3d linear;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) linear(r, c) = direction->GetElement(r, c) * spacing[c];
  const Eigen::Vector3d start(extent[0], extent[2], extent[4]);
  geometry.ijkToRas.setIdentity();
  geometry.ijkToRas.block<3, 3>(0, 0) = linear;
  geometry.ijkToRas.block<3, 1>(0, 3) =
      Eigen::Vector3d(origin[0], origin[1], origin[2]) + linear * start;
  for (int a = 0; a < 3; ++a) geometry.dims[a] = extent[2 * a + 1] - extent[2 * a] + 1;
  return geometry;
}

void vtkSlicerReposeVolumeConversion::SetLabelTable(vtkImageData* image,
                                                    const repose::LabelTable& labels) {
  auto values = vtkSmartPointer<vtkIntArray>::New();
  auto layers = vtkSmartPointer<vtkIntArray>::New();
  auto colors = vtkSmartPointer<vtkDoubleArray>::New();
  auto names = vtkSmartPointer<vtkStringArray>::New();
  auto ids = vtkSmartPointer<vtkStringArray>::New();
  auto tags = vtkSmartPointer<vtkStringArray>::New();
  auto generated = vtkSmartPointer<vtkIntArray>::New();
  generated->SetName(LabelColorGeneratedArrayName);
  values->SetName(LabelValueArrayName);
  layers->SetName(LabelLayerArrayName);
  colors->SetName(LabelColorArrayName);
  colors->SetNumberOfComponents(3);
  names->SetName(LabelNameArrayName);
  ids->SetName(LabelIDArrayName);
  tags->SetName(LabelTagsArrayName);
  for (const repose::Label& label : labels.labels()) {
    values->InsertNextValue(label.value);
    layers->InsertNextValue(label.layer);
    colors->InsertNextTuple(label.color.data());
    names->InsertNextValue(label.name);
    ids->InsertNextValue(label.id);
    tags->InsertNextValue(label.tags);
    generated->InsertNextValue(label.colorGenerated ? 1 : 0);
  }
  vtkFieldData* fields = image->GetFieldData();
  vtkAbstractArray* arrays[] = {values, layers, colors, names, ids, tags, generated};
  for (vtkAbstractArray* array : arrays) fields->AddArray(array);  // replaces a same-named one
}

repose::LabelTable vtkSlicerReposeVolumeConversion::GetLabelTable(vtkImageData* image) {
  repose::LabelTable table;
  vtkFieldData* fields = image->GetFieldData();
  auto* values = vtkIntArray::SafeDownCast(fields->GetAbstractArray(LabelValueArrayName));
  auto* layers = vtkIntArray::SafeDownCast(fields->GetAbstractArray(LabelLayerArrayName));
  auto* colors = vtkDoubleArray::SafeDownCast(fields->GetAbstractArray(LabelColorArrayName));
  auto* names = vtkStringArray::SafeDownCast(fields->GetAbstractArray(LabelNameArrayName));
  auto* ids = vtkStringArray::SafeDownCast(fields->GetAbstractArray(LabelIDArrayName));
  auto* tags = vtkStringArray::SafeDownCast(fields->GetAbstractArray(LabelTagsArrayName));
  auto* generated =
      vtkIntArray::SafeDownCast(fields->GetAbstractArray(LabelColorGeneratedArrayName));
  if (!values || !layers || !colors || !names || !ids || !tags) return table;
  const vtkIdType n = values->GetNumberOfValues();
  if (layers->GetNumberOfValues() != n || colors->GetNumberOfTuples() != n ||
      names->GetNumberOfValues() != n || ids->GetNumberOfValues() != n ||
      tags->GetNumberOfValues() != n || colors->GetNumberOfComponents() != 3)
    throw repose::Error("label table arrays of the image have different lengths");
  for (vtkIdType i = 0; i < n; ++i) {
    repose::Label label;
    label.value = values->GetValue(i);
    label.layer = layers->GetValue(i);
    colors->GetTypedTuple(i, label.color.data());
    label.name = names->GetValue(i);
    label.id = ids->GetValue(i);
    label.tags = tags->GetValue(i);
    label.colorGenerated =
        generated && generated->GetNumberOfValues() == n && generated->GetValue(i) != 0;
    table.set(label);
  }
  return table;
}

vtkSmartPointer<vtkLookupTable> vtkSlicerReposeVolumeConversion::ToLookupTable(
    const repose::LabelTable& labels, int layer, const std::vector<int>& present) {
  std::vector<repose::Label> shown;
  for (const repose::Label& label : labels.labels())
    if (label.layer == layer) shown.push_back(label);
  for (const int value : present)
    if (value != 0 && !labels.find(value, layer)) {
      repose::Label l;
      l.value = value;
      l.layer = layer;
      l.name = std::to_string(value);
      l.color = repose::LabelTable::defaultColor(value);
      shown.push_back(l);
    }
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  lut->IndexedLookupOn();
  lut->SetNumberOfTableValues(vtkIdType(shown.size()));
  vtkIdType index = 0;
  for (const repose::Label& label : shown) {
    lut->SetTableValue(index++, label.color[0], label.color[1], label.color[2], 1.0);
    // Annotations are matched to table values by order in indexed mode.
    lut->SetAnnotation(vtkVariant(label.value), label.name);
  }
  return lut;
}

vtkSmartPointer<vtkImageData> vtkSlicerReposeVolumeConversion::ToImageData(
    const repose::Volume& volume) {
  auto image = vtkSmartPointer<vtkImageData>::New();
  SetGeometry(image, volume.geometry());
  const int layers = volume.layers();
  const vtkIdType voxels = volume.numVoxels();
  const std::size_t size = repose::scalarSize(volume.scalarType());
  vtkSmartPointer<vtkDataArray> scalars;
  scalars.TakeReference(vtkDataArray::CreateDataArray(ToVTKScalarType(volume.scalarType())));
  scalars->SetName("ImageScalars");
  scalars->SetNumberOfComponents(layers);
  scalars->SetNumberOfTuples(voxels);
  auto* out = static_cast<char*>(scalars->GetVoidPointer(0));
  if (layers == 1) {
    std::memcpy(out, volume.layerData(0), voxels * size);
  } else {
    for (int l = 0; l < layers; ++l) {
      const auto* in = static_cast<const char*>(volume.layerData(l));
      for (vtkIdType v = 0; v < voxels; ++v)
        std::memcpy(out + (v * layers + l) * size, in + v * size, size);
    }
  }
  image->GetPointData()->SetScalars(scalars);
  auto flag = vtkSmartPointer<vtkIntArray>::New();
  flag->SetName(LabelMapFlagArrayName);
  flag->InsertNextValue(volume.isLabelMap() ? 1 : 0);
  image->GetFieldData()->AddArray(flag);
  SetLabelTable(image, volume.labels());
  return image;
}

repose::Volume vtkSlicerReposeVolumeConversion::FromImageData(vtkImageData* image) {
  if (!image) throw repose::Error("no image");
  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  if (!scalars) throw repose::Error("image has no point scalars");
  const repose::VolumeGeometry geometry = GetGeometry(image);
  const int layers = scalars->GetNumberOfComponents();
  repose::Volume volume(geometry, FromVTKScalarType(scalars->GetDataType()), layers);
  const vtkIdType voxels = volume.numVoxels();
  if (scalars->GetNumberOfTuples() != voxels)
    throw repose::Error("image scalars hold " + std::to_string(scalars->GetNumberOfTuples()) +
                        " tuples for " + std::to_string(voxels) + " voxels");
  const std::size_t size = repose::scalarSize(volume.scalarType());
  const auto* in = static_cast<const char*>(scalars->GetVoidPointer(0));
  if (layers == 1) {
    std::memcpy(volume.layerData(0), in, voxels * size);
  } else {
    for (int l = 0; l < layers; ++l) {
      auto* out = static_cast<char*>(volume.layerData(l));
      for (vtkIdType v = 0; v < voxels; ++v)
        std::memcpy(out + v * size, in + (v * layers + l) * size, size);
    }
  }
  auto* flag =
      vtkIntArray::SafeDownCast(image->GetFieldData()->GetAbstractArray(LabelMapFlagArrayName));
  volume.setLabelMap(flag && flag->GetNumberOfValues() > 0 && flag->GetValue(0) != 0);
  volume.labels() = GetLabelTable(image);
  return volume;
}

// A posed body as the voxel model of an FDTD solver: an axis-aligned RAS grid of material
// indices (at most 255 materials and the background) and, per material, the tissue's relative
// permittivity, conductivity and mass density at one frequency. The grid is the label map's own
// when its axes run along R, A and S (any order or sign: the voxels are only reordered), or a
// nearest-neighbour resampling at a given cell size, whose change per tissue is reported.
#pragma once

#include "repose/dosimetry/ColeCole.h"
#include "repose/dosimetry/LabelTissues.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace repose {

struct FdtdMaterial {
  std::string tissue;      // gabrielTissues() name; "background" for index 0
  double densityKgM3 = 0;  // 0 for the background (openEMS's SAR skips such cells)
  DielectricValues dielectric;
  std::vector<int> labels;   // the labels of G made of this material
  std::int64_t voxels = 0;   // cells of the FDTD grid
  double volumeMl = 0;       // on the FDTD grid
  double inputVolumeMl = 0;  // in G, before resampling
  double massKg() const { return densityKgM3 * volumeMl * 1e-6; }
};

struct FdtdLabelCount {
  std::int64_t inputVoxels = 0, voxels = 0;
  double inputVolumeMl = 0, volumeMl = 0;
  int material = 0;
};

struct FdtdModel {
  double frequencyHz = 0;
  std::array<std::int64_t, 3> dims{0, 0, 0};
  Eigen::Vector3d cornerMm = Eigen::Vector3d::Zero();   // RAS of the first cell's outer corner
  Eigen::Vector3d spacingMm = Eigen::Vector3d::Ones();  // along R, A, S
  std::vector<std::uint8_t> index;      // material per cell, x (R) fastest, then y (A), then z (S)
  std::vector<FdtdMaterial> materials;  // [0] is the background outside the body
  std::map<int, FdtdLabelCount> labels;
  bool resampled = false;
  std::int64_t overlapVoxels = 0;  // voxels of G where two layers (segments) overlap; last wins
  // Cell boundaries along axis a (dims[a] + 1 values, mm).
  std::vector<double> lines(int axis) const;
};

struct FdtdModelOptions {
  double frequencyHz = 900e6;
  // Cell size (mm) per axis for a resampled grid; unset keeps G's voxels (axes along RAS only).
  std::optional<Eigen::Vector3d> spacingMm;
  int threads = 0;
  ProgressFn progress;
  // Bytes the model's cells may take (one each); 0: no limit. Checked before allocating.
  double memoryBytes = 0;
};

// Throws repose::Error "<source>: ..." for a grid whose axes are oblique to RAS without a
// spacing, for more than 255 materials, or a grid beyond 8G cells or options.memoryBytes.
FdtdModel buildFdtdModel(const Volume& organs, const std::map<int, LabelTissue>& labels,
                         const FdtdModelOptions& options, const std::string& source);

// "2" or "2,2,4" (mm, > 0): the cell size per axis. Throws repose::Error naming the text.
Eigen::Vector3d parseCellSizeMm(const std::string& text);

}  // namespace repose

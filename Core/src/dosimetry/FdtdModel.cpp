#include "repose/dosimetry/FdtdModel.h"

#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <type_traits>
#include <unordered_map>

namespace repose {
namespace {

// A grid larger than this is refused: 8G cells of one byte each, beyond any whole body at 0.5 mm.
constexpr std::int64_t kMaxCells = std::int64_t(8) << 30;

// Label value -> dense slot (0 = background), by table when the values are compact.
class LabelSlots {
 public:
  explicit LabelSlots(const std::vector<int>& values) {
    if (!values.empty()) {
      min_ = values.front();
      const std::int64_t range = std::int64_t(values.back()) - min_ + 1;
      if (range <= (1 << 24)) table_.assign(std::size_t(range), 0);
    }
    for (std::size_t s = 0; s < values.size(); ++s) {
      if (!table_.empty())
        table_[std::size_t(values[s] - min_)] = int(s) + 1;
      else
        map_[values[s]] = int(s) + 1;
    }
  }
  int operator()(std::int64_t value) const {
    if (value == 0) return 0;
    if (!table_.empty()) {
      const std::int64_t k = value - min_;
      return k >= 0 && k < std::int64_t(table_.size()) ? table_[std::size_t(k)] : 0;
    }
    const auto it = map_.find(value);
    return it == map_.end() ? 0 : it->second;
  }

 private:
  std::int64_t min_ = 0;
  std::vector<int> table_;
  std::unordered_map<std::int64_t, int> map_;
};

// The label of voxel n: the last layer with a non-zero value (Slicer's export order), and
// whether two layers overlap there.
template <class T>
std::int64_t flattenedLabel(const std::vector<const T*>& layers, std::int64_t n, bool* overlap) {
  std::int64_t label = 0;
  int found = 0;
  for (const T* layer : layers)
    if (layer[n] != 0) label = static_cast<std::int64_t>(layer[n]), ++found;
  if (overlap) *overlap = found > 1;
  return label;
}

struct TargetGrid {
  std::array<std::int64_t, 3> dims{0, 0, 0};
  Eigen::Vector3d corner = Eigen::Vector3d::Zero(), spacing = Eigen::Vector3d::Ones();
};

TargetGrid ownGrid(const VolumeGeometry& g, const std::string& source) {
  const Eigen::Matrix3d d = g.directions();
  const Eigen::Vector3d s = g.spacing();
  const double tolerance = std::sin(kMaxAxisSkewDegrees * M_PI / 180.0);
  TargetGrid t;
  std::array<bool, 3> used{false, false, false};
  for (int a = 0; a < 3; ++a) {
    int axis = 0;
    d.col(a).cwiseAbs().maxCoeff(&axis);
    for (int b = 0; b < 3; ++b)
      if (b != axis && std::abs(d(b, a)) > tolerance)
        throw Error(source +
                    ": its voxel axes are oblique to R, A and S (an FDTD grid is not): give "
                    "--spacing-mm to resample it onto an axis-aligned grid");
    if (used[axis]) throw Error(source + ": two voxel axes point the same way");
    used[axis] = true;
    t.dims[axis] = g.dims[a];
    t.spacing[axis] = s[a];
  }
  t.corner = g.rasBounds().first;
  return t;
}

TargetGrid resampledGrid(const VolumeGeometry& g, const Eigen::Vector3d& spacing) {
  const auto [lo, hi] = g.rasBounds();
  TargetGrid t;
  t.spacing = spacing;
  for (int a = 0; a < 3; ++a) {
    const double extent = hi[a] - lo[a];
    t.dims[a] = std::max<std::int64_t>(1, std::int64_t(std::ceil(extent / spacing[a] - 1e-6)));
    t.corner[a] = lo[a] + (extent - double(t.dims[a]) * spacing[a]) / 2;  // centred on G
  }
  return t;
}

}  // namespace

std::vector<double> FdtdModel::lines(int axis) const {
  std::vector<double> out(std::size_t(dims[axis] + 1));
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = cornerMm[axis] + double(i) * spacingMm[axis];
  return out;
}

Eigen::Vector3d parseCellSizeMm(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  for (std::string f; std::getline(in, f, ',');) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(f, &used));
      if (used != f.size()) v.back() = -1;
    } catch (const std::exception&) {
      v.push_back(-1);
    }
  }
  if (v.size() == 1) v = {v[0], v[0], v[0]};
  if (v.size() != 3 || !(v[0] > 0 && v[1] > 0 && v[2] > 0) || !std::isfinite(v[0] + v[1] + v[2]))
    throw Error("cell size \"" + text + "\": expected S or SX,SY,SZ in mm, each > 0");
  return {v[0], v[1], v[2]};
}

FdtdModel buildFdtdModel(const Volume& organs, const std::map<int, LabelTissue>& labels,
                         const FdtdModelOptions& options, const std::string& source) {
  if (!organs.isLabelMap()) throw Error(source + ": not a label map (float voxels)");
  const VolumeGeometry& g = organs.geometry();
  FdtdModel model;
  model.frequencyHz = options.frequencyHz;
  model.resampled = options.spacingMm.has_value();
  const TargetGrid grid =
      model.resampled ? resampledGrid(g, *options.spacingMm) : ownGrid(g, source);
  model.dims = grid.dims;
  model.cornerMm = grid.corner;
  model.spacingMm = grid.spacing;
  const std::int64_t cells = grid.dims[0] * grid.dims[1] * grid.dims[2];
  if (cells > kMaxCells)
    throw Error(source + ": the FDTD grid would have " + std::to_string(cells) +
                " cells (more than 8G): give a larger --spacing-mm");
  if (options.memoryBytes > 0 && double(cells) > options.memoryBytes)
    throw Error(source + ": the FDTD grid of " + std::to_string(grid.dims[0]) + "x" +
                std::to_string(grid.dims[1]) + "x" + std::to_string(grid.dims[2]) +
                " cells needs " + std::to_string(std::llround(double(cells) / (1 << 20))) +
                " MiB, more than the memory budget leaves (" +
                std::to_string(std::llround(options.memoryBytes / (1 << 20))) +
                " MiB): give a larger --spacing-mm or --memory");

  // Materials: one per (tissue, density), in the order of the labels; 0 is the background.
  std::vector<int> values;
  for (const auto& [v, l] : labels) values.push_back(v);
  const LabelSlots slots(values);
  FdtdMaterial background;
  background.tissue = "background";
  background.dielectric = DielectricValues{1, 0};
  model.materials.push_back(background);
  std::vector<std::uint8_t> materialOfSlot(values.size() + 1, 0);
  for (std::size_t s = 0; s < values.size(); ++s) {
    const LabelTissue& l = labels.at(values[s]);
    const ColeColeTissue* tissue = findGabrielTissue(l.tissue);
    if (!tissue) throw Error(source + ": label " + std::to_string(values[s]) + " has no tissue");
    std::size_t m = 1;
    while (m < model.materials.size() && !(model.materials[m].tissue == tissue->name &&
                                           model.materials[m].densityKgM3 == l.densityKgM3))
      ++m;
    if (m == model.materials.size()) {
      if (m > 255)
        throw Error(source + ": more than 255 (tissue, density) materials, the most an 8-bit " +
                    "CSXCAD material index holds");
      FdtdMaterial material;
      material.tissue = tissue->name;
      material.densityKgM3 = l.densityKgM3;
      material.dielectric = dielectricAt(*tissue, options.frequencyHz);
      model.materials.push_back(material);
    }
    model.materials[m].labels.push_back(values[s]);
    materialOfSlot[s + 1] = std::uint8_t(m);
    model.labels[values[s]].material = int(m);
  }

  model.index.assign(std::size_t(cells), 0);
  const Eigen::Matrix4d rasToIjk = g.ijkToRas.inverse();
  const Eigen::Matrix3d step =
      rasToIjk.topLeftCorner<3, 3>() * grid.spacing.asDiagonal();  // ijk per cell along x, y, z
  const Eigen::Vector3d start =
      rasToIjk.topLeftCorner<3, 3>() * (grid.corner + 0.5 * grid.spacing) +
      rasToIjk.block<3, 1>(0, 3);
  const auto& in = g.dims;
  const std::size_t slotCount = values.size() + 1;
  std::vector<std::int64_t> inputCounts(slotCount, 0), outputCounts(slotCount, 0);
  std::int64_t overlaps = 0;
  std::int64_t untissued = std::numeric_limits<std::int64_t>::max();  // smallest label without one

  dispatchScalar(organs.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_floating_point_v<T>) {
      throw Error(source + ": not a label map (float voxels)");
    } else {
      std::vector<const T*> layers;
      for (int layer = 0; layer < organs.layers(); ++layer) layers.push_back(organs.data<T>(layer));
      std::mutex merge;
      // G's own counts (flattened as the cells are), for the volume change per tissue.
      parallelFor(
          in[2], options.threads,
          [&](std::int64_t k0, std::int64_t k1) {
            std::vector<std::int64_t> counts(slotCount, 0);
            std::int64_t overlap = 0, missing = std::numeric_limits<std::int64_t>::max();
            for (std::int64_t n = k0 * in[0] * in[1]; n < k1 * in[0] * in[1]; ++n) {
              bool both = false;
              ++counts[std::size_t(slots(flattenedLabel(layers, n, &both)))];
              overlap += both;
              // Every label of G, in any layer, needs its tissue: one left out would silently
              // become background.
              for (const T* layer : layers)
                if (layer[n] != 0 && slots(std::int64_t(layer[n])) == 0)
                  missing = std::min(missing, std::int64_t(layer[n]));
            }
            std::lock_guard<std::mutex> lock(merge);
            for (std::size_t s = 0; s < slotCount; ++s) inputCounts[s] += counts[s];
            overlaps += overlap;
            untissued = std::min(untissued, missing);
          },
          1);
      if (untissued != std::numeric_limits<std::int64_t>::max())
        throw Error(source + ": label " + std::to_string(untissued) + " has no tissue");
      // Each cell takes the voxel of G nearest its centre; outside G it is background.
      const std::int64_t block = std::max<std::int64_t>(1, grid.dims[2] / 50);
      for (std::int64_t z0 = 0; z0 < grid.dims[2]; z0 += block) {
        reportProgress(options.progress, double(z0) / double(grid.dims[2]), "FDTD grid");
        const std::int64_t z1 = std::min(grid.dims[2], z0 + block);
        parallelFor(
            z1 - z0, options.threads,
            [&](std::int64_t a, std::int64_t b) {
              std::vector<std::int64_t> counts(slotCount, 0);
              for (std::int64_t z = z0 + a; z < z0 + b; ++z)
                for (std::int64_t y = 0; y < grid.dims[1]; ++y) {
                  const Eigen::Vector3d row =
                      start + step.col(1) * double(y) + step.col(2) * double(z);
                  std::uint8_t* out =
                      &model.index[std::size_t((z * grid.dims[1] + y) * grid.dims[0])];
                  for (std::int64_t x = 0; x < grid.dims[0]; ++x) {
                    const Eigen::Vector3d p = row + step.col(0) * double(x);
                    const std::int64_t i = std::int64_t(std::floor(p[0] + 0.5)),
                                       j = std::int64_t(std::floor(p[1] + 0.5)),
                                       k = std::int64_t(std::floor(p[2] + 0.5));
                    int slot = 0;
                    if (i >= 0 && j >= 0 && k >= 0 && i < in[0] && j < in[1] && k < in[2])
                      slot = slots(flattenedLabel(layers, i + in[0] * (j + in[1] * k), nullptr));
                    out[x] = materialOfSlot[std::size_t(slot)];
                    ++counts[std::size_t(slot)];
                  }
                }
              std::lock_guard<std::mutex> lock(merge);
              for (std::size_t s = 0; s < slotCount; ++s) outputCounts[s] += counts[s];
            },
            1);
      }
      reportProgress(options.progress, 1.0, "FDTD grid");
    }
  });

  model.overlapVoxels = overlaps;
  const double inputMl = g.voxelVolumeMm3() * 1e-3;
  const double cellMl = grid.spacing.prod() * 1e-3;
  for (std::size_t s = 0; s < slotCount; ++s) {
    FdtdMaterial& m = model.materials[materialOfSlot[s]];
    m.voxels += outputCounts[s];
    m.volumeMl += double(outputCounts[s]) * cellMl;
    m.inputVolumeMl += double(inputCounts[s]) * inputMl;
    if (s == 0) continue;
    FdtdLabelCount& c = model.labels[values[s - 1]];
    c.inputVoxels = inputCounts[s];
    c.voxels = outputCounts[s];
    c.inputVolumeMl = double(inputCounts[s]) * inputMl;
    c.volumeMl = double(outputCounts[s]) * cellMl;
  }
  return model;
}

}  // namespace repose

// Working grid: the body mask downsampled by whole blocks ("any voxel of the block is body", so
// the cage never shrinks below the body), padded so the dilated body never touches the border.
#include "CageField.h"

#include "repose/util/Error.h"
#include "repose/volume/DistanceTransform.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace repose::cage {
namespace {

int readLabel(const Volume& v, std::int64_t index) {
  return static_cast<int>(v.valueAsDouble(index));
}

struct Masks {
  std::vector<std::uint8_t> body;
  std::vector<std::vector<std::uint8_t>> a, b;  // per separation
};

}  // namespace

double CageField::at(const Eigen::Vector3d& gridMm) const {
  const Eigen::Vector3d s = spacing();
  const auto& d = grid.dims;
  double f[3];
  std::int64_t i0[3];
  for (int c = 0; c < 3; ++c) {
    const double x = std::clamp(gridMm[c] / s[c], 0.0, double(d[c] - 1) - 1e-9);
    i0[c] = static_cast<std::int64_t>(std::floor(x));
    f[c] = x - i0[c];
  }
  auto v = [&](int di, int dj, int dk) {
    return double(value[(i0[0] + di) + d[0] * ((i0[1] + dj) + d[1] * (i0[2] + dk))]);
  };
  const double c00 = v(0, 0, 0) * (1 - f[0]) + v(1, 0, 0) * f[0];
  const double c10 = v(0, 1, 0) * (1 - f[0]) + v(1, 1, 0) * f[0];
  const double c01 = v(0, 0, 1) * (1 - f[0]) + v(1, 0, 1) * f[0];
  const double c11 = v(0, 1, 1) * (1 - f[0]) + v(1, 1, 1) * f[0];
  return (c00 * (1 - f[1]) + c10 * f[1]) * (1 - f[2]) + (c01 * (1 - f[1]) + c11 * f[1]) * f[2];
}

CageField makeCageField(const Volume& parts, const CageOptions& options, std::int64_t& bodyVoxels) {
  if (!isIntegerType(parts.scalarType()))
    throw Error("the cage needs a label map (integer voxels), not float32");
  // The distance field and the surface assume orthogonal voxel axes (the workbench and the
  // Python bindings get here without the CLI's check, which names the file).
  parts.geometry().requireOrthogonalAxes("the body-part map");
  if (options.dilateMm < 0 || !std::isfinite(options.dilateMm))
    throw Error("dilation must be >= 0 mm");
  const VolumeGeometry& in = parts.geometry();
  const Eigen::Vector3d inSpacing = in.spacing();
  const auto& dims = in.dims;

  // Which labels exist, for clear errors about the separations.
  std::set<int> present;
  bodyVoxels = 0;
  for (std::int64_t n = 0; n < parts.numVoxels(); ++n) {
    const int l = readLabel(parts, n);
    if (l != 0) ++bodyVoxels, present.insert(l);
  }
  if (bodyVoxels == 0)
    throw Error("the segmentation is empty: no voxel is non-zero, there is no body to cage");
  for (const LimbSeparation& s : options.separations)
    for (int l : {s.labelA, s.labelB})
      if (!present.count(l))
        throw Error("separation label " + std::to_string(l) +
                    " is not present in the segmentation");

  // Working voxel: a coarse cage needs no finer grid than a fraction of the dilation; finer
  // grids make the restricted Delaunay refinement chase the voxel staircase (minutes, GBs).
  const double target = options.workingVoxelMm > 0 ? options.workingVoxelMm
                                                   : std::clamp(options.dilateMm / 2.5, 3.0, 8.0);
  std::array<std::int64_t, 3> factor;
  for (int c = 0; c < 3; ++c)
    factor[c] = std::max<std::int64_t>(1, std::llround(std::floor(target / inSpacing[c] + 1e-9)));
  const Eigen::Vector3d work(inSpacing[0] * factor[0], inSpacing[1] * factor[1],
                             inSpacing[2] * factor[2]);
  const double margin = options.dilateMm + 3 * work.maxCoeff();
  std::array<std::int64_t, 3> pad, wd;
  for (int c = 0; c < 3; ++c) {
    pad[c] = static_cast<std::int64_t>(std::ceil(margin / work[c]));
    wd[c] = (dims[c] + factor[c] - 1) / factor[c] + 2 * pad[c];
  }
  // Working voxel (I,J,K) covers input voxels [(I-pad)*f, (I-pad+1)*f); its centre in input index
  // space is (I - pad) * f + (f - 1) / 2.
  VolumeGeometry g;
  g.dims = wd;
  g.ijkToRas = Eigen::Matrix4d::Identity();
  g.ijkToRas.block<3, 3>(0, 0) =
      in.ijkToRas.block<3, 3>(0, 0) * Eigen::Vector3d(factor[0], factor[1], factor[2]).asDiagonal();
  const Eigen::Vector3d startIndex(-pad[0] * factor[0] + (factor[0] - 1) / 2.0,
                                   -pad[1] * factor[1] + (factor[1] - 1) / 2.0,
                                   -pad[2] * factor[2] + (factor[2] - 1) / 2.0);
  g.ijkToRas.block<3, 1>(0, 3) = in.voxelToRas(startIndex.x(), startIndex.y(), startIndex.z());

  const std::size_t nWork = static_cast<std::size_t>(g.numVoxels());
  Masks m;
  m.body.assign(nWork, 0);
  m.a.assign(options.separations.size(), std::vector<std::uint8_t>(nWork, 0));
  m.b = m.a;
  for (std::int64_t k = 0; k < dims[2]; ++k)
    for (std::int64_t j = 0; j < dims[1]; ++j)
      for (std::int64_t i = 0; i < dims[0]; ++i) {
        const int l = readLabel(parts, parts.index(i, j, k));
        if (!l) continue;
        const std::size_t w = static_cast<std::size_t>(
            (i / factor[0] + pad[0]) +
            wd[0] * ((j / factor[1] + pad[1]) + wd[1] * (k / factor[2] + pad[2])));
        m.body[w] = 1;
        for (std::size_t s = 0; s < options.separations.size(); ++s) {
          if (l == options.separations[s].labelA) m.a[s][w] = 1;
          if (l == options.separations[s].labelB) m.b[s][w] = 1;
        }
      }
  reportProgress(options.progress, 0.1, "cage: distance field");
  const std::vector<float> dBody2 = squaredDistanceToMask(m.body, wd, work, options.threads);
  CageField field;
  field.grid = g;
  field.value.resize(nWork);
  std::size_t deepestAt = 0;
  const std::vector<float> dBg2 = [&] {
    std::vector<std::uint8_t> background(nWork);
    for (std::size_t n = 0; n < nWork; ++n) background[n] = !m.body[n];
    return squaredDistanceToMask(background, wd, work, options.threads);
  }();
  for (std::size_t n = 0; n < nWork; ++n) {
    // Signed distance to the body boundary, shifted by the dilation.
    const double sd = m.body[n] ? -std::sqrt(double(dBg2[n])) : std::sqrt(double(dBody2[n]));
    field.value[n] = static_cast<float>(sd - options.dilateMm);
  }

  // Inset: inside the region, near both parts, points closer to the bisector of A and B than half
  // the gap are pushed outside, so the surface passes between the parts and erodes their contact.
  // Wide enough (3 working voxels) that the surface approximation and a coarse cage keep it open.
  const double halfGap = 1.5 * work.maxCoeff();
  for (std::size_t s = 0; s < options.separations.size(); ++s) {
    const LimbSeparation& sep = options.separations[s];
    const std::vector<float> dA2 = squaredDistanceToMask(m.a[s], wd, work, options.threads);
    const std::vector<float> dB2 = squaredDistanceToMask(m.b[s], wd, work, options.threads);
    std::int64_t selected = 0;
    for (std::int64_t k = 0; k < wd[2]; ++k)
      for (std::int64_t j = 0; j < wd[1]; ++j)
        for (std::int64_t i = 0; i < wd[0]; ++i) {
          const std::size_t n = static_cast<std::size_t>(i + wd[0] * (j + wd[1] * k));
          if (!sep.region.contains(g.voxelToRas(i, j, k))) continue;
          ++selected;
          const double dA = std::sqrt(double(dA2[n])), dB = std::sqrt(double(dB2[n]));
          const double reach = options.dilateMm + 4 * halfGap;
          if (dA > reach || dB > reach) continue;
          field.value[n] =
              std::max(field.value[n], static_cast<float>(halfGap - std::fabs(dA - dB) / 2));
        }
    if (selected == 0) {
      std::ostringstream msg;
      msg << "separation region for labels " << sep.labelA << ":" << sep.labelB
          << " selects no voxel of the volume";
      throw Error(msg.str());
    }
  }
  // The mesher starts from a point strictly inside: the lowest value after the inset.
  deepestAt = static_cast<std::size_t>(std::min_element(field.value.begin(), field.value.end()) -
                                       field.value.begin());
  const std::int64_t di = static_cast<std::int64_t>(deepestAt % wd[0]);
  const std::int64_t dj = static_cast<std::int64_t>((deepestAt / wd[0]) % wd[1]);
  const std::int64_t dk = static_cast<std::int64_t>(deepestAt / (wd[0] * wd[1]));
  field.insidePoint = g.voxelToRas(di, dj, dk);
  return field;
}

}  // namespace repose::cage

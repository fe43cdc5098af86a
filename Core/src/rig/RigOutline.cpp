// The body's outline from the image a segmentation was made from. Organ segmentations
// (TotalSegmentator's, a radiologist's) label organs and bones but not the skin, fat and muscle
// between them: G's non-zero voxels are then islands, and a rig of them alone would pose an arm's
// bones with nothing around them. The CT or MR shows where the body is.
#include "RigInternal.h"

#include "repose/util/Error.h"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace repose::rig {
namespace {

// Otsu's threshold of the values (256 bins between their minimum and maximum).
double otsu(const std::vector<float>& values) {
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  const double a = *lo, b = *hi;
  if (!(b > a)) return a;
  std::array<double, 256> h{};
  for (const float v : values) ++h[std::min<std::size_t>(255, std::size_t((v - a) / (b - a) * 256))];
  double total = 0, sum = 0;
  for (std::size_t i = 0; i < 256; ++i) total += h[i], sum += double(i) * h[i];
  double w0 = 0, sum0 = 0, best = -1;
  std::size_t cut = 0;
  for (std::size_t i = 0; i < 256; ++i) {
    w0 += h[i], sum0 += double(i) * h[i];
    const double w1 = total - w0;
    if (w0 == 0 || w1 == 0) continue;
    const double m0 = sum0 / w0, m1 = (sum - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) best = between, cut = i;
  }
  return a + (double(cut) + 1) / 256 * (b - a);
}

// Keeps the 6-connected pieces of `mask` that hold some of G's labels: the body and its limbs
// (an arm lying apart from the trunk is a piece of its own), not the table or a blanket.
void keepLabelled(std::vector<std::uint8_t>& mask, const std::vector<std::uint8_t>& labelled,
                  const std::array<std::int64_t, 3>& d) {
  const std::int64_t n = d[0] * d[1] * d[2], step[3] = {1, d[0], d[0] * d[1]};
  std::vector<std::int32_t> component(static_cast<std::size_t>(n), -1);
  std::vector<char> keep;
  std::vector<std::int64_t> queue;
  for (std::int64_t s = 0; s < n; ++s) {
    if (!mask[std::size_t(s)] || component[std::size_t(s)] >= 0) continue;
    const std::int32_t c = std::int32_t(keep.size());
    keep.push_back(0);
    queue.assign(1, s);
    component[std::size_t(s)] = c;
    while (!queue.empty()) {
      const std::int64_t v = queue.back();
      queue.pop_back();
      keep.back() = keep.back() || labelled[std::size_t(v)];
      const std::int64_t ijk[3] = {v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])};
      for (int a = 0; a < 3; ++a)
        for (const int o : {-1, 1}) {
          if (ijk[a] + o < 0 || ijk[a] + o >= d[a]) continue;
          const std::int64_t nb = v + o * step[a];
          if (mask[std::size_t(nb)] && component[std::size_t(nb)] < 0)
            component[std::size_t(nb)] = c, queue.push_back(nb);
        }
    }
  }
  for (std::int64_t v = 0; v < n; ++v)
    mask[std::size_t(v)] = mask[std::size_t(v)] && keep[std::size_t(component[std::size_t(v)])];
}

// Fills, slice by slice (k), the background a slice's border cannot reach: lungs, bowel gas, the
// airway. Per slice, since a scan cut through the chest opens the lungs to its first slice.
void fillSlices(std::vector<std::uint8_t>& mask, const std::array<std::int64_t, 3>& d) {
  const std::int64_t plane = d[0] * d[1];
  std::vector<std::uint8_t> reached(static_cast<std::size_t>(plane));
  std::vector<std::int64_t> queue;
  for (std::int64_t k = 0; k < d[2]; ++k) {
    std::uint8_t* m = mask.data() + k * plane;
    std::fill(reached.begin(), reached.end(), std::uint8_t(0));
    queue.clear();
    auto seed = [&](std::int64_t p) {
      if (!m[p] && !reached[std::size_t(p)]) reached[std::size_t(p)] = 1, queue.push_back(p);
    };
    for (std::int64_t i = 0; i < d[0]; ++i) seed(i), seed(i + (d[1] - 1) * d[0]);
    for (std::int64_t j = 0; j < d[1]; ++j) seed(j * d[0]), seed(d[0] - 1 + j * d[0]);
    while (!queue.empty()) {
      const std::int64_t p = queue.back();
      queue.pop_back();
      const std::int64_t i = p % d[0], j = p / d[0];
      if (i > 0) seed(p - 1);
      if (i + 1 < d[0]) seed(p + 1);
      if (j > 0) seed(p - d[0]);
      if (j + 1 < d[1]) seed(p + d[0]);
    }
    for (std::int64_t p = 0; p < plane; ++p)
      if (!m[p] && !reached[std::size_t(p)]) m[p] = 1;
  }
}

}  // namespace

std::vector<std::uint8_t> bodyOutline(const Volume& image, const Volume& organs, const Grid& grid,
                                      std::string& how) {
  if (image.layers() != 1) throw Error("the image has several layers: give one intensity image");
  const auto& d = grid.dims;
  const std::int64_t n = grid.count();
  // The image at each voxel of G's grid (nearest voxel): the same grid, or any other over the
  // same place (a DICOM series and a NIfTI made from it differ by axis flips).
  const Eigen::Matrix4d toImage = image.geometry().ijkToRas.inverse() * organs.geometry().ijkToRas;
  const auto& id = image.dims();
  double low = std::numeric_limits<double>::infinity();
  for (std::int64_t v = 0; v < image.numVoxels(); ++v) low = std::min(low, image.valueAsDouble(v));
  std::vector<float> value(static_cast<std::size_t>(n), float(low));
  std::int64_t covered = 0;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const Eigen::Vector4d p = toImage * Eigen::Vector4d(double(i), double(j), double(k), 1);
        const std::int64_t a = std::int64_t(std::floor(p.x() + 0.5)),
                           b = std::int64_t(std::floor(p.y() + 0.5)),
                           c = std::int64_t(std::floor(p.z() + 0.5));
        if (a < 0 || b < 0 || c < 0 || a >= id[0] || b >= id[1] || c >= id[2]) continue;
        value[std::size_t(i + d[0] * (j + d[1] * k))] = float(image.valueAsDouble(image.index(a, b, c)));
        ++covered;
      }
  if (covered < n / 2)
    throw Error("the image covers " + std::to_string(100 * covered / std::max<std::int64_t>(1, n)) +
                " % of G's grid: is it the scan G was segmented from?");
  // A CT in Hounsfield units (air near -1000): tissue above -300 HU (fat is about -100). Else
  // (MR, or a CT without its rescale) Otsu's threshold between background and body.
  const bool ct = low < -500;
  const double threshold = ct ? -300.0 : otsu(value);
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(n)), labelled(mask.size());
  for (std::int64_t v = 0; v < n; ++v) {
    mask[std::size_t(v)] = double(value[std::size_t(v)]) > threshold;
    labelled[std::size_t(v)] = organs.valueAsDouble(v) > 0;
  }
  keepLabelled(mask, labelled, d);
  for (std::int64_t v = 0; v < n; ++v) mask[std::size_t(v)] |= labelled[std::size_t(v)];
  fillSlices(mask, d);
  std::int64_t added = 0;
  for (std::int64_t v = 0; v < n; ++v) added += mask[std::size_t(v)] && !labelled[std::size_t(v)];
  const double ml = std::fabs(grid.geometry->ijkToRas.block<3, 3>(0, 0).determinant()) / 1000;
  std::ostringstream text;
  text << (ct ? "CT above -300 HU" : "the image above its Otsu threshold " + std::to_string(threshold))
       << ", its pieces that hold G's labels, and the holes of each slice: " << added
       << " voxels (" << std::lround(double(added) * ml) << " ml) of body beyond G's labels";
  how = text.str();
  return mask;
}

}  // namespace repose::rig

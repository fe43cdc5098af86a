#include "repose/volume/BackgroundTrace.h"

#include "repose/util/Error.h"

#include <algorithm>
#include <limits>
#include <string>
#include <type_traits>

namespace repose {

BackgroundTrace::BackgroundTrace(const std::array<std::int64_t, 3>& dims) : dims_(dims) {
  if (dims[0] <= 0 || dims[1] <= 0 || dims[2] <= 0) throw Error("background trace: an empty grid");
  const std::size_t plane = std::size_t(dims[0] * dims[1]);
  below_.assign(plane, -1);
  here_.assign(plane, -1);
  parent_.push_back(0);  // the outside
}

std::int32_t BackgroundTrace::newId() {
  if (parent_.size() >= std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw Error("background trace: more than 2^31 background components");
  parent_.push_back(std::int32_t(parent_.size()));
  return parent_.back();
}

std::int32_t BackgroundTrace::find(std::int32_t id) const {
  std::int32_t root = id;
  while (parent_[std::size_t(root)] != root) root = parent_[std::size_t(root)];
  while (parent_[std::size_t(id)] != root) {
    const std::int32_t up = parent_[std::size_t(id)];
    parent_[std::size_t(id)] = root;
    id = up;
  }
  return root;
}

void BackgroundTrace::join(std::int32_t a, std::int32_t b) {
  a = find(a), b = find(b);
  // The smaller id is the root, so the outside (0) stays its own root.
  if (a < b)
    parent_[std::size_t(b)] = a;
  else if (b < a)
    parent_[std::size_t(a)] = b;
}

template <class T>
void BackgroundTrace::addSlice(const T* slice, std::int64_t k) {
  const std::int64_t nx = dims_[0], ny = dims_[1];
  const bool borderSlice = k == 0 || k == dims_[2] - 1;
  std::swap(below_, here_);
  if (k == 0) std::fill(below_.begin(), below_.end(), -1);
  for (std::int64_t j = 0; j < ny; ++j)
    for (std::int64_t i = 0; i < nx; ++i) {
      const std::int64_t v = j * nx + i;
      std::int32_t& id = here_[std::size_t(v)];
      if (slice[v] != T(0)) {
        id = -1;
        continue;
      }
      // A run continues its left neighbour's component; a new run takes the one above it.
      const std::int32_t left = i > 0 ? here_[std::size_t(v - 1)] : -1;
      const std::int32_t up = j > 0 ? here_[std::size_t(v - nx)] : -1;
      id = left >= 0 ? left : up >= 0 ? up : newId();
      if (left >= 0 && up >= 0 && left != up) join(left, up);
      if (below_[std::size_t(v)] >= 0) join(id, below_[std::size_t(v)]);
      if (borderSlice || i == 0 || j == 0 || i == nx - 1 || j == ny - 1) join(id, 0);
    }
}

void BackgroundTrace::add(const void* slices, ScalarType type, std::int64_t k0, std::int64_t k1,
                          std::vector<std::int64_t>* open) {
  if (finished_ || k0 != next_ || k1 <= k0 || k1 > dims_[2])
    throw Error("background trace: slices [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") out of order (expected from slice " + std::to_string(next_) + " of " +
                std::to_string(dims_[2]) + ")");
  if (!isIntegerType(type)) throw Error("background is traced in label maps, not in float volumes");
  const std::int64_t plane = dims_[0] * dims_[1];
  // The voxels this call leaves open: not outside when their slice was traced, and still not
  // when the last slice of this call was.
  std::vector<std::int64_t> voxels;
  std::vector<std::int32_t> ids;
  dispatchScalar(type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>)
      for (std::int64_t k = k0; k < k1; ++k) {
        addSlice(static_cast<const T*>(slices) + (k - k0) * plane, k);
        // A run's voxels share an id: its root is looked up once per run, not per voxel.
        std::int32_t last = -1;
        bool stillOpen = false;
        for (std::int64_t v = 0; v < plane; ++v) {
          const std::int32_t id = here_[std::size_t(v)];
          if (id < 0) continue;
          if (id != last) last = id, stillOpen = find(id) != 0;
          if (stillOpen) voxels.push_back(k * plane + v), ids.push_back(id);
        }
      }
  });
  next_ = k1;
  // What earlier calls left open and is now joined to the outside is dropped: memory follows
  // the holes.
  std::size_t kept = 0;
  for (std::size_t c = 0; c < openVoxels_.size(); ++c)
    if (find(openIds_[c]) != 0) openVoxels_[kept] = openVoxels_[c], openIds_[kept++] = openIds_[c];
  openVoxels_.resize(kept), openIds_.resize(kept);
  for (std::size_t c = 0; c < voxels.size(); ++c)
    if (find(ids[c]) != 0) {
      openVoxels_.push_back(voxels[c]), openIds_.push_back(ids[c]);
      if (open) open->push_back(voxels[c]);
    }
  if (next_ == dims_[2]) finish();
}

void BackgroundTrace::finish() {
  std::size_t kept = 0;
  for (std::size_t c = 0; c < openVoxels_.size(); ++c)
    if (find(openIds_[c]) != 0) openVoxels_[kept] = openVoxels_[c], openIds_[kept++] = openIds_[c];
  openVoxels_.resize(kept), openIds_.resize(kept);
  finished_ = true;
}

void BackgroundTrace::keepOpen(std::vector<std::int64_t>& voxels) const {
  // add() keeps openVoxels_ to the voxels still open: a voxel not there has joined the outside.
  std::size_t kept = 0;
  for (const std::int64_t v : voxels)
    if (std::binary_search(openVoxels_.begin(), openVoxels_.end(), v)) voxels[kept++] = v;
  voxels.resize(kept);
}

bool BackgroundTrace::enclosed(std::int64_t voxel) const {
  if (!finished_) throw Error("background trace: asked before its last slice");
  return std::binary_search(openVoxels_.begin(), openVoxels_.end(), voxel);
}

std::int64_t BackgroundTrace::enclosedVoxels() const {
  if (!finished_) throw Error("background trace: asked before its last slice");
  return std::int64_t(openVoxels_.size());
}

std::vector<std::int64_t> BackgroundTrace::enclosedList() const {
  if (!finished_) throw Error("background trace: asked before its last slice");
  return openVoxels_;
}

}  // namespace repose

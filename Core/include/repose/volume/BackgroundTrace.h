// Enclosed background traced slice by slice, for label maps too large to hold: the background
// (0) voxels no 6-connected path of background joins to the grid's border, the holes a pose must
// not make (countEnclosedBackground) and the pockets it fills (PocketFilling.h).
//
// Each slice's background is split into its 2D components; each component gets an id in a
// union-find joined to the components below it and, where it reaches the grid's border, to the
// outside. Only two slices of ids and the voxels not yet known to be outside are held, so memory
// follows the holes, not the grid: a body's outside reaches the grid's margin in every slice.
#pragma once

#include "repose/volume/ScalarType.h"

#include <array>
#include <cstdint>
#include <vector>

namespace repose {

class BackgroundTrace {
 public:
  explicit BackgroundTrace(const std::array<std::int64_t, 3>& dims);

  // Slices [k0, k1) of layer 0, x fastest, values of `type` (an integer type); k0 is the last
  // call's k1 (0 the first time). `open`, when given, receives the background voxels of these
  // slices that the slices seen so far do not join to the border (indices into the whole grid,
  // ascending): the caller's candidates, some of which later slices may still join to it.
  void add(const void* slices, ScalarType type, std::int64_t k0, std::int64_t k1,
           std::vector<std::int64_t>* open = nullptr);

  // Drops from `voxels` (ascending, some of what add() listed as open) those the slices seen so
  // far join to the border.
  void keepOpen(std::vector<std::int64_t>& voxels) const;

  // After the last slice: whether a voxel add() listed as open is enclosed (false for any other
  // voxel), and how many voxels are.
  bool enclosed(std::int64_t voxel) const;
  std::int64_t enclosedVoxels() const;
  // The enclosed voxels, ascending.
  std::vector<std::int64_t> enclosedList() const;

 private:
  std::int32_t newId();
  std::int32_t find(std::int32_t id) const;
  void join(std::int32_t a, std::int32_t b);
  template <class T>
  void addSlice(const T* slice, std::int64_t k);
  void finish();

  std::array<std::int64_t, 3> dims_;
  std::int64_t next_ = 0;                     // the next slice add() expects
  mutable std::vector<std::int32_t> parent_;  // id 0: the outside
  std::vector<std::int32_t> below_, here_;    // per voxel of a slice: its component's id, or -1
  std::vector<std::int64_t> openVoxels_;      // ascending
  std::vector<std::int32_t> openIds_;
  bool finished_ = false;
};

}  // namespace repose

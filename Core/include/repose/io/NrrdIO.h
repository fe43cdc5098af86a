// NRRD (.nrrd, .nhdr with raw or gzip data) through teem, with `space` LPS or RAS and direction
// vectors, and 3D Slicer .seg.nrrd: the Segment{N}_* fields, including 4D layered segmentations.
#pragma once

#include "repose/io/VolumeIO.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace repose {

Volume readNrrd(const std::string& path, const ReadOptions& options = {});
// A .seg.nrrd path writes the Slicer segmentation fields; otherwise a plain NRRD in LPS.
void writeNrrd(const Volume& volume, const std::string& path, const WriteOptions& options = {});

// A .seg.nrrd written slice by slice, for a segmentation larger than memory: the voxels go to a
// side file as gzip pieces as they come, the header last (the segments' extents are known only
// then), so the file is the same, byte for byte, as writeVolume of the whole map. Atomic: nothing
// appears at path until finish().
class SegNrrdSlabWriter {
 public:
  SegNrrdSlabWriter(const std::string& path, const VolumeGeometry& geometry, ScalarType type,
                    int layers, const LabelTable& labels);
  ~SegNrrdSlabWriter();
  // `slices` whole k-slices where the last call ended: each layer's slices together, layer after
  // layer (as LabelSlabs writes a slab).
  void writeSlices(const void* data, std::int64_t slices);
  void finish();  // throws unless every slice was written

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A displacement-field transform as ITK and 3D Slicer load it: a NRRD float vector image on
// `grid` (kinds "vector domain domain domain", space left-posterior-superior). rasVectors holds 3
// floats per voxel in RAS mm (rasterizeDisplacement); they are written in LPS. Atomic, gzip.
void writeDisplacementFieldNrrd(const std::vector<float>& rasVectors, const VolumeGeometry& grid,
                                const std::string& path);

// The same file written slice by slice (k slabs in order), for a field larger than memory: the
// same bytes as writeDisplacementFieldNrrd (its gzip pieces are cut from the data stream, not
// from the writes). Atomic: nothing appears at path until finish().
class DisplacementFieldNrrdWriter {
 public:
  DisplacementFieldNrrdWriter(const VolumeGeometry& grid, const std::string& path);
  ~DisplacementFieldNrrdWriter();
  // `slices` whole k-slices of RAS vectors (3 floats per voxel) where the last call ended.
  void writeSlices(const float* rasVectors, std::int64_t slices);
  void finish();  // throws unless every slice was written

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace repose

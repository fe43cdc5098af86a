// NIfTI-1 and NIfTI-2 (.nii, .nii.gz) through niftilib. sform (else qform, else pixdim) gives
// IJK -> RAS; label names come from a Caret/GIFTI XML LabelTable header extension (ecode 0),
// as TotalSegmentator writes them, and are written back the same way.
#pragma once

#include "repose/io/VolumeIO.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace repose {

Volume readNifti(const std::string& path, const ReadOptions& options = {});
void writeNifti(const Volume& volume, const std::string& path, const WriteOptions& options = {});

// Where and how a NIfTI file's voxels lie, to read them in place (out-of-core): geometry, label
// table, in-memory type (the disk type, unscaled), the byte offset of voxel 0, and whether the file
// is gzip-compressed. Throws naming the file when its voxels cannot be used as they are on disk
// (scaled, or a type Repose converts when reading).
struct NiftiLayout {
  VolumeGeometry geometry;
  ScalarType type = ScalarType::UInt8;
  LabelTable labels;
  bool labelMap = false;
  std::int64_t dataOffset = 0;
  bool gzip = false;
};
NiftiLayout readNiftiLayout(const std::string& path);

// The bytes a NIfTI file holds before its voxels (header, label-table extension, padding to the
// voxel offset), exactly as NiftiSlabWriter writes them.
std::vector<char> niftiHeaderBytes(const VolumeGeometry& geometry, ScalarType type,
                                   const LabelTable& labels, bool labelMap, int niftiVersion = 1);

// A .nii.gz is written as independent gzip pieces (GzipPieces.h): the header bytes, then the
// voxels in pieces of this many whole k-slices (about kNiftiGzipPieceBytes each; the last may be
// shorter). A fixed function of the grid and type, so a writer on several threads or MPI ranks
// that cuts the same pieces writes the same bytes.
constexpr std::int64_t kNiftiGzipPieceBytes = std::int64_t(4) << 20;
std::int64_t niftiGzipPieceSlices(const VolumeGeometry& geometry, ScalarType type);

// Writes a single-layer NIfTI slice by slice (k slabs in order) so a volume larger than memory
// can be produced with bounded memory; a .nii.gz's pieces are compressed on all cores. Atomic:
// nothing appears at path until finish().
class NiftiSlabWriter {
 public:
  NiftiSlabWriter(const std::string& path, const VolumeGeometry& geometry, ScalarType type,
                  const LabelTable& labels, bool labelMap, int niftiVersion = 1);
  ~NiftiSlabWriter();
  // `slices` whole k-slices of voxels in file order, starting where the previous call ended.
  void writeSlices(const void* data, std::int64_t slices);
  void finish();  // throws unless every slice was written

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace repose

// NRRD (.nrrd, .nhdr with raw or gzip data) through teem, with `space` LPS or RAS and direction
// vectors, and 3D Slicer .seg.nrrd: the Segment{N}_* fields, including 4D layered segmentations.
#pragma once

#include "repose/io/VolumeIO.h"

namespace repose {

Volume readNrrd(const std::string& path, const ReadOptions& options = {});
// A .seg.nrrd path writes the Slicer segmentation fields; otherwise a plain NRRD in LPS.
void writeNrrd(const Volume& volume, const std::string& path, const WriteOptions& options = {});

// A displacement-field transform as ITK and 3D Slicer load it: a NRRD float vector image on
// `grid` (kinds "vector domain domain domain", space left-posterior-superior). rasVectors holds 3
// floats per voxel in RAS mm (rasterizeDisplacement); they are written in LPS. Atomic, gzip.
void writeDisplacementFieldNrrd(const std::vector<float>& rasVectors, const VolumeGeometry& grid,
                                const std::string& path);

}  // namespace repose

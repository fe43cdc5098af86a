// Helpers every reader shares: file checks, conversion of on-disk voxel types to the in-memory
// ones, and the rule that decides whether an integer volume is a label map.
#pragma once

#include "repose/io/VolumeIO.h"
#include "repose/volume/Volume.h"

#include <cstdint>
#include <string>

namespace repose::io {

// On-disk scalar types the readers accept.
enum class DiskType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

const char* diskTypeName(DiskType t);
std::size_t diskTypeSize(DiskType t);
// The in-memory type a disk type is kept as (int8 -> int16, wider ints -> int32, f64 -> f32).
ScalarType memoryTypeFor(DiskType t);
// Converts n values; throws naming path when an integer does not fit the memory type.
void convertVoxels(DiskType from, const void* in, ScalarType to, void* out, std::int64_t n,
                   const std::string& path);

// Throws naming path, with the numbers, when a read needing voxels x bytesPerVoxel would exceed
// options.memoryLimitBytes (when set). Called after the header, before any voxel is allocated.
void checkReadMemory(const std::string& path, std::int64_t voxels, double bytesPerVoxel,
                     const ReadOptions& options);

// Throws "path: file not found" / "is a folder" / "cannot be read" before a library gets it.
void requireReadableFile(const std::string& path);

// An integer volume with at most 256 distinct non-negative values (and a label table or a label
// intent when the file has one) is treated as a label map; CT/MR intensities are not.
bool looksLikeLabelMap(const Volume& volume);

}  // namespace repose::io

// Voxels of a NIfTI file larger than memory, read in place (the out-of-core rasterizer's input):
// blocks of whole k-slices, contiguous on disk and read with one call each, kept under a byte
// budget, least recently used out first. A .nii.gz is decompressed once, streaming, into a
// temporary .nii (in the system temp folder) that the cache deletes when it goes.
#pragma once

#include "repose/io/NiftiIO.h"

#include <cstdint>
#include <memory>
#include <string>

namespace repose {

class SliceCache {
 public:
  SliceCache(const std::string& path, std::size_t budgetBytes);
  ~SliceCache();
  SliceCache(const SliceCache&) = delete;
  SliceCache& operator=(const SliceCache&) = delete;

  const NiftiLayout& layout() const;
  // Slice k's dims[0]*dims[1] voxels of layout().type; valid until the next call. Not thread-safe.
  const void* slice(std::int64_t k);
  std::int64_t blockReads() const;  // blocks read from disk so far
  std::size_t blockBytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace repose

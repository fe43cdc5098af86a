// The gzip-encoded voxels of a NRRD whose header teem has read, inflated through a zlib stream of
// our own that is released on every path; and written the same way after teem wrote the header.
// teem's gzip reader keeps its stream (about 50 KB) when the data are short or corrupt: a workbench
// or a batch script fed file after file would grow by that much with every bad file.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace repose::io {

// Reads `bytes` bytes of voxels from `file`, positioned at the data (gzip members, one or several
// back to back; a zlib stream is accepted too), into a buffer from malloc (teem frees a Nrrd's data
// with free). With `swap`, elements of `elementSize` bytes are turned to the host's byte order.
// Throws repose::Error naming `path` when the data end early or do not inflate.
void* readGzipVoxels(std::FILE* file, std::size_t bytes, std::size_t elementSize, bool swap,
                     const std::string& path);

// Writes `bytes` bytes of voxels as the gzip data of a NRRD whose header teem wrote (with
// skipData): appended to `dataPath` after an attached header, or as the detached data file
// `dataPath`. teem's own gzip writer kept its zlib stream when a write failed (a full disk); this
// one holds nothing past its return. One gzip member of independently compressed 4 MiB pieces
// (GzipPieces.h), deflated on every core. Throws repose::Error naming `path` when a write fails.
void writeGzipVoxels(const std::string& dataPath, bool append, const void* data, std::size_t bytes,
                     const std::string& path);

}  // namespace repose::io

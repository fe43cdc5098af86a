#include "NrrdGzipData.h"

#include "repose/io/GzipPieces.h"
#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <zlib.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <vector>

namespace repose::io {
namespace {

struct Inflater {
  z_stream stream{};
  bool open = false;
  ~Inflater() {
    if (open) inflateEnd(&stream);
  }
};

struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};

}  // namespace

void* readGzipVoxels(std::FILE* file, std::size_t bytes, std::size_t elementSize, bool swap,
                     const std::string& path) {
  std::unique_ptr<void, FreeDeleter> data(std::malloc(std::max<std::size_t>(bytes, 1)));
  if (!data) throwFileError(path, "not enough memory for its voxels");
  auto* out = static_cast<unsigned char*>(data.get());
  Inflater z;
  // 15 + 32: a gzip or zlib header, detected from the data.
  if (inflateInit2(&z.stream, 15 + 32) != Z_OK) throwFileError(path, "zlib could not start");
  z.open = true;
  std::vector<unsigned char> in(1 << 18);
  std::size_t done = 0;
  bool ended = false;  // the last member's end was reached with no input after it
  while (done < bytes) {
    if (z.stream.avail_in == 0) {
      const std::size_t got = std::fread(in.data(), 1, in.size(), file);
      if (got == 0) break;  // no more compressed data
      z.stream.next_in = in.data();
      z.stream.avail_in = static_cast<uInt>(got);
    }
    const std::size_t room = std::min<std::size_t>(bytes - done, 1u << 30);
    z.stream.next_out = out + done;
    z.stream.avail_out = static_cast<uInt>(room);
    const uInt inBefore = z.stream.avail_in;
    const int rc = inflate(&z.stream, Z_NO_FLUSH);
    done += room - z.stream.avail_out;
    if (rc == Z_BUF_ERROR && z.stream.avail_in == inBefore && z.stream.avail_out == room &&
        z.stream.avail_in > 0)
      throwFileError(path, "voxel data is truncated or corrupt (gzip: no progress)");
    if (rc == Z_STREAM_END) {
      // Another gzip member may follow (a concatenated file): start over on what is left.
      if (done < bytes && inflateReset(&z.stream) != Z_OK)
        throwFileError(path, "voxel data is truncated or corrupt (gzip)");
      ended = true;
      continue;
    }
    ended = false;
    if (rc != Z_OK && rc != Z_BUF_ERROR)
      throwFileError(path, std::string("voxel data is truncated or corrupt (gzip: ") +
                               (z.stream.msg ? z.stream.msg : "inflate failed") + ")");
  }
  if (done < bytes)
    throwFileError(path, "voxel data is truncated or corrupt (gzip data hold " +
                             std::to_string(done) + " of the " + std::to_string(bytes) +
                             " bytes the header gives" + (ended ? "" : ", cut off") + ")");
  if (swap && elementSize > 1)
    for (std::size_t e = 0; e + elementSize <= bytes; e += elementSize)
      std::reverse(out + e, out + e + elementSize);
  return data.release();
}

void writeGzipVoxels(const std::string& dataPath, bool append, const void* data, std::size_t bytes,
                     const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(
      std::fopen(dataPath.c_str(), append ? "ab" : "wb"), &std::fclose);
  if (!file) throwFileError(path, "cannot create the output file");
  const auto put = [&](const std::string& bytesOut) {
    if (std::fwrite(bytesOut.data(), 1, bytesOut.size(), file.get()) != bytesOut.size())
      throwFileError(path, "write failed (disk full?)");
  };
  constexpr std::size_t kPiece = std::size_t(4) << 20;
  const std::size_t pieces = (bytes + kPiece - 1) / kPiece;
  const auto* in = static_cast<const char*>(data);
  // A batch of pieces at a time, so the compressed copy stays small beside the volume.
  constexpr std::size_t kBatch = 16;
  std::vector<std::string> packed(kBatch);
  std::vector<std::uint32_t> crcs(kBatch);
  std::uint32_t crc = 0;
  put(gzipHeaderBytes());
  for (std::size_t first = 0; first < pieces; first += kBatch) {
    const std::size_t n = std::min(kBatch, pieces - first);
    const auto sizeOf = [&](std::size_t p) { return std::min(kPiece, bytes - p * kPiece); };
    parallelFor(
        std::int64_t(n), 0,
        [&](std::int64_t a, std::int64_t b) {
          for (std::int64_t i = a; i < b; ++i) {
            const std::size_t p = first + std::size_t(i);
            packed[std::size_t(i)] = deflatePiece(in + p * kPiece, sizeOf(p));
            crcs[std::size_t(i)] = crc32Of(in + p * kPiece, sizeOf(p));
          }
        },
        1);
    for (std::size_t i = 0; i < n; ++i) {
      crc = crc32Concat(crc, crcs[i], sizeOf(first + i));
      put(packed[i]);
    }
  }
  put(gzipTrailerBytes(crc, bytes));
  if (std::fflush(file.get()) != 0) throwFileError(path, "write failed (disk full?)");
  if (std::fclose(file.release()) != 0) throwFileError(path, "write failed (disk full?)");
}

}  // namespace repose::io

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
  // The same pieces as a volume streamed slab by slab (GzipPieceStream): the same bytes.
  GzipPieceStream stream(file.get(), path);
  stream.write(data, bytes);
  stream.finish();
  if (std::fflush(file.get()) != 0) throwFileError(path, "write failed (disk full?)");
  if (std::fclose(file.release()) != 0) throwFileError(path, "write failed (disk full?)");
}

}  // namespace repose::io

#include "repose/io/GzipPieces.h"

#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <zlib.h>

#include <algorithm>

namespace repose {

std::string gzipHeaderBytes() {
  // ID1 ID2, CM = deflate, FLG = 0, MTIME = 0, XFL = 0, OS = 255 (unknown).
  return std::string("\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\xff", 10);
}

std::string deflatePiece(const void* data, std::size_t size, int level) {
  z_stream z{};
  // Raw deflate (negative window bits): the member's header and trailer are written separately.
  if (deflateInit2(&z, level, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("gzip: cannot start a deflate stream");
  std::string out;
  const auto* in = static_cast<const Bytef*>(data);
  std::size_t left = size;
  int rc = Z_OK;
  do {
    // zlib counts in 32-bit lengths: feed large pieces in parts.
    if (z.avail_in == 0 && left > 0) {
      const auto n = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
      z.next_in = const_cast<Bytef*>(in);
      z.avail_in = n;
      in += n;
      left -= n;
    }
    // Output room in modest steps: a label map's piece shrinks 10-100x, so a buffer sized for
    // the worst case (deflateBound) would only add to the resident memory of every piece held.
    const std::size_t at = out.size();
    const std::size_t room = std::size_t(1) << 18;
    out.resize(at + room);
    z.next_out = reinterpret_cast<Bytef*>(&out[at]);
    z.avail_out = static_cast<uInt>(room);
    rc = deflate(&z, left > 0 ? Z_NO_FLUSH : Z_SYNC_FLUSH);
    out.resize(out.size() - z.avail_out);
    if (rc != Z_OK && rc != Z_BUF_ERROR) {
      deflateEnd(&z);
      throw Error("gzip: deflate failed");
    }
    // Done when all input is in and the sync flush left room to spare (it completed).
  } while (left > 0 || z.avail_in > 0 || z.avail_out == 0);
  deflateEnd(&z);
  out.shrink_to_fit();
  return out;
}

std::string gzipTrailerBytes(std::uint32_t crc, std::uint64_t size) {
  std::string t("\x03\x00", 2);  // an empty final block with fixed Huffman codes
  const std::uint32_t isize = static_cast<std::uint32_t>(size);
  for (int b = 0; b < 4; ++b) t.push_back(static_cast<char>((crc >> (8 * b)) & 0xff));
  for (int b = 0; b < 4; ++b) t.push_back(static_cast<char>((isize >> (8 * b)) & 0xff));
  return t;
}

std::uint32_t crc32Of(const void* data, std::size_t size, std::uint32_t crc) {
  const auto* p = static_cast<const Bytef*>(data);
  uLong c = crc;
  while (size > 0) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
    c = crc32(c, p, n);
    p += n;
    size -= n;
  }
  return static_cast<std::uint32_t>(c);
}

std::uint32_t crc32Concat(std::uint32_t crcA, std::uint32_t crcB, std::uint64_t sizeB) {
  return static_cast<std::uint32_t>(crc32_combine(crcA, crcB, static_cast<z_off_t>(sizeB)));
}

GzipPieceStream::GzipPieceStream(std::FILE* file, std::string path, std::size_t pieceBytes)
    : file_(file), path_(std::move(path)), piece_(pieceBytes) {
  if (piece_ == 0) throw Error("gzip: pieces of 0 bytes");
  put(gzipHeaderBytes());
}

void GzipPieceStream::put(const std::string& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    throwFileError(path_, "write failed (disk full?)");
}

void GzipPieceStream::deflateBatch(const std::vector<const char*>& pieces,
                                   const std::vector<std::size_t>& sizes) {
  std::vector<std::string> packed(pieces.size());
  std::vector<std::uint32_t> crcs(pieces.size());
  parallelFor(
      std::int64_t(pieces.size()), 0,
      [&](std::int64_t a, std::int64_t b) {
        for (std::int64_t i = a; i < b; ++i) {
          packed[std::size_t(i)] = deflatePiece(pieces[std::size_t(i)], sizes[std::size_t(i)]);
          crcs[std::size_t(i)] = crc32Of(pieces[std::size_t(i)], sizes[std::size_t(i)]);
        }
      },
      1);
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    crc_ = crc32Concat(crc_, crcs[i], sizes[i]);
    put(packed[i]);
  }
}

void GzipPieceStream::write(const void* data, std::size_t bytes) {
  if (finished_) throw Error("gzip: written after its end");
  const char* in = static_cast<const char*>(data);
  total_ += bytes;
  // A batch of pieces at a time, so the compressed copy stays small beside the data.
  constexpr std::size_t kBatch = 16;
  std::vector<const char*> pieces;
  std::vector<std::size_t> sizes;
  std::string first;  // the held partial piece completed, when there is one
  if (!partial_.empty()) {
    const std::size_t take = std::min(bytes, piece_ - partial_.size());
    partial_.append(in, take);
    in += take, bytes -= take;
    if (partial_.size() < piece_) return;
    first.swap(partial_);
    pieces.push_back(first.data()), sizes.push_back(first.size());
  }
  // Whole pieces straight from the caller's data; the rest is held.
  while (bytes >= piece_) {
    pieces.push_back(in), sizes.push_back(piece_);
    in += piece_, bytes -= piece_;
    if (pieces.size() == kBatch) deflateBatch(pieces, sizes), pieces.clear(), sizes.clear();
  }
  if (!pieces.empty()) deflateBatch(pieces, sizes);
  partial_.assign(in, bytes);
}

void GzipPieceStream::finish() {
  if (finished_) return;
  if (!partial_.empty()) deflateBatch({partial_.data()}, {partial_.size()});
  partial_.clear();
  put(gzipTrailerBytes(crc_, total_));
  finished_ = true;
}

}  // namespace repose

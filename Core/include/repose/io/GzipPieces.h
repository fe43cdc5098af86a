// A gzip file made of independently compressed pieces (the layout pigz writes, without the
// dictionary carried from piece to piece): one gzip member whose deflate stream is the
// concatenation of raw deflate streams, each started afresh and ended byte-aligned with a sync
// flush, closed by an empty final block and the CRC-32 and length of the whole. Any gzip reader
// (zlib's gzread, niftilib, Python's gzip, nibabel) reads it as one stream. Because a piece's
// bytes depend on its own data only, pieces can be compressed in any order, on any thread or MPI
// rank, and the file is the same byte for byte: that is how `repose warp --mpi` writes the
// serial writer's exact .nii.gz from several ranks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace repose {

// The 10-byte member header: deflate, no name, no time stamp (the bytes depend on the data only),
// OS "unknown".
std::string gzipHeaderBytes();

// `size` bytes as one piece (level 1: label maps compress nearly as well as at level 6, several
// times faster). Throws repose::Error when zlib fails.
std::string deflatePiece(const void* data, std::size_t size, int level = 1);

// The end of the member: the empty final block, then the CRC-32 and the length (mod 2^32) of all
// the data, little-endian.
std::string gzipTrailerBytes(std::uint32_t crc, std::uint64_t size);

// CRC-32 of data, continuing `crc`; and the CRC of A followed by B from CRC(A), CRC(B) and |B|.
std::uint32_t crc32Of(const void* data, std::size_t size, std::uint32_t crc = 0);
std::uint32_t crc32Concat(std::uint32_t crcA, std::uint32_t crcB, std::uint64_t sizeB);

// One gzip member written to an open file as the data arrive, cut into pieces of `pieceBytes` of
// the data stream whatever the sizes of the writes, so a volume written slab by slab is the same
// file, byte for byte, as one written whole. Full pieces are deflated in batches on every core;
// at most one partial piece is held between writes. Throws repose::Error naming `path` when a
// write fails.
class GzipPieceStream {
 public:
  GzipPieceStream(std::FILE* file, std::string path, std::size_t pieceBytes = std::size_t(4) << 20);
  void write(const void* data, std::size_t bytes);
  void finish();  // the last piece and the trailer
  std::uint64_t bytesIn() const { return total_; }

 private:
  void put(const std::string& bytes);
  void deflateBatch(const std::vector<const char*>& pieces, const std::vector<std::size_t>& sizes);

  std::FILE* file_;
  std::string path_;
  std::size_t piece_;
  std::string partial_;
  std::uint32_t crc_ = 0;
  std::uint64_t total_ = 0;
  bool finished_ = false;
};

}  // namespace repose

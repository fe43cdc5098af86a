// The gzip piece layout (io/GzipPieces.h) and the .nii.gz it makes: any gzip reader gets the data
// back; a file assembled from pieces compressed separately, in any order, equals the writer's
// byte for byte (what `repose warp --mpi` relies on); and the writer's bytes do not depend on how
// its caller cuts the slices into calls.
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/io/GzipPieces.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/NrrdIO.h"
#include "repose/util/Error.h"
#include "repose/io/VolumeIO.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <iterator>
#include <random>

using namespace repose;
using namespace repose::test;

namespace {

// zlib's own gzip decoder (16 + window bits: a gzip wrapper, checked CRC and length).
std::string gunzip(const std::string& gz) {
  z_stream z{};
  EXPECT_EQ(inflateInit2(&z, 16 + MAX_WBITS), Z_OK);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(gz.data()));
  z.avail_in = static_cast<uInt>(gz.size());
  std::string out;
  int rc = Z_OK;
  while (rc == Z_OK) {
    char buffer[1 << 16];
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof(buffer);
    rc = inflate(&z, Z_NO_FLUSH);
    out.append(buffer, sizeof(buffer) - z.avail_out);
  }
  EXPECT_EQ(rc, Z_STREAM_END) << "not a complete gzip stream";
  EXPECT_EQ(z.avail_in, 0u) << "bytes after the gzip member";
  inflateEnd(&z);
  return out;
}

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Label-map-like data: runs of a few values, with some noise.
std::string labelBytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::string s(n, '\0');
  char v = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (rng() % 500 == 0) v = static_cast<char>(rng() % 7);
    s[i] = rng() % 97 == 0 ? static_cast<char>(rng()) : v;
  }
  return s;
}

}  // namespace

TEST(GzipPieces, PiecesConcatenatedAreOneGzipStreamWithTheWholeCrcAndLength) {
  for (const std::vector<std::size_t>& sizes :
       std::vector<std::vector<std::size_t>>{{0}, {1}, {5, 0, 7}, {70000, 1, 200000, 3 << 20}}) {
    std::string data, gz = gzipHeaderBytes();
    std::uint32_t crc = 0;
    unsigned seed = 1;
    for (const std::size_t n : sizes) {
      const std::string piece = labelBytes(n, seed++);
      gz += deflatePiece(piece.data(), piece.size());
      crc = crc32Concat(crc, crc32Of(piece.data(), piece.size()), piece.size());
      data += piece;
    }
    EXPECT_EQ(crc, crc32Of(data.data(), data.size()));
    gz += gzipTrailerBytes(crc, data.size());
    EXPECT_EQ(gunzip(gz), data) << sizes.size() << " pieces";
  }
  // Incompressible data grows by a few bytes only, and a wrong CRC is caught by the reader.
  std::mt19937 rng(3);
  std::string noise(1 << 20, '\0');
  for (char& c : noise) c = static_cast<char>(rng());
  const std::string packed = deflatePiece(noise.data(), noise.size());
  EXPECT_LT(packed.size(), noise.size() + 1024);
  std::string gz = gzipHeaderBytes() + packed + gzipTrailerBytes(crc32Of(noise.data(), 5), 1 << 20);
  z_stream z{};
  inflateInit2(&z, 16 + MAX_WBITS);
  std::string out(noise.size() + 16, '\0');
  z.next_in = reinterpret_cast<Bytef*>(gz.data());
  z.avail_in = static_cast<uInt>(gz.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(inflate(&z, Z_FINISH), Z_DATA_ERROR);
  inflateEnd(&z);
}

TEST(GzipPieces, NiftiWriterBytesAreThePiecesAndDoNotDependOnTheCallsSlicing) {
  ScratchDir dir;
  // 61 x 47 slices of int16: 5,734 bytes each, so a 4 MiB piece is 731 slices; 1,700 slices make
  // two whole pieces and a short last one.
  const VolumeGeometry g = obliqueGeometry({61, 47, 1700});
  Volume v = randomVolume(ScalarType::Int16, g, 9, 5);
  v.setLabelMap(true);
  LabelTable labels;
  Label liver;
  liver.value = 3, liver.name = "liver", liver.color = {0.8, 0.4, 0.3};
  labels.set(liver);
  v.labels() = labels;
  const std::int64_t sliceBytes = 61 * 47 * 2;
  ASSERT_EQ(niftiGzipPieceSlices(g, ScalarType::Int16), kNiftiGzipPieceBytes / sliceBytes);
  const auto* voxels = static_cast<const char*>(v.layerData(0));

  // The whole volume in one call, and in calls of 1, 2, 3, ... slices: the same file.
  const std::string whole = dir.file("whole.nii.gz");
  writeVolume(v, whole);
  const std::string cut = dir.file("cut.nii.gz");
  {
    NiftiSlabWriter w(cut, g, ScalarType::Int16, labels, true);
    std::int64_t k = 0;
    for (std::int64_t n = 1; k < g.dims[2]; ++n) {
      const std::int64_t m = std::min(n, g.dims[2] - k);
      w.writeSlices(voxels + k * sliceBytes, m);
      k += m;
    }
    w.finish();
  }
  const std::string bytes = fileBytes(whole);
  EXPECT_EQ(fileBytes(cut), bytes);

  // The same bytes assembled from separately compressed pieces, compressed last to first.
  const std::vector<char> header = niftiHeaderBytes(g, ScalarType::Int16, labels, true);
  const std::int64_t pieceSlices = niftiGzipPieceSlices(g, ScalarType::Int16);
  std::vector<std::string> pieces;
  for (std::int64_t k = 0; k < g.dims[2]; k += pieceSlices) pieces.emplace_back();
  std::uint32_t crc = crc32Of(header.data(), header.size());
  for (std::size_t p = pieces.size(); p-- > 0;) {
    const std::int64_t k0 = std::int64_t(p) * pieceSlices;
    const std::int64_t n = std::min(pieceSlices, g.dims[2] - k0) * sliceBytes;
    pieces[p] = deflatePiece(voxels + k0 * sliceBytes, std::size_t(n));
  }
  std::string assembled = gzipHeaderBytes() + deflatePiece(header.data(), header.size());
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const std::int64_t k0 = std::int64_t(p) * pieceSlices;
    const std::int64_t n = std::min(pieceSlices, g.dims[2] - k0) * sliceBytes;
    crc = crc32Concat(crc, crc32Of(voxels + k0 * sliceBytes, std::size_t(n)), std::uint64_t(n));
    assembled += pieces[p];
  }
  const std::uint64_t raw = header.size() + std::uint64_t(v.numVoxels()) * 2;
  assembled += gzipTrailerBytes(crc, raw);
  EXPECT_EQ(assembled, bytes);
  ASSERT_EQ(pieces.size(), 3u);

  // Readers: ours (niftilib's gzip reader) and zlib's give back the volume and the header bytes.
  const Volume r = readVolume(whole);
  EXPECT_TRUE(sameVoxels(v, r));
  EXPECT_EQ(r.labels().find(3)->name, "liver");
  const std::string plain = gunzip(bytes);
  ASSERT_EQ(plain.size(), raw);
  EXPECT_EQ(plain.substr(0, header.size()), std::string(header.begin(), header.end()));
  // The uncompressed writer puts the same header and voxels down.
  const std::string nii = dir.file("whole.nii");
  writeVolume(v, nii);
  EXPECT_EQ(fileBytes(nii), plain);
}

// A stream of pieces cut from the data, not from the writes: any slicing of the same bytes into
// writes gives the same file, which any gzip reader reads back whole.
TEST(GzipPieces, AStreamsBytesDoNotDependOnHowItsWritesAreCut) {
  ScratchDir dir;
  const std::string data = labelBytes(3 * 1000 + 17, 5);
  auto streamed = [&](const std::vector<std::size_t>& cuts, const std::string& name) {
    const std::string path = dir.file(name);
    std::FILE* file = std::fopen(path.c_str(), "wb");
    GzipPieceStream stream(file, path, 1000);
    std::size_t at = 0;
    for (std::size_t c = 0; at < data.size(); ++c) {
      const std::size_t n = std::min(cuts[c % cuts.size()], data.size() - at);
      stream.write(data.data() + at, n);
      at += n;
    }
    stream.finish();
    EXPECT_EQ(stream.bytesIn(), data.size());
    std::fclose(file);
    return fileBytes(path);
  };
  const std::string whole = streamed({data.size()}, "whole.gz");
  EXPECT_EQ(gunzip(whole), data);
  EXPECT_EQ(streamed({1}, "ones.gz"), whole);
  EXPECT_EQ(streamed({999, 2, 1000, 3001}, "mixed.gz"), whole);
  EXPECT_EQ(streamed({250}, "quarters.gz"), whole);
}

// The displacement field written slab by slab is the whole field's file, byte for byte.
TEST(GzipPieces, AFieldWrittenInSlabsIsTheWholeFieldsFile) {
  ScratchDir dir;
  const VolumeGeometry g = obliqueGeometry({37, 29, 41});
  std::vector<float> field(std::size_t(3 * g.numVoxels()));
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> mm(-30, 30);
  for (float& f : field) f = mm(rng);
  const std::string whole = dir.file("whole.nrrd");
  writeDisplacementFieldNrrd(field, g, whole);
  const std::int64_t plane = 37 * 29;
  for (const std::int64_t slab : {std::int64_t(1), std::int64_t(6), std::int64_t(41)}) {
    const std::string path = dir.file("slabs" + std::to_string(slab) + ".nrrd");
    DisplacementFieldNrrdWriter writer(g, path);
    for (std::int64_t k0 = 0; k0 < 41; k0 += slab)
      writer.writeSlices(field.data() + 3 * k0 * plane, std::min<std::int64_t>(slab, 41 - k0));
    EXPECT_FALSE(std::ifstream(path).good()) << "nothing appears before finish()";
    writer.finish();
    EXPECT_EQ(fileBytes(path), fileBytes(whole)) << "slabs of " << slab;
  }
  // Read back: the vectors in LPS, as the whole writer puts them.
  const Volume read = readVolume(whole);
  EXPECT_EQ(read.dims(), (std::array<std::int64_t, 3>{37, 29, 41}));
  EXPECT_EQ(read.layers(), 3);
  EXPECT_FLOAT_EQ(read.data<float>(0)[5], -field[15]);
  EXPECT_FLOAT_EQ(read.data<float>(2)[5], field[17]);
  DisplacementFieldNrrdWriter short_(g, dir.file("short.nrrd"));
  short_.writeSlices(field.data(), 40);
  EXPECT_THROW(short_.finish(), Error);
}

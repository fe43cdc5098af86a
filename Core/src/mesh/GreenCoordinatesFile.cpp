#include "GreenCoordinatesFile.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"

#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>

namespace repose {
namespace {

// Layout (host byte order, checked by the marker): magic, version, byte-order marker, key, the
// mesh's vertex count, the cage's vertex and face counts, #V_c, unreproduced, V_c (int32),
// rest positions (double, column-major), CRC-32 of those two arrays, the compact matrix
// (CompactGreenMatrix::writeTo), its CRC-32.
constexpr char kMagic[8] = {'R', 'E', 'P', 'O', 'S', 'E', 'G', 'C'};
// 2: coordinates of the closed forms made stable above a cage edge's line (GreenCoordinates.cpp);
// files of version 1 hold the earlier ones and are computed again.
constexpr std::uint32_t kVersion = 2;
constexpr std::uint32_t kByteOrder = 0x01020304;

struct Header {
  char magic[8];
  std::uint32_t version, byteOrder;
  std::uint64_t key;
  std::int64_t meshVertices, cageVertices, cageFaces, rows, unreproduced;
};

std::uint64_t fnv1a(std::uint64_t h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
  return h;
}

template <class M>
std::uint64_t hashMatrix(std::uint64_t h, const M& m) {
  const std::int64_t size[2] = {m.rows(), m.cols()};
  h = fnv1a(h, size, sizeof(size));
  return fnv1a(h, m.data(), static_cast<std::size_t>(m.size()) * sizeof(*m.data()));
}

std::uint32_t smallArraysCrc(const std::vector<int>& cageVertices, const Eigen::MatrixX3d& rest) {
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, reinterpret_cast<const Bytef*>(cageVertices.data()),
              static_cast<uInt>(cageVertices.size() * sizeof(int)));
  crc = crc32(crc, reinterpret_cast<const Bytef*>(rest.data()),
              static_cast<uInt>(rest.size() * sizeof(double)));
  return static_cast<std::uint32_t>(crc);
}

}  // namespace

std::uint64_t greenCoordinatesKey(const TransferMesh& mesh, const TriangleMesh& cage) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  h = fnv1a(h, &kVersion, sizeof(kVersion));
  h = hashMatrix(h, mesh.vertices);
  h = hashMatrix(h, mesh.tets);
  h = hashMatrix(h, cage.vertices);
  return hashMatrix(h, cage.faces);
}

void writeGreenCoordinatesFile(const std::string& path, std::uint64_t key,
                               Eigen::Index meshVertices, const std::vector<int>& cageVertices,
                               int unreproduced, const Eigen::MatrixX3d& restPositions,
                               const CompactGreenMatrix& coefficients, int threads) {
  if (Eigen::Index(cageVertices.size()) != restPositions.rows() ||
      restPositions.rows() != coefficients.rows())
    throw Error(path + ": Green coordinates with rows that do not match V_c");
  AtomicOutput output(path);
  {
    std::ofstream out(output.tempPath(), std::ios::binary);
    if (!out) throw Error(path + ": cannot create the file");
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof(kMagic));
    h.version = kVersion, h.byteOrder = kByteOrder, h.key = key;
    h.meshVertices = meshVertices;
    h.cageVertices = coefficients.vertexCols();
    h.cageFaces = coefficients.cols() - coefficients.vertexCols();
    h.rows = restPositions.rows();
    h.unreproduced = unreproduced;
    out.write(reinterpret_cast<const char*>(&h), sizeof(h));
    out.write(reinterpret_cast<const char*>(cageVertices.data()),
              static_cast<std::streamsize>(cageVertices.size() * sizeof(int)));
    out.write(reinterpret_cast<const char*>(restPositions.data()),
              static_cast<std::streamsize>(restPositions.size() * sizeof(double)));
    const std::uint32_t smallCrc = smallArraysCrc(cageVertices, restPositions);
    out.write(reinterpret_cast<const char*>(&smallCrc), sizeof(smallCrc));
    coefficients.writeTo(out);
    const std::uint32_t matrixCrc = coefficients.checksum(threads);
    out.write(reinterpret_cast<const char*>(&matrixCrc), sizeof(matrixCrc));
    if (!out.flush()) throw Error(path + ": write failed (disk full?)");
  }
  output.commit();
}

std::optional<SavedGreenCoordinates> readGreenCoordinatesFile(const std::string& path,
                                                              std::uint64_t key,
                                                              Eigen::Index meshVertices,
                                                              const TriangleMesh& cage, int threads,
                                                              std::string* why) {
  const auto fail = [&](const std::string& reason) -> std::optional<SavedGreenCoordinates> {
    if (why) *why = path + ": " + reason;
    return std::nullopt;
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail("no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot be opened");
  Header h{};
  if (!in.read(reinterpret_cast<char*>(&h), sizeof(h))) return fail("cut short (no header)");
  if (std::memcmp(h.magic, kMagic, sizeof(kMagic)) != 0)
    return fail("not a Repose Green-coordinate file");
  if (h.byteOrder != kByteOrder) return fail("written on a machine of another byte order");
  if (h.version != kVersion)
    return fail("format version " + std::to_string(h.version) + ", this build reads " +
                std::to_string(kVersion));
  if (h.key != key) return fail("written for another transfer mesh or cage");
  const Eigen::Index vertexCols = cage.vertices.rows(), faceCols = cage.faces.rows();
  if (h.meshVertices != meshVertices || h.cageVertices != vertexCols || h.cageFaces != faceCols ||
      h.rows <= 0 || h.rows > meshVertices || h.unreproduced < 0 || h.unreproduced > meshVertices)
    return fail("sizes that do not fit this mesh and cage");
  SavedGreenCoordinates s;
  s.unreproduced = static_cast<int>(h.unreproduced);
  s.cageVertices.resize(static_cast<std::size_t>(h.rows));
  s.restPositions.resize(h.rows, 3);
  in.read(reinterpret_cast<char*>(s.cageVertices.data()),
          static_cast<std::streamsize>(s.cageVertices.size() * sizeof(int)));
  in.read(reinterpret_cast<char*>(s.restPositions.data()),
          static_cast<std::streamsize>(s.restPositions.size() * sizeof(double)));
  std::uint32_t smallCrc = 0, matrixCrc = 0;
  if (!in.read(reinterpret_cast<char*>(&smallCrc), sizeof(smallCrc))) return fail("cut short");
  if (smallCrc != smallArraysCrc(s.cageVertices, s.restPositions)) return fail("damaged (CRC)");
  for (std::size_t i = 0; i < s.cageVertices.size(); ++i)
    if (s.cageVertices[i] < 0 || s.cageVertices[i] >= meshVertices ||
        (i > 0 && s.cageVertices[i] <= s.cageVertices[i - 1]))
      return fail("V_c is not a list of this mesh's vertices");
  if (!s.restPositions.allFinite()) return fail("damaged (positions not finite)");
  if (!s.coefficients.readFrom(in, h.rows, vertexCols, faceCols))
    return fail("cut short or damaged (coefficients)");
  if (!in.read(reinterpret_cast<char*>(&matrixCrc), sizeof(matrixCrc))) return fail("cut short");
  if (in.peek() != std::char_traits<char>::eof()) return fail("longer than its contents");
  if (matrixCrc != s.coefficients.checksum(threads)) return fail("damaged (CRC)");
  return s;
}

}  // namespace repose

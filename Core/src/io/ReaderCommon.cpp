// Reader helpers: type conversion with range checks, file checks, label map detection.
#include "ReaderCommon.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <unordered_set>

namespace repose::io {

const char* diskTypeName(DiskType t) {
  static const char* names[] = {"int8",   "uint8", "int16",  "uint16",  "int32",
                                "uint32", "int64", "uint64", "float32", "float64"};
  return names[static_cast<int>(t)];
}

std::size_t diskTypeSize(DiskType t) {
  static const std::size_t sizes[] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
  return sizes[static_cast<int>(t)];
}

ScalarType memoryTypeFor(DiskType t) {
  switch (t) {
    case DiskType::UInt8:
      return ScalarType::UInt8;
    case DiskType::Int8:
    case DiskType::Int16:
      return ScalarType::Int16;
    case DiskType::UInt16:
      return ScalarType::UInt16;
    case DiskType::Int32:
    case DiskType::UInt32:
    case DiskType::Int64:
    case DiskType::UInt64:
      return ScalarType::Int32;
    case DiskType::Float32:
    case DiskType::Float64:
      return ScalarType::Float32;
  }
  return ScalarType::Float32;
}

namespace {

template <class In, class Out>
void convertTyped(const In* in, Out* out, std::int64_t n, const std::string& path) {
  for (std::int64_t i = 0; i < n; ++i) {
    if constexpr (std::is_integral_v<Out> && std::is_integral_v<In>) {
      const auto v = in[i];
      const bool fits = std::is_signed_v<In>
                            ? static_cast<long double>(v) >= std::numeric_limits<Out>::min() &&
                                  static_cast<long double>(v) <= std::numeric_limits<Out>::max()
                            : static_cast<unsigned long long>(v) <=
                                  static_cast<unsigned long long>(std::numeric_limits<Out>::max());
      if (!fits)
        throw Error(path + ": voxel value " + std::to_string(v) + " does not fit in " +
                    scalarTypeName(scalarTypeOf<Out>()));
    }
    out[i] = static_cast<Out>(in[i]);
  }
}

template <class Out>
void convertFrom(DiskType from, const void* in, Out* out, std::int64_t n, const std::string& p) {
  switch (from) {
    case DiskType::Int8:
      return convertTyped(static_cast<const std::int8_t*>(in), out, n, p);
    case DiskType::UInt8:
      return convertTyped(static_cast<const std::uint8_t*>(in), out, n, p);
    case DiskType::Int16:
      return convertTyped(static_cast<const std::int16_t*>(in), out, n, p);
    case DiskType::UInt16:
      return convertTyped(static_cast<const std::uint16_t*>(in), out, n, p);
    case DiskType::Int32:
      return convertTyped(static_cast<const std::int32_t*>(in), out, n, p);
    case DiskType::UInt32:
      return convertTyped(static_cast<const std::uint32_t*>(in), out, n, p);
    case DiskType::Int64:
      return convertTyped(static_cast<const std::int64_t*>(in), out, n, p);
    case DiskType::UInt64:
      return convertTyped(static_cast<const std::uint64_t*>(in), out, n, p);
    case DiskType::Float32:
      return convertTyped(static_cast<const float*>(in), out, n, p);
    case DiskType::Float64:
      return convertTyped(static_cast<const double*>(in), out, n, p);
  }
}

}  // namespace

void convertVoxels(DiskType from, const void* in, ScalarType to, void* out, std::int64_t n,
                   const std::string& path) {
  dispatchScalar(to, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    convertFrom(from, in, static_cast<T*>(out), n, path);
  });
}

void checkReadMemory(const std::string& path, std::int64_t voxels, double bytesPerVoxel,
                     const ReadOptions& options) {
  const double need = double(voxels) * bytesPerVoxel;
  if (options.memoryLimitBytes <= 0 || need <= options.memoryLimitBytes) return;
  const auto size = [](double bytes) {
    std::ostringstream s;
    s.precision(3);
    if (bytes >= 1024.0 * 1024 * 1024)
      s << bytes / (1024.0 * 1024 * 1024) << " GiB";
    else
      s << bytes / (1024.0 * 1024) << " MiB";
    return s.str();
  };
  std::ostringstream m;
  m << "reading it needs " << size(need) << " (" << voxels << " voxels x " << bytesPerVoxel
    << " bytes), ";
  if (options.memoryLimitBytes <= 1)
    m << "but the memory budget is already used up (" << options.budgetHint << ")";
  else
    m << "more than the " << size(options.memoryLimitBytes) << " the memory budget leaves ("
      << options.budgetHint << ")";
  throwFileError(path, m.str());
}

void requireReadableFile(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throwFileError(path, "file not found");
  if (fs::is_directory(path, ec)) throwFileError(path, "is a folder, not a file");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throwFileError(path, std::string("cannot be opened: ") + std::strerror(errno));
  if (fs::file_size(path, ec) == 0) throwFileError(path, "file is empty");
}

bool looksLikeLabelMap(const Volume& volume) {
  if (!isIntegerType(volume.scalarType())) return false;
  if (!volume.labels().empty()) return true;
  return dispatchScalar(volume.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_floating_point_v<T>) {
      return false;
    } else {
      std::unordered_set<T> seen;
      for (int layer = 0; layer < volume.layers(); ++layer) {
        const T* v = volume.data<T>(layer);
        T last = 0;
        for (std::int64_t i = 0, n = volume.numVoxels(); i < n; ++i) {
          if (v[i] == last) continue;  // long runs are the common case in label maps
          last = v[i];
          if (v[i] < 0) return false;
          if (seen.insert(v[i]).second && seen.size() > 256) return false;
        }
      }
      return true;
    }
  });
}

}  // namespace repose::io

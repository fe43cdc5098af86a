// NRRD through teem, as Slicer does. Geometry comes from `space`, `space directions` and
// `space origin`, converted to RAS; a 4D .seg.nrrd with a leading list axis becomes layers.
#include "repose/io/NrrdIO.h"

#include "NrrdGzipData.h"
#include "repose/io/GzipPieces.h"
#include "NrrdHeaderCheck.h"
#include "NrrdLoad.h"
#include "ReaderCommon.h"
#include "SegNrrdFields.h"
#include "repose/io/AtomicOutput.h"

#include <teem/nrrd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

namespace repose {
namespace {

struct NrrdDeleter {
  void operator()(Nrrd* n) const {
    if (n) nrrdNuke(n);
  }
};
using NrrdPtr = std::unique_ptr<Nrrd, NrrdDeleter>;

// teem reports through biff as a multi-line stack; the deepest line says what went wrong.
std::string takeBiffMessage() {
  char* raw = biffGetDone(NRRD);
  std::string text = raw ? raw : "";
  std::free(raw);
  std::string best;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    // "[nrrd] _nrrdRead: problem" -> "problem"
    if (auto b = line.find("] "); b != std::string::npos) line = line.substr(b + 2);
    if (auto c = line.find(": "); c != std::string::npos && c < 40) line = line.substr(c + 2);
    if (!line.empty()) best = line;
  }
  return best.empty() ? "unreadable NRRD file" : best;
}

bool diskTypeFromNrrd(int type, io::DiskType& out) {
  switch (type) {
    case nrrdTypeChar:
      out = io::DiskType::Int8;
      return true;
    case nrrdTypeUChar:
      out = io::DiskType::UInt8;
      return true;
    case nrrdTypeShort:
      out = io::DiskType::Int16;
      return true;
    case nrrdTypeUShort:
      out = io::DiskType::UInt16;
      return true;
    case nrrdTypeInt:
      out = io::DiskType::Int32;
      return true;
    case nrrdTypeUInt:
      out = io::DiskType::UInt32;
      return true;
    case nrrdTypeLLong:
      out = io::DiskType::Int64;
      return true;
    case nrrdTypeULLong:
      out = io::DiskType::UInt64;
      return true;
    case nrrdTypeFloat:
      out = io::DiskType::Float32;
      return true;
    case nrrdTypeDouble:
      out = io::DiskType::Float64;
      return true;
    default:
      return false;
  }
}

int nrrdTypeFor(ScalarType t) {
  switch (t) {
    case ScalarType::UInt8:
      return nrrdTypeUChar;
    case ScalarType::UInt16:
      return nrrdTypeUShort;
    case ScalarType::Int16:
      return nrrdTypeShort;
    case ScalarType::Int32:
      return nrrdTypeInt;
    case ScalarType::Float32:
      return nrrdTypeFloat;
  }
  return nrrdTypeUChar;
}

bool hasDirection(const NrrdAxisInfo& axis, unsigned spaceDim) {
  return spaceDim > 0 && !std::isnan(axis.spaceDirection[0]);
}

// IJK -> RAS of the three domain axes (given by index), from whatever the header has.
Eigen::Matrix4d ijkToRasOf(const Nrrd& nrrd, const int axes[3], const std::string& path) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (nrrd.spaceDim == 0) {
    // No space: ITK and Slicer take per-axis spacing in LPS with identity directions.
    for (int a = 0; a < 3; ++a) {
      const double s = nrrd.axis[axes[a]].spacing;
      m(a, a) = std::isfinite(s) && s > 0 ? s : 1.0;
    }
    return flipLpsRas(m);
  }
  if (nrrd.spaceDim != 3)
    throwFileError(path, "space dimension " + std::to_string(nrrd.spaceDim) + " is not supported");
  for (int a = 0; a < 3; ++a)
    for (int r = 0; r < 3; ++r) m(r, a) = nrrd.axis[axes[a]].spaceDirection[r];
  for (int r = 0; r < 3; ++r) m(r, 3) = std::isnan(nrrd.spaceOrigin[r]) ? 0.0 : nrrd.spaceOrigin[r];
  switch (nrrd.space) {
    case nrrdSpaceRightAnteriorSuperior:
    case nrrdSpaceRightAnteriorSuperiorTime:
      return m;
    case nrrdSpaceLeftAnteriorSuperior:
    case nrrdSpaceLeftAnteriorSuperiorTime: {
      Eigen::Matrix4d f = Eigen::Matrix4d::Identity();
      f(0, 0) = -1;
      return f * m;
    }
    case nrrdSpaceLeftPosteriorSuperior:
    case nrrdSpaceLeftPosteriorSuperiorTime:
    case nrrdSpaceScannerXYZ:  // taken as LPS, like ITK
    case nrrdSpaceUnknown:     // "space dimension: 3" alone: LPS, like ITK
      return flipLpsRas(m);
    default:
      throwFileError(
          path, std::string("unsupported NRRD space '") + airEnumStr(nrrdSpace, nrrd.space) + "'");
  }
}

std::map<std::string, std::string> keyValues(const Nrrd& nrrd) {
  std::map<std::string, std::string> kv;
  for (unsigned i = 0; i < nrrdKeyValueSize(&nrrd); ++i) {
    char *key = nullptr, *value = nullptr;
    nrrdKeyValueIndex(&nrrd, &key, &value, i);
    if (key) kv[key] = value ? value : "";
    std::free(key);
    std::free(value);
  }
  return kv;
}

// The header's voxel count, refused above 2^40 voxels (also where the product of the sizes would
// overflow): no scanner or phantom comes near it, and teem would allocate a wrapped-around size.
std::int64_t checkedVoxelCount(const std::string& path, const Nrrd& nrrd) {
  constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 40;
  std::uint64_t voxels = 1;
  std::string sizes;
  bool tooMany = false;
  for (unsigned a = 0; a < nrrd.dim && a < NRRD_DIM_MAX; ++a) {
    const std::uint64_t n = nrrd.axis[a].size;
    sizes += (a ? " " : "") + std::to_string(n);
    if (n == 0 || n > kMaxVoxels / voxels)
      tooMany = tooMany || n != 0;
    else
      voxels *= n;
  }
  if (tooMany)
    throwFileError(path, "sizes " + sizes +
                             " hold more than 2^40 voxels: not a volume Repose can read (corrupt "
                             "header?)");
  return std::int64_t(voxels);
}

}  // namespace

Volume readNrrd(const std::string& path, const ReadOptions& options) {
  io::requireReadableFile(path);
  reportProgress(options.progress, 0.0, "reading");
  io::checkNrrdHeader(path);
  NrrdPtr nrrd(nrrdNew());
  {
    // teem allocates the voxels as it reads them, at the product of the header's sizes, which can
    // overflow (a fuzzed "sizes: 5555...554 4 4" asked malloc for 1.4e19 bytes): the header alone
    // first, for the voxel count (checked) and the memory estimate (teem's copy of the voxels,
    // then Repose's volume in its memory type).
    std::unique_ptr<NrrdIoState, NrrdIoState* (*)(NrrdIoState*)> nio(nrrdIoStateNew(),
                                                                     &nrrdIoStateNix);
    nio->skipData = AIR_TRUE;
    // The data file kept open at the data (the header file itself for attached data), so gzip
    // data can be inflated here rather than by teem (NrrdGzipData.h).
    nio->keepNrrdDataFileOpen = AIR_TRUE;
    // Closes the kept file however this block is left once the header was read. After a failed
    // load teem has closed what it opened (the pointer may be left dangling): not touched then.
    struct KeptFile {
      NrrdIoState* nio;
      bool loaded = false;
      ~KeptFile() {
        if (loaded && nio->dataFile) std::fclose(nio->dataFile);
        nio->dataFile = nullptr;
      }
    } kept{nio.get()};
    bool inflated = false;
    if (io::loadNrrd(nrrd.get(), path, nio.get()) != 0) {
      takeBiffMessage();  // a header teem cannot read is reported by the full read below
    } else {
      kept.loaded = true;
      const std::int64_t voxels = checkedVoxelCount(path, *nrrd);
      io::DiskType t;
      const double memBytes = diskTypeFromNrrd(nrrd->type, t)
                                  ? double(scalarSize(io::memoryTypeFor(t)))
                                  : double(nrrdElementSize(nrrd.get()));
      io::checkReadMemory(path, voxels, double(nrrdElementSize(nrrd.get())) + memBytes, options);
      // One data file, no skips, gzip: ours. Anything else (several data files, line or byte
      // skips, other encodings) stays with teem's full read below.
      const bool oneFile = !nio->dataFNArr || nio->dataFNArr->len <= 1;
      if (nio->encoding == nrrdEncodingGzip && nio->dataFile && oneFile && nio->lineSkip == 0 &&
          nio->byteSkip == 0 && !nio->dataFSkip && voxels > 0) {
        const std::size_t element = nrrdElementSize(nrrd.get());
        const bool swap =
            element > 1 && nio->endian != airEndianUnknown && nio->endian != airMyEndian();
        nrrd->data =
            io::readGzipVoxels(nio->dataFile, std::size_t(voxels) * element, element, swap, path);
        inflated = true;
      }
    }
    if (!inflated) nrrd.reset(nrrdNew());
  }
  std::unique_ptr<NrrdIoState, NrrdIoState* (*)(NrrdIoState*)> fullRead(nrrdIoStateNew(),
                                                                        &nrrdIoStateNix);
  if (!nrrd->data && io::loadNrrd(nrrd.get(), path, fullRead.get()) != 0) {
    std::string message = takeBiffMessage();
    if (message.find("fread got only") != std::string::npos ||
        message.find("but received") != std::string::npos)
      message = "voxel data is truncated or corrupt (" + message + ")";
    throwFileError(path, message);
  }

  io::DiskType diskType;
  if (!diskTypeFromNrrd(nrrd->type, diskType))
    throwFileError(path, std::string("unsupported voxel type ") + airEnumStr(nrrdType, nrrd->type));
  // Domain axes are those with a space direction; a 4D file may have one leading list axis.
  int axes[3];
  int layerAxis = -1;
  if (nrrd->dim == 3) {
    axes[0] = 0, axes[1] = 1, axes[2] = 2;
  } else if (nrrd->dim == 4 && !hasDirection(nrrd->axis[0], nrrd->spaceDim) && nrrd->spaceDim > 0) {
    layerAxis = 0;
    axes[0] = 1, axes[1] = 2, axes[2] = 3;
  } else if (nrrd->dim == 2) {
    throwFileError(path, "2D NRRD: a volume needs three dimensions");
  } else {
    throwFileError(path, std::to_string(nrrd->dim) +
                             "D NRRD is not supported (only 3D, or 4D segmentation layers)");
  }
  for (int a = 0; a < 3; ++a)
    if (nrrd->spaceDim > 0 && !hasDirection(nrrd->axis[axes[a]], nrrd->spaceDim))
      throwFileError(path, "axis " + std::to_string(axes[a]) + " has no space direction");

  VolumeGeometry geometry;
  for (int a = 0; a < 3; ++a)
    geometry.dims[a] = static_cast<std::int64_t>(nrrd->axis[axes[a]].size);
  geometry.ijkToRas = ijkToRasOf(*nrrd, axes, path);
  geometry.validate(path);
  const int layers = layerAxis < 0 ? 1 : static_cast<int>(nrrd->axis[layerAxis].size);
  if (layers < 1 || layers > 256)
    throwFileError(path, "implausible number of layers: " + std::to_string(layers));

  const ScalarType memType = io::memoryTypeFor(diskType);
  Volume volume(geometry, memType, layers);
  const std::int64_t n = geometry.numVoxels();
  const std::size_t inSize = io::diskTypeSize(diskType);
  if (layers == 1) {
    io::convertVoxels(diskType, nrrd->data, memType, volume.layerData(0), n, path);
  } else {
    // On disk the layer index runs fastest; in memory each layer is one contiguous volume.
    std::vector<std::uint8_t> planar(n * inSize);
    const auto* in = static_cast<const std::uint8_t*>(nrrd->data);
    for (int l = 0; l < layers; ++l) {
      for (std::int64_t v = 0; v < n; ++v)
        std::memcpy(&planar[v * inSize], in + (v * layers + l) * inSize, inSize);
      io::convertVoxels(diskType, planar.data(), memType, volume.layerData(l), n, path);
    }
  }

  const auto kv = keyValues(*nrrd);
  if (segnrrd::hasSegmentFields(kv)) {
    volume.labels() = segnrrd::parseSegments(kv, path);
    for (const Label& l : volume.labels().labels())
      if (l.layer >= layers)
        throwFileError(path, "segment '" + l.name + "' is on layer " + std::to_string(l.layer) +
                                 " but the file has " + std::to_string(layers));
    volume.setLabelMap(true);
  } else {
    volume.setLabelMap(layers > 1 || io::looksLikeLabelMap(volume));
  }
  reportProgress(options.progress, 1.0, "reading");
  return volume;
}

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// After nrrdSave failed. When writing a detached data file fails (a full disk), teem frees the
// data file's name on its error path but leaves it in the I/O state's list, which
// nrrdIoStateNix would free a second time (heap corruption: the .nhdr disk-full test). The
// list's elements are no longer freed by the list; the one name it holds is already freed.
[[noreturn]] void failedSave(NrrdIoState* nio, const std::string& path) {
  if (nio->dataFNArr) airArrayPointerCB(nio->dataFNArr, nullptr, nullptr);
  throwFileError(path, takeBiffMessage());
}

// teem writes the header (attached, or a detached .nhdr naming its data file); gzip data are
// written by Repose (writeGzipVoxels): teem's gzip writer kept its zlib stream when the write
// failed on a full disk.
void saveNrrd(Nrrd* nrrd, NrrdIoState* nio, const std::string& file, const std::string& path,
              bool gzip) {
  nio->encoding = gzip ? nrrdEncodingGzip : nrrdEncodingRaw;
  nio->skipData = gzip ? AIR_TRUE : AIR_FALSE;
  if (nrrdSave(file.c_str(), nrrd, nio) != 0) failedSave(nio, path);
  if (!gzip) return;
  std::string dataPath = file;
  if (nio->detachedHeader) {
    if (!nio->dataFNArr || nio->dataFNArr->len != 1 || !nio->dataFN[0])
      throwFileError(path, "teem named no data file for the detached header");
    const std::filesystem::path named(nio->dataFN[0]);
    dataPath = named.is_absolute() ? named.string()
                                   : (std::filesystem::path(file).parent_path() / named).string();
  }
  io::writeGzipVoxels(dataPath, !nio->detachedHeader, nrrd->data,
                      nrrdElementNumber(nrrd) * nrrdElementSize(nrrd), path);
}

}  // namespace

// A volume's header: `layers` (a list axis first when more than one) of `type` on `geometry`, in
// LPS. `data` is wrapped, not owned.
static void setVolumeHeader(Nrrd* nrrd, const VolumeGeometry& geometry, ScalarType type, int layers,
                            void* data, const std::string& path) {
  const auto& d = geometry.dims;
  size_t sizes[4];
  unsigned dim = 0;
  if (layers > 1) sizes[dim++] = static_cast<size_t>(layers);
  for (int a = 0; a < 3; ++a) sizes[dim++] = static_cast<size_t>(d[a]);
  if (nrrdWrap_nva(nrrd, data, nrrdTypeFor(type), dim, sizes) != 0)
    throwFileError(path, takeBiffMessage());
  nrrdSpaceSet(nrrd, nrrdSpaceLeftPosteriorSuperior);
  const Eigen::Matrix4d lps = flipLpsRas(geometry.ijkToRas);
  double dirs[4][NRRD_SPACE_DIM_MAX];
  int kinds[4];
  unsigned axis = 0;
  if (layers > 1) {
    for (int r = 0; r < NRRD_SPACE_DIM_MAX; ++r) dirs[axis][r] = AIR_NAN;
    kinds[axis++] = nrrdKindList;
  }
  for (int a = 0; a < 3; ++a, ++axis) {
    for (int r = 0; r < NRRD_SPACE_DIM_MAX; ++r) dirs[axis][r] = r < 3 ? lps(r, a) : AIR_NAN;
    kinds[axis] = nrrdKindDomain;
  }
  nrrdAxisInfoSet_nva(nrrd, nrrdAxisInfoSpaceDirection, dirs);
  nrrdAxisInfoSet_nva(nrrd, nrrdAxisInfoKind, kinds);
  const double origin[3] = {lps(0, 3), lps(1, 3), lps(2, 3)};
  nrrdSpaceOriginSet(nrrd, origin);
}

void writeNrrd(const Volume& volume, const std::string& path, const WriteOptions& options) {
  const bool segmentation = endsWith(path, ".seg.nrrd");
  if (segmentation && !isIntegerType(volume.scalarType()))
    throwFileError(path, "a segmentation needs integer labels, this volume is float32");
  if (volume.layers() > 1 && !segmentation)
    throwFileError(path, "a layered segmentation can only be written as .seg.nrrd");
  reportProgress(options.progress, 0.0, "writing");
  AtomicOutput output(path);

  const int layers = volume.layers();
  const std::int64_t n = volume.numVoxels();
  const std::size_t size = scalarSize(volume.scalarType());
  // teem wants the on-disk layout: for layers, interleave them (layer index fastest).
  std::vector<std::uint8_t> interleaved;
  void* data = const_cast<void*>(volume.layerData(0));
  if (layers > 1) {
    interleaved.resize(volume.byteSize());
    for (int l = 0; l < layers; ++l) {
      const auto* in = static_cast<const std::uint8_t*>(volume.layerData(l));
      for (std::int64_t v = 0; v < n; ++v)
        std::memcpy(&interleaved[(v * layers + l) * size], in + v * size, size);
    }
    data = interleaved.data();
  }

  // nrrdNix, not nrrdNuke: the voxels belong to the volume (or `interleaved`), not to teem.
  std::unique_ptr<Nrrd, Nrrd* (*)(Nrrd*)> nrrd(nrrdNew(), &nrrdNix);
  std::unique_ptr<NrrdIoState, NrrdIoState* (*)(NrrdIoState*)> nio(nrrdIoStateNew(),
                                                                   &nrrdIoStateNix);
  setVolumeHeader(nrrd.get(), volume.geometry(), volume.scalarType(), layers, data, path);
  if (segmentation)
    for (const auto& [key, value] : segnrrd::formatSegments(volume))
      nrrdKeyValueAdd(nrrd.get(), key.c_str(), value.c_str());

  saveNrrd(nrrd.get(), nio.get(), output.tempPath(), path, options.compress);
  output.commit();
  reportProgress(options.progress, 1.0, "writing");
}

// The field's header: a float vector image in LPS, with what 3D Slicer needs to open it as a
// transform. `data` is only wrapped (teem writes the header alone: skipData).
static void setFieldHeader(Nrrd* nrrd, const VolumeGeometry& grid, void* data,
                           const std::string& path) {
  size_t sizes[4] = {3, size_t(grid.dims[0]), size_t(grid.dims[1]), size_t(grid.dims[2])};
  if (nrrdWrap_nva(nrrd, data, nrrdTypeFloat, 4, sizes) != 0)
    throwFileError(path, takeBiffMessage());
  nrrdSpaceSet(nrrd, nrrdSpaceLeftPosteriorSuperior);
  const Eigen::Matrix4d m = flipLpsRas(grid.ijkToRas);
  double dirs[4][NRRD_SPACE_DIM_MAX];
  for (int r = 0; r < NRRD_SPACE_DIM_MAX; ++r) dirs[0][r] = AIR_NAN;
  for (int a = 0; a < 3; ++a)
    for (int r = 0; r < NRRD_SPACE_DIM_MAX; ++r) dirs[a + 1][r] = r < 3 ? m(r, a) : AIR_NAN;
  int kinds[4] = {nrrdKindVector, nrrdKindDomain, nrrdKindDomain, nrrdKindDomain};
  nrrdAxisInfoSet_nva(nrrd, nrrdAxisInfoSpaceDirection, dirs);
  nrrdAxisInfoSet_nva(nrrd, nrrdAxisInfoKind, kinds);
  const double origin[3] = {m(0, 3), m(1, 3), m(2, 3)};
  nrrdSpaceOriginSet(nrrd, origin);
  // What 3D Slicer needs to open it as a transform: qSlicerTransformsReader.cxx takes a 3D vector
  // image as a transform only with intent_code 1006 (NIfTI's displacement vector; else the
  // volumes reader wins and it opens as a vector volume); vtkMRMLTransformStorageNode.cxx reads
  // "displacement field type" resampling as a transform from parent (output -> input, as here,
  // never inverted) and refuses a measurement frame other than the identity.
  if (nrrdKeyValueAdd(nrrd, "intent_code", "1006") != 0 ||
      nrrdKeyValueAdd(nrrd, "displacement field type", "resampling") != 0)
    throwFileError(path, takeBiffMessage());
  for (int r = 0; r < NRRD_SPACE_DIM_MAX; ++r)
    for (int c = 0; c < NRRD_SPACE_DIM_MAX; ++c)
      nrrd->measurementFrame[r][c] = r < 3 && c < 3 ? (r == c ? 1.0 : 0.0) : AIR_NAN;
}

struct DisplacementFieldNrrdWriter::Impl {
  VolumeGeometry grid;
  std::string path;
  AtomicOutput output;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file{nullptr, &std::fclose};
  std::unique_ptr<GzipPieceStream> stream;
  std::int64_t written = 0;  // slices
  std::vector<float> lps;
  Impl(const VolumeGeometry& g, const std::string& p) : grid(g), path(p), output(p) {}
};

DisplacementFieldNrrdWriter::DisplacementFieldNrrdWriter(const VolumeGeometry& grid,
                                                         const std::string& path) {
  grid.validate(path);
  impl_ = std::make_unique<Impl>(grid, path);
  std::unique_ptr<Nrrd, Nrrd* (*)(Nrrd*)> nrrd(nrrdNew(), &nrrdNix);
  std::unique_ptr<NrrdIoState, NrrdIoState* (*)(NrrdIoState*)> nio(nrrdIoStateNew(),
                                                                   &nrrdIoStateNix);
  float unused = 0;
  setFieldHeader(nrrd.get(), grid, &unused, path);
  nio->encoding = nrrdEncodingGzip;
  nio->skipData = AIR_TRUE;
  const std::string& temp = impl_->output.tempPath();
  if (nrrdSave(temp.c_str(), nrrd.get(), nio.get()) != 0) failedSave(nio.get(), path);
  impl_->file.reset(std::fopen(temp.c_str(), "ab"));
  if (!impl_->file) throwFileError(path, "cannot create the output file");
  impl_->stream = std::make_unique<GzipPieceStream>(impl_->file.get(), path);
}

DisplacementFieldNrrdWriter::~DisplacementFieldNrrdWriter() = default;

void DisplacementFieldNrrdWriter::writeSlices(const float* rasVectors, std::int64_t slices) {
  Impl& r = *impl_;
  if (slices <= 0 || r.written + slices > r.grid.dims[2])
    throwFileError(r.path, "more slices of the displacement field than its grid holds");
  const std::size_t n = std::size_t(3 * r.grid.dims[0] * r.grid.dims[1] * slices);
  r.lps.assign(rasVectors, rasVectors + n);
  for (std::size_t v = 0; v < n; v += 3) r.lps[v] = -r.lps[v], r.lps[v + 1] = -r.lps[v + 1];
  r.stream->write(r.lps.data(), n * sizeof(float));
  r.written += slices;
}

void DisplacementFieldNrrdWriter::finish() {
  Impl& r = *impl_;
  if (r.written != r.grid.dims[2])
    throwFileError(r.path, "the displacement field ends after " + std::to_string(r.written) +
                               " of its " + std::to_string(r.grid.dims[2]) + " slices");
  r.stream->finish();
  if (std::fflush(r.file.get()) != 0) throwFileError(r.path, "write failed (disk full?)");
  if (std::fclose(r.file.release()) != 0) throwFileError(r.path, "write failed (disk full?)");
  r.lps.clear(), r.lps.shrink_to_fit();
  r.output.commit();
}

struct SegNrrdSlabWriter::Impl {
  std::string path;
  VolumeGeometry geometry;
  ScalarType type;
  int layers;
  LabelTable labels;
  AtomicOutput output;
  std::string dataPath;  // the voxels' gzip pieces, beside the header being made
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file{nullptr, &std::fclose};
  std::unique_ptr<GzipPieceStream> stream;
  std::vector<segnrrd::Extents> extents;
  std::vector<std::uint8_t> interleaved;
  std::int64_t written = 0;
  Impl(const std::string& p, const VolumeGeometry& g, ScalarType t, int l, const LabelTable& table)
      : path(p), geometry(g), type(t), layers(l), labels(table), output(p) {}
};

SegNrrdSlabWriter::SegNrrdSlabWriter(const std::string& path, const VolumeGeometry& geometry,
                                     ScalarType type, int layers, const LabelTable& labels) {
  geometry.validate(path);
  if (!isIntegerType(type))
    throwFileError(path, "a segmentation needs integer labels, this volume is float32");
  if (layers < 1) throwFileError(path, "a segmentation of no layer");
  impl_ = std::make_unique<Impl>(path, geometry, type, layers, labels);
  impl_->extents.resize(std::size_t(layers));
  impl_->dataPath = impl_->output.tempPath() + ".voxels";
  impl_->file.reset(std::fopen(impl_->dataPath.c_str(), "wb"));
  if (!impl_->file) throwFileError(path, "cannot create the output file");
  impl_->stream = std::make_unique<GzipPieceStream>(impl_->file.get(), path);
}

SegNrrdSlabWriter::~SegNrrdSlabWriter() {
  if (impl_ && !impl_->dataPath.empty()) std::remove(impl_->dataPath.c_str());
}

void SegNrrdSlabWriter::writeSlices(const void* data, std::int64_t slices) {
  Impl& r = *impl_;
  const auto& d = r.geometry.dims;
  if (slices <= 0 || r.written + slices > d[2])
    throwFileError(r.path, "more slices than the segmentation's grid holds");
  const std::size_t size = scalarSize(r.type);
  const std::int64_t n = d[0] * d[1] * slices;
  const auto* in = static_cast<const std::uint8_t*>(data);
  for (int l = 0; l < r.layers; ++l)
    segnrrd::addExtents(in + std::size_t(l * n) * size, r.type, d, r.written, r.written + slices,
                        r.extents[std::size_t(l)]);
  if (r.layers == 1) {
    r.stream->write(data, std::size_t(n) * size);
  } else {
    // The file's layout: the layer index fastest.
    r.interleaved.resize(std::size_t(n * r.layers) * size);
    for (int l = 0; l < r.layers; ++l)
      for (std::int64_t v = 0; v < n; ++v)
        std::memcpy(&r.interleaved[std::size_t(v * r.layers + l) * size],
                    in + std::size_t(l * n + v) * size, size);
    r.stream->write(r.interleaved.data(), r.interleaved.size());
  }
  r.written += slices;
}

void SegNrrdSlabWriter::finish() {
  Impl& r = *impl_;
  if (r.written != r.geometry.dims[2])
    throwFileError(r.path, "the segmentation ends after " + std::to_string(r.written) + " of its " +
                               std::to_string(r.geometry.dims[2]) + " slices");
  r.stream->finish();
  if (std::fflush(r.file.get()) != 0 || std::fclose(r.file.release()) != 0)
    throwFileError(r.path, "write failed (disk full?)");
  // The header, now that the segments' extents are known, then the voxels after it.
  std::unique_ptr<Nrrd, Nrrd* (*)(Nrrd*)> nrrd(nrrdNew(), &nrrdNix);
  std::unique_ptr<NrrdIoState, NrrdIoState* (*)(NrrdIoState*)> nio(nrrdIoStateNew(),
                                                                   &nrrdIoStateNix);
  std::uint8_t unused = 0;
  setVolumeHeader(nrrd.get(), r.geometry, r.type, r.layers, &unused, r.path);
  for (const auto& [key, value] :
       segnrrd::formatSegments(r.geometry, r.layers, r.labels, r.extents))
    nrrdKeyValueAdd(nrrd.get(), key.c_str(), value.c_str());
  nio->encoding = nrrdEncodingGzip;
  nio->skipData = AIR_TRUE;
  const std::string& temp = r.output.tempPath();
  if (nrrdSave(temp.c_str(), nrrd.get(), nio.get()) != 0) failedSave(nio.get(), r.path);
  {
    std::ifstream in(r.dataPath, std::ios::binary);
    std::ofstream out(temp, std::ios::binary | std::ios::app);
    out << in.rdbuf();
    out.flush();
    if (!in || !out) throwFileError(r.path, "write failed (disk full?)");
  }
  std::remove(r.dataPath.c_str());
  r.dataPath.clear();
  r.interleaved.clear(), r.interleaved.shrink_to_fit();
  r.output.commit();
}

void writeDisplacementFieldNrrd(const std::vector<float>& rasVectors, const VolumeGeometry& grid,
                                const std::string& path) {
  grid.validate(path);
  if (rasVectors.size() != static_cast<std::size_t>(3 * grid.numVoxels()))
    throwFileError(path, "the displacement field does not match its grid");
  // Written in slabs of about 64 MiB (one writer for both: the same bytes either way), so the
  // LPS copy stays small beside the field.
  DisplacementFieldNrrdWriter writer(grid, path);
  const std::int64_t plane = grid.dims[0] * grid.dims[1];
  const std::int64_t slab = std::max<std::int64_t>(1, (std::int64_t(64) << 20) / (12 * plane));
  for (std::int64_t k0 = 0; k0 < grid.dims[2]; k0 += slab)
    writer.writeSlices(rasVectors.data() + 3 * k0 * plane, std::min(slab, grid.dims[2] - k0));
  writer.finish();
}

}  // namespace repose

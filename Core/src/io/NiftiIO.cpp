// NIfTI-1/2 reading and writing with niftilib (libnifti2 reads both versions). Geometry: sform
// if set, else qform, else pixdim (NIfTI "method 1"); all three are RAS, so no flip is needed.
#include "repose/io/NiftiIO.h"

#include "NiftiLabelExtension.h"
#include "ReaderCommon.h"
#include "repose/io/AtomicOutput.h"
#include "repose/io/GzipPieces.h"
#include "repose/util/Parallel.h"

#include <nifti2_io.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>

namespace repose {
namespace {

struct NiftiImageDeleter {
  void operator()(nifti_image* nim) const {
    if (nim) nifti_image_free(nim);
  }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiImageDeleter>;

constexpr int kIntentLabel = 1002;  // NIFTI_INTENT_LABEL

// niftilib prints its own diagnostics at debug level >= 1; we report one line ourselves.
void quietNiftilib() {
  nifti_set_debug_level(getenv("REPOSE_NIFTI_DEBUG") ? 3 : 0);
}

bool diskTypeFromNifti(int datatype, io::DiskType& out) {
  switch (datatype) {
    case DT_INT8:
      out = io::DiskType::Int8;
      return true;
    case DT_UINT8:
      out = io::DiskType::UInt8;
      return true;
    case DT_INT16:
      out = io::DiskType::Int16;
      return true;
    case DT_UINT16:
      out = io::DiskType::UInt16;
      return true;
    case DT_INT32:
      out = io::DiskType::Int32;
      return true;
    case DT_UINT32:
      out = io::DiskType::UInt32;
      return true;
    case DT_INT64:
      out = io::DiskType::Int64;
      return true;
    case DT_UINT64:
      out = io::DiskType::UInt64;
      return true;
    case DT_FLOAT32:
      out = io::DiskType::Float32;
      return true;
    case DT_FLOAT64:
      out = io::DiskType::Float64;
      return true;
    default:
      return false;
  }
}

int niftiTypeFor(ScalarType t) {
  switch (t) {
    case ScalarType::UInt8:
      return DT_UINT8;
    case ScalarType::UInt16:
      return DT_UINT16;
    case ScalarType::Int16:
      return DT_INT16;
    case ScalarType::Int32:
      return DT_INT32;
    case ScalarType::Float32:
      return DT_FLOAT32;
  }
  return DT_UINT8;
}

Eigen::Matrix4d toEigen(const nifti_dmat44& m) {
  Eigen::Matrix4d e;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) e(r, c) = m.m[r][c];
  return e;
}

nifti_dmat44 toNifti(const Eigen::Matrix4d& e) {
  nifti_dmat44 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m.m[r][c] = e(r, c);
  return m;
}

VolumeGeometry geometryOf(const nifti_image& nim, const std::string& path) {
  VolumeGeometry g;
  g.dims = {nim.nx, nim.ny, nim.nz};
  if (nim.sform_code > 0) {
    g.ijkToRas = toEigen(nim.sto_xyz);
  } else if (nim.qform_code > 0) {
    g.ijkToRas = toEigen(nim.qto_xyz);
  } else {
    g.ijkToRas.setIdentity();
    const double d[3] = {nim.dx, nim.dy, nim.dz};
    for (int a = 0; a < 3; ++a) g.ijkToRas(a, a) = d[a] > 0 ? d[a] : 1.0;
  }
  g.validate(path);
  return g;
}

// niftilib looks for "X.nii" before "X.nii.gz" whatever name it is given, so with both present
// it would read the other file. Then we hand it the file through a private symlink instead.
class UnambiguousNiftiPath {
 public:
  explicit UnambiguousNiftiPath(const std::string& path) : path_(path) {
    namespace fs = std::filesystem;
    const std::string lower = fs::path(path).filename().string();
    if (lower.size() < 7 || lower.compare(lower.size() - 7, 7, ".nii.gz") != 0) return;
    std::error_code ec;
    if (!fs::exists(path.substr(0, path.size() - 3), ec)) return;
    std::string pattern = (fs::temp_directory_path() / "repose-nii-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) return;
    dir_ = pattern;
    const fs::path link = fs::path(dir_) / "volume.nii.gz";
    fs::create_symlink(fs::absolute(path), link, ec);
    if (!ec) path_ = link.string();
  }
  ~UnambiguousNiftiPath() {
    std::error_code ec;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_, dir_;
};

// Header, geometry and label table of a NIfTI file, checked before any voxel is read.
NiftiPtr readHeader(const std::string& path, const std::string& libraryPath) {
  io::requireReadableFile(path);
  quietNiftilib();
  NiftiPtr nim(nifti_image_read(libraryPath.c_str(), 0));
  if (!nim)
    throwFileError(path, "not a readable NIfTI file (header missing, truncated or corrupt)");
  if (nim->nifti_type == NIFTI_FTYPE_ANALYZE)
    throwFileError(path, "is an ANALYZE 7.5 file without orientation; convert it to NIfTI");
  // niftilib takes vox_offset as it comes; a negative one made the truncation check below pass
  // and a 350-byte file allocate 2 GB (found by Testing/Fuzz/FuzzNifti).
  if (nim->iname_offset < 0)
    throwFileError(
        path, "invalid voxel data offset (vox_offset " + std::to_string(nim->iname_offset) + ")");
  for (int d = 4; d <= 7; ++d)
    if (nim->dim[0] >= d && nim->dim[d] > 1)
      throwFileError(path, std::to_string(nim->dim[0]) + "D NIfTI (dim" + std::to_string(d) +
                               " = " + std::to_string(nim->dim[d]) +
                               ") is not supported: give one 3D volume");
  return nim;
}

// The file's voxel type, refused with the file's name when Repose cannot read it.
io::DiskType checkedDiskType(const nifti_image& nim, const std::string& path) {
  io::DiskType diskType;
  if (!diskTypeFromNifti(nim.datatype, diskType))
    throwFileError(path,
                   std::string("unsupported voxel type ") + nifti_datatype_to_string(nim.datatype));
  if (static_cast<std::size_t>(nim.nbyper) != io::diskTypeSize(diskType))
    throwFileError(path, "inconsistent bytes per voxel in header");
  return diskType;
}

}  // namespace

Volume readNifti(const std::string& path, const ReadOptions& options) {
  const UnambiguousNiftiPath alias(path);
  NiftiPtr nim = readHeader(path, alias.path());
  const io::DiskType diskType = checkedDiskType(*nim, path);
  const VolumeGeometry geometry = geometryOf(*nim, path);

  // An uncompressed file must hold all its voxels; say so before reading anything.
  const std::int64_t dataBytes = nim->nvox * nim->nbyper;
  if (!nifti_is_gzfile(nim->iname)) {
    const std::int64_t size = nifti_get_filesize(nim->iname);
    if (size < nim->iname_offset + dataBytes)
      throwFileError(path, "file is truncated: header announces " + std::to_string(dataBytes) +
                               " bytes of voxels after offset " +
                               std::to_string(nim->iname_offset) + ", the file has " +
                               std::to_string(size) + " bytes");
  }

  reportProgress(options.progress, 0.0, "reading");
  const bool scaled = nim->scl_slope != 0.0 && (nim->scl_slope != 1.0 || nim->scl_inter != 0.0);
  const ScalarType memType = scaled ? ScalarType::Float32 : io::memoryTypeFor(diskType);
  const bool direct = !scaled && scalarSize(memType) == io::diskTypeSize(diskType) &&
                      io::memoryTypeFor(diskType) == memType && diskType != io::DiskType::UInt32 &&
                      diskType != io::DiskType::Int8;
  io::checkReadMemory(path, nim->nvox,
                      double(scalarSize(memType)) + (direct ? 0.0 : double(nim->nbyper)), options);
  Volume volume(geometry, memType);
  // Straight into the volume when no conversion is needed, else into a staging buffer.
  std::vector<std::uint8_t> staging;
  if (direct) {
    nim->data = volume.layerData(0);
  } else {
    staging.resize(static_cast<std::size_t>(dataBytes));
    nim->data = staging.data();
  }
  // Read with niftilib's buffer reader, not nifti_image_load: on a short read that one calls
  // free() on nim->data, which is our (operator new) buffer (found by Testing/Fuzz/FuzzNifti).
  void* const target = nim->data;
  nim->data = nullptr;  // niftilib never owns our buffers
  znzFile fp = znzopen(nim->iname, "rb", nifti_is_gzfile(nim->iname));
  if (znz_isnull(fp)) throwFileError(path, "cannot open the voxel data");
  // fseek returns 0, gzseek the new offset; both -1 on failure.
  const bool positioned = znzseek(fp, static_cast<znz_off_t>(nim->iname_offset), SEEK_SET) >= 0;
  const int64_t got = positioned ? nifti_read_buffer(fp, target, dataBytes, nim.get()) : -1;
  znzclose(fp);
  if (got != static_cast<int64_t>(dataBytes))
    throwFileError(path, "cannot read the voxel data (truncated or corrupt file)");
  if (!direct) {
    if (scaled) {
      std::vector<float> tmp(static_cast<std::size_t>(nim->nvox));
      io::convertVoxels(diskType, staging.data(), ScalarType::Float32, tmp.data(), nim->nvox, path);
      float* out = volume.data<float>();
      for (std::int64_t i = 0; i < nim->nvox; ++i)
        out[i] = static_cast<float>(tmp[i] * nim->scl_slope + nim->scl_inter);
    } else {
      io::convertVoxels(diskType, staging.data(), memType, volume.layerData(0), nim->nvox, path);
    }
  }

  for (int e = 0; e < nim->num_ext; ++e) {
    const nifti1_extension& ext = nim->ext_list[e];
    if (ext.edata && ext.esize > 8) {
      const std::string text(ext.edata, strnlen(ext.edata, ext.esize - 8));
      if (text.find("LabelTable") != std::string::npos) {
        const LabelTable labels = nifti::parseCaretLabelTable(text);
        for (const Label& l : labels.labels()) volume.labels().set(l);
      }
    }
  }
  volume.setLabelMap(nim->intent_code == kIntentLabel || io::looksLikeLabelMap(volume));
  reportProgress(options.progress, 1.0, "reading");
  return volume;
}

NiftiLayout readNiftiLayout(const std::string& path) {
  const UnambiguousNiftiPath alias(path);
  NiftiPtr nim = readHeader(path, alias.path());
  const io::DiskType diskType = checkedDiskType(*nim, path);
  const bool scaled = nim->scl_slope != 0.0 && (nim->scl_slope != 1.0 || nim->scl_inter != 0.0);
  const ScalarType memType = io::memoryTypeFor(diskType);
  if (scaled || scalarSize(memType) != io::diskTypeSize(diskType) ||
      diskType == io::DiskType::UInt32 || diskType == io::DiskType::Int8)
    throwFileError(path,
                   "voxels are scaled or of a type read by conversion; convert the file "
                   "(repose convert) before posing it out of core");
  NiftiLayout layout;
  layout.geometry = geometryOf(*nim, path);
  layout.type = memType;
  layout.dataOffset = nim->iname_offset;
  layout.gzip = nifti_is_gzfile(nim->iname) != 0;
  for (int e = 0; e < nim->num_ext; ++e) {
    const nifti1_extension& ext = nim->ext_list[e];
    if (ext.edata && ext.esize > 8) {
      const std::string text(ext.edata, strnlen(ext.edata, ext.esize - 8));
      if (text.find("LabelTable") != std::string::npos)
        layout.labels = nifti::parseCaretLabelTable(text);
    }
  }
  layout.labelMap =
      nim->intent_code == kIntentLabel || !layout.labels.empty() || isIntegerType(memType);
  return layout;
}

namespace {

// A nifti_image describing `geometry` (no data), ready for niftilib's header writer.
NiftiPtr makeHeader(const std::string& tempPath, const VolumeGeometry& geometry, ScalarType type,
                    const LabelTable& labels, bool labelMap, int niftiVersion) {
  quietNiftilib();
  if (niftiVersion != 1 && niftiVersion != 2)
    throw Error("NIfTI version must be 1 or 2, not " + std::to_string(niftiVersion));
  for (auto d : geometry.dims)
    if (d > 32767) niftiVersion = 2;  // NIfTI-1 stores dims as 16-bit
  const std::int64_t dims[8] = {3, geometry.dims[0], geometry.dims[1], geometry.dims[2], 1, 1, 1,
                                1};
  NiftiPtr nim(nifti_make_new_nim(dims, niftiTypeFor(type), 0));
  if (!nim) throw Error(tempPath + ": cannot create a NIfTI header");
  const Eigen::Vector3d spacing = geometry.spacing();
  nim->dx = nim->pixdim[1] = spacing[0];
  nim->dy = nim->pixdim[2] = spacing[1];
  nim->dz = nim->pixdim[3] = spacing[2];
  nim->xyz_units = NIFTI_UNITS_MM;
  // Both codes set: sform keeps the exact matrix (shear included), qform its rigid part.
  nim->sform_code = NIFTI_XFORM_SCANNER_ANAT;
  nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
  nim->sto_xyz = toNifti(geometry.ijkToRas);
  nim->sto_ijk = nifti_dmat44_inverse(nim->sto_xyz);
  nifti_dmat44_to_quatern(nim->sto_xyz, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d,
                          &nim->qoffset_x, &nim->qoffset_y, &nim->qoffset_z, nullptr, nullptr,
                          nullptr, &nim->qfac);
  nim->qto_xyz =
      nifti_quatern_to_dmat44(nim->quatern_b, nim->quatern_c, nim->quatern_d, nim->qoffset_x,
                              nim->qoffset_y, nim->qoffset_z, nim->dx, nim->dy, nim->dz, nim->qfac);
  nim->qto_ijk = nifti_dmat44_inverse(nim->qto_xyz);
  if (labelMap) {
    nim->intent_code = kIntentLabel;
    std::strncpy(nim->intent_name, "Label", sizeof(nim->intent_name) - 1);
    if (!labels.empty()) {
      const std::string xml = nifti::formatCaretLabelTable(labels);
      nifti_add_extension(nim.get(), xml.c_str(), static_cast<int>(xml.size() + 1), 0);
    }
  }
  std::strncpy(nim->descrip, "Repose", sizeof(nim->descrip) - 1);
  if (nifti_set_filenames(nim.get(), tempPath.c_str(), 0, 1) != 0)
    throw Error(tempPath + ": not a NIfTI file name (.nii or .nii.gz)");
  // After nifti_set_filenames, which resets the type from the file name.
  nim->nifti_type = niftiVersion == 2 ? NIFTI_FTYPE_NIFTI2_1 : NIFTI_FTYPE_NIFTI1_1;
  return nim;
}

// Header, extender and extensions as bytes, padded to the voxel offset. niftilib fills the header
// struct; we write the bytes ourselves because libnifti2 3.0.1's single-file NIfTI-2 writer puts
// the voxels over the header.
std::vector<char> headerBytes(const nifti_image& nim) {
  std::int64_t offset = (nim.nifti_type == NIFTI_FTYPE_NIFTI2_1 ? 540 : 348) + 4;
  for (int e = 0; e < nim.num_ext; ++e) offset += nim.ext_list[e].esize;
  offset = (offset + 15) / 16 * 16;
  std::vector<char> bytes;
  if (nim.nifti_type == NIFTI_FTYPE_NIFTI2_1) {
    nifti_2_header h;
    nifti_convert_nim2n2hdr(&nim, &h);
    h.vox_offset = offset;
    std::memcpy(h.magic, "n+2\0\r\n\032\n", 8);
    bytes.assign(reinterpret_cast<const char*>(&h), reinterpret_cast<const char*>(&h) + sizeof(h));
  } else {
    nifti_1_header h;
    nifti_convert_nim2n1hdr(&nim, &h);
    h.vox_offset = static_cast<float>(offset);
    std::memcpy(h.magic, "n+1\0", 4);
    bytes.assign(reinterpret_cast<const char*>(&h), reinterpret_cast<const char*>(&h) + sizeof(h));
  }
  const char extender[4] = {static_cast<char>(nim.num_ext > 0 ? 1 : 0), 0, 0, 0};
  bytes.insert(bytes.end(), extender, extender + 4);
  for (int e = 0; e < nim.num_ext; ++e) {
    const nifti1_extension& ext = nim.ext_list[e];
    const std::int32_t head[2] = {ext.esize, ext.ecode};
    bytes.insert(bytes.end(), reinterpret_cast<const char*>(head),
                 reinterpret_cast<const char*>(head) + 8);
    const std::size_t start = bytes.size();
    bytes.resize(start + ext.esize - 8, 0);
    std::memcpy(&bytes[start], ext.edata, ext.esize - 8);
  }
  bytes.resize(static_cast<std::size_t>(offset), 0);
  return bytes;
}

}  // namespace

std::vector<char> niftiHeaderBytes(const VolumeGeometry& geometry, ScalarType type,
                                   const LabelTable& labels, bool labelMap, int niftiVersion) {
  geometry.validate("NIfTI header");
  return headerBytes(*makeHeader("header.nii", geometry, type, labels, labelMap, niftiVersion));
}

std::int64_t niftiGzipPieceSlices(const VolumeGeometry& geometry, ScalarType type) {
  const std::int64_t sliceBytes =
      geometry.dims[0] * geometry.dims[1] * static_cast<std::int64_t>(scalarSize(type));
  return std::max<std::int64_t>(1, kNiftiGzipPieceBytes / std::max<std::int64_t>(1, sliceBytes));
}

struct NiftiSlabWriter::Impl {
  AtomicOutput output;
  std::FILE* file = nullptr;
  bool gz = false;
  std::int64_t sliceBytes = 0, slicesWritten = 0, slicesTotal = 0;
  // .nii.gz: the voxels go in pieces of pieceSlices whole slices (GzipPieces.h); `pending` holds
  // the slices of an unfinished piece, crc and rawBytes what the trailer needs.
  std::int64_t pieceSlices = 1;
  std::vector<char> pending;
  std::uint32_t crc = 0;
  std::uint64_t rawBytes = 0;
  explicit Impl(const std::string& path) : output(path) {}
  ~Impl() {
    if (file) std::fclose(file);
  }
  void put(const void* bytes, std::size_t n) {
    if (n > 0 && std::fwrite(bytes, 1, n, file) != n)
      throwFileError(output.finalPath(), "write failed (disk full?)");
  }
  // Whole pieces compressed in parallel (the pieces are independent), written in order.
  void putPieces(const char* bytes, std::int64_t pieces, std::int64_t pieceBytes) {
    std::vector<std::string> packed(static_cast<std::size_t>(pieces));
    parallelFor(
        pieces, 0,
        [&](std::int64_t p0, std::int64_t p1) {
          for (std::int64_t p = p0; p < p1; ++p)
            packed[std::size_t(p)] =
                deflatePiece(bytes + p * pieceBytes, static_cast<std::size_t>(pieceBytes));
        },
        1);
    for (std::int64_t p = 0; p < pieces; ++p) {
      crc = crc32Concat(crc, crc32Of(bytes + p * pieceBytes, std::size_t(pieceBytes)),
                        std::uint64_t(pieceBytes));
      put(packed[std::size_t(p)].data(), packed[std::size_t(p)].size());
    }
    rawBytes += std::uint64_t(pieces * pieceBytes);
  }
};

NiftiSlabWriter::NiftiSlabWriter(const std::string& path, const VolumeGeometry& geometry,
                                 ScalarType type, const LabelTable& labels, bool labelMap,
                                 int niftiVersion)
    : impl_(std::make_unique<Impl>(path)) {
  geometry.validate(path);
  const std::string& temp = impl_->output.tempPath();
  const NiftiPtr nim = makeHeader(temp, geometry, type, labels, labelMap, niftiVersion);
  impl_->sliceBytes =
      geometry.dims[0] * geometry.dims[1] * static_cast<std::int64_t>(scalarSize(type));
  impl_->slicesTotal = geometry.dims[2];
  impl_->gz = temp.size() > 3 && temp.compare(temp.size() - 3, 3, ".gz") == 0;
  impl_->pieceSlices = niftiGzipPieceSlices(geometry, type);
  impl_->file = std::fopen(temp.c_str(), "wb");
  if (!impl_->file) throwFileError(path, "cannot create the output file");
  const std::vector<char> header = headerBytes(*nim);
  if (impl_->gz) {
    // The header is a piece of its own, so the voxels' pieces start at slice 0.
    const std::string head = gzipHeaderBytes() + deflatePiece(header.data(), header.size());
    impl_->put(head.data(), head.size());
    impl_->crc = crc32Of(header.data(), header.size());
    impl_->rawBytes = header.size();
  } else {
    impl_->put(header.data(), header.size());
  }
}

NiftiSlabWriter::~NiftiSlabWriter() = default;

void NiftiSlabWriter::writeSlices(const void* data, std::int64_t slices) {
  Impl& w = *impl_;
  if (!w.file) throw Error(w.output.finalPath() + ": writer already finished");
  if (w.slicesWritten + slices > w.slicesTotal)
    throw Error(w.output.finalPath() + ": more slices written than the volume has");
  const auto* bytes = static_cast<const char*>(data);
  w.slicesWritten += slices;
  if (!w.gz) {
    w.put(bytes, static_cast<std::size_t>(slices * w.sliceBytes));
    return;
  }
  const std::int64_t pieceBytes = w.pieceSlices * w.sliceBytes;
  std::int64_t left = slices * w.sliceBytes;
  if (!w.pending.empty()) {  // complete the piece begun by the previous call
    const std::int64_t n =
        std::min<std::int64_t>(left, pieceBytes - static_cast<std::int64_t>(w.pending.size()));
    w.pending.insert(w.pending.end(), bytes, bytes + n);
    bytes += n;
    left -= n;
    if (static_cast<std::int64_t>(w.pending.size()) < pieceBytes) return;
    w.putPieces(w.pending.data(), 1, pieceBytes);
    w.pending.clear();
  }
  // Whole pieces straight from the caller's slab, 16 at a time (bounded extra memory).
  for (std::int64_t whole = left / pieceBytes; whole > 0;) {
    const std::int64_t n = std::min<std::int64_t>(whole, 16);
    w.putPieces(bytes, n, pieceBytes);
    bytes += n * pieceBytes;
    left -= n * pieceBytes;
    whole -= n;
  }
  w.pending.assign(bytes, bytes + left);
}

void NiftiSlabWriter::finish() {
  Impl& w = *impl_;
  if (w.slicesWritten != w.slicesTotal)
    throw Error(w.output.finalPath() + ": only " + std::to_string(w.slicesWritten) + " of " +
                std::to_string(w.slicesTotal) + " slices were written");
  if (w.gz) {
    if (!w.pending.empty()) {  // the last piece, shorter than the others
      w.putPieces(w.pending.data(), 1, static_cast<std::int64_t>(w.pending.size()));
      w.pending.clear();
    }
    const std::string tail = gzipTrailerBytes(w.crc, w.rawBytes);
    w.put(tail.data(), tail.size());
  }
  const int rc = std::fclose(w.file);
  w.file = nullptr;
  if (rc != 0) throwFileError(w.output.finalPath(), "closing the file failed (disk full?)");
  w.output.commit();
}

void writeNifti(const Volume& volume, const std::string& path, const WriteOptions& options) {
  if (volume.layers() != 1)
    throwFileError(path, "a NIfTI file holds one layer; this segmentation has " +
                             std::to_string(volume.layers()) +
                             " overlapping layers: write it as .seg.nrrd");
  reportProgress(options.progress, 0.0, "writing");
  NiftiSlabWriter writer(path, volume.geometry(), volume.scalarType(), volume.labels(),
                         volume.isLabelMap(), options.niftiVersion);
  const std::int64_t slices = volume.dims()[2];
  const std::int64_t sliceBytes = volume.dims()[0] * volume.dims()[1] *
                                  static_cast<std::int64_t>(scalarSize(volume.scalarType()));
  const auto* bytes = static_cast<const std::uint8_t*>(volume.layerData(0));
  const std::int64_t step =
      std::max<std::int64_t>(1, (64 << 20) / std::max<std::int64_t>(1, sliceBytes));
  for (std::int64_t k = 0; k < slices; k += step) {
    const std::int64_t n = std::min(step, slices - k);
    writer.writeSlices(bytes + k * sliceBytes, n);
    reportProgress(options.progress, double(k + n) / slices, "writing");
  }
  writer.finish();
}

}  // namespace repose

// DICOM SEG out, slice by slice: dcmseg builds and checks the header (DicomSegHeader.cpp); the
// frames are Repose's. Their bits go to a temporary file as the slices come, one after the other
// with no padding between frames (dcmseg 3.6.7 pads each frame whose size is not a multiple of 8:
// DCMTK issue 1132), and their functional groups (position, dimension index, segment) are
// encoded here after the header, since the segments' numbers are known only once every slice has
// been seen. A SEG larger than memory is then written with a frame's slice, layer and value in
// memory per frame (issue 56); the in-core writer is the same code over the whole volume.
#include "repose/io/DicomSegIO.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"

#include "DcmtkCommon.h"
#include "DicomSegHeader.h"

// clang-format off
#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
// clang-format on
#include <dcmtk/dcmdata/dcfilefo.h>

#include <Eigen/Core>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <set>

namespace repose {
namespace {

// What a frame shows: slice k of a layer's value (0: an empty frame, of segment 1 unless a
// segment with no voxel is named by layer and value).
struct FrameSource {
  std::int32_t k, layer, value;
};

// Explicit VR little endian, as the header is saved (PS3.5 7.1.2): a short element, a sequence
// or item of undefined length, and their ends.
void put16(std::string& out, std::uint16_t v) {
  out.push_back(char(v & 0xFF)), out.push_back(char(v >> 8));
}
void put32(std::string& out, std::uint32_t v) {
  put16(out, std::uint16_t(v & 0xFFFF)), put16(out, std::uint16_t(v >> 16));
}
void putShort(std::string& out, std::uint16_t group, std::uint16_t element, const char* vr,
              const std::string& value) {
  put16(out, group), put16(out, element), out.append(vr, 2);
  put16(out, std::uint16_t(value.size())), out += value;
}
void openSequence(std::string& out, std::uint16_t group, std::uint16_t element) {
  put16(out, group), put16(out, element), out.append("SQ"), put16(out, 0), put32(out, 0xFFFFFFFF);
}
void openItem(std::string& out) {
  put16(out, 0xFFFE), put16(out, 0xE000), put32(out, 0xFFFFFFFF);
}
void closeItem(std::string& out) {
  put16(out, 0xFFFE), put16(out, 0xE00D), put32(out, 0);
}
void closeSequence(std::string& out) {
  put16(out, 0xFFFE), put16(out, 0xE0DD), put32(out, 0);
}

// A frame's item of the Per-frame Functional Groups Sequence: Frame Content (its dimension index
// values: segment, slice), Plane Position, Segment Identification (PS3.3 C.8.20.3).
void putFrameItem(std::string& out, std::uint16_t segment, std::uint32_t slice,
                  const std::string& position) {
  openItem(out);
  openSequence(out, 0x0020, 0x9111);
  openItem(out);
  std::string indices;
  put32(indices, segment), put32(indices, slice);
  putShort(out, 0x0020, 0x9157, "UL", indices);
  closeItem(out), closeSequence(out);
  openSequence(out, 0x0020, 0x9113);
  openItem(out);
  putShort(out, 0x0020, 0x0032, "DS", position.size() % 2 ? position + " " : position);
  closeItem(out), closeSequence(out);
  openSequence(out, 0x0062, 0x000A);
  openItem(out);
  std::string number;
  put16(number, segment);
  putShort(out, 0x0062, 0x000B, "US", number);
  closeItem(out), closeSequence(out);
  closeItem(out);
}

}  // namespace

struct DicomSegSlabWriter::Impl {
  std::string path;
  VolumeGeometry geometry;
  ScalarType type;
  int layers;
  LabelTable labels;
  DicomSegWriteOptions options;
  AtomicOutput output;
  std::string framesPath;  // the frames' bits, beside the file being made
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> frames{nullptr, &std::fclose};
  std::vector<FrameSource> sources;
  std::set<std::pair<int, int>> present;  // (layer, value) met
  bool emptySlices = false;               // a slice with no voxel of any segment
  std::int64_t bits = 0;                  // written, the carry's included
  std::uint8_t carry = 0;                 // the last byte begun, not yet written
  std::int64_t written = 0;
  std::vector<std::uint8_t> packed;
  Eigen::Matrix4d lps;  // ijk to LPS: the frames' positions
  Impl(const std::string& p, const VolumeGeometry& g, ScalarType t, int l, const LabelTable& table,
       const DicomSegWriteOptions& o)
      : path(p), geometry(g), type(t), layers(l), labels(table), options(o), output(p) {}

  std::int64_t pixels() const { return geometry.dims[0] * geometry.dims[1]; }

  // Appends `count` frames whose set pixels `setBits` gives (as frame index, pixel): their bits
  // follow the last frame's with no gap.
  template <class SetBits>
  void addFrames(std::int64_t count, SetBits&& setBits) {
    const std::int64_t n = pixels();
    const std::int64_t total = bits + count * n;
    if ((total + 15) / 16 * 2 > kDicomSegPixelDataBytes)
      throwFileError(path,
                     "the frames need more than the 4 GiB a DICOM object's pixel data can "
                     "hold (" +
                         std::to_string(sources.size() + std::size_t(count)) + " frames of " +
                         std::to_string(geometry.dims[0]) + "x" + std::to_string(geometry.dims[1]) +
                         "); write NIfTI or .seg.nrrd");
    const std::int64_t start = bits % 8;  // the carry's bits come first
    const std::int64_t end = start + count * n;
    packed.assign(std::size_t((end + 7) / 8), 0);
    packed[0] = carry;
    setBits([&](std::int64_t frame, std::int64_t p) {
      const std::int64_t bit = start + frame * n + p;
      packed[std::size_t(bit >> 3)] |= std::uint8_t(1u << (bit & 7));
    });
    const std::size_t whole = std::size_t(end / 8);
    if (whole > 0 && std::fwrite(packed.data(), 1, whole, frames.get()) != whole)
      throwFileError(path, "write failed (disk full?)");
    carry = end % 8 ? packed[whole] : 0;
    bits = total;
  }

  // Slice `k` of a layer (`pixels()` values of type T): one frame per value present, in
  // increasing value; the values are added to `present`. Returns whether it had any.
  template <class T>
  bool addSlice(const T* slice, std::int32_t k, int layer) {
    const std::int64_t n = pixels();
    std::vector<int> values;  // sorted
    T last = T(0);
    for (std::int64_t p = 0; p < n; ++p)
      if (slice[p] != T(0) && slice[p] != last) {
        last = slice[p];
        const auto at = std::lower_bound(values.begin(), values.end(), int(last));
        if (at == values.end() || *at != int(last)) values.insert(at, int(last));
      }
    if (values.empty()) return false;
    addFrames(std::int64_t(values.size()), [&](auto&& set) {
      T lastValue = T(0);
      std::int64_t frame = 0;
      for (std::int64_t p = 0; p < n; ++p)
        if (slice[p] != T(0)) {
          if (slice[p] != lastValue) {
            lastValue = slice[p];
            frame = std::lower_bound(values.begin(), values.end(), int(lastValue)) - values.begin();
          }
          set(frame, p);
        }
    });
    for (int v : values) {
      sources.push_back({k, layer, v});
      present.insert({layer, v});
    }
    return true;
  }

  void addEmptyFrame(std::int32_t k, int layer, int value) {
    addFrames(1, [](auto&&) {});
    sources.push_back({k, layer, value});
  }
};

DicomSegSlabWriter::DicomSegSlabWriter(const std::string& path, const VolumeGeometry& geometry,
                                       ScalarType type, int layers, const LabelTable& labels,
                                       const DicomSegWriteOptions& options) {
  geometry.validate(path);
  if (type != ScalarType::UInt8 && type != ScalarType::UInt16 && type != ScalarType::Int16 &&
      type != ScalarType::Int32)
    throwFileError(path, "a DICOM SEG needs integer labels");
  if (layers < 1) throwFileError(path, "a segmentation of no layer");
  if (geometry.dims[2] > 0x7FFFFFFF) throwFileError(path, "more slices than DICOM can number");
  io::prepareDcmtk(path);
  const io::DicomSegPlane plane = io::dicomSegPlane(path, geometry);
  impl_ = std::make_unique<Impl>(path, geometry, type, layers, labels, options);
  impl_->lps = plane.lps;
  impl_->framesPath = impl_->output.tempPath() + ".frames";
  impl_->frames.reset(std::fopen(impl_->framesPath.c_str(), "wb"));
  if (!impl_->frames) throwFileError(path, "cannot create the output file");
}

DicomSegSlabWriter::~DicomSegSlabWriter() {
  if (impl_ && !impl_->framesPath.empty()) {
    impl_->frames.reset();
    std::remove(impl_->framesPath.c_str());
  }
}

void DicomSegSlabWriter::writeSlices(const void* data, std::int64_t slices) {
  Impl& r = *impl_;
  const auto& d = r.geometry.dims;
  if (slices <= 0 || r.written + slices > d[2])
    throwFileError(r.path, "more slices than the segmentation's grid holds");
  const std::int64_t n = r.pixels();
  const auto* in = static_cast<const std::uint8_t*>(data);
  const std::size_t size = scalarSize(r.type);
  for (std::int64_t s = 0; s < slices; ++s) {
    const std::int32_t k = std::int32_t(r.written + s);
    bool any = false;
    for (int l = 0; l < r.layers; ++l) {
      const std::uint8_t* slice = in + std::size_t((l * slices + s) * n) * size;
      dispatchScalar(r.type, [&](auto* tag) {
        using T = std::remove_pointer_t<decltype(tag)>;
        if constexpr (std::is_integral_v<T>)
          any = r.addSlice(reinterpret_cast<const T*>(slice), k, l) || any;
      });
    }
    if (!any) {
      r.addEmptyFrame(k, 0, 0);
      r.emptySlices = true;
    }
  }
  r.written += slices;
}

void DicomSegSlabWriter::finish() {
  Impl& r = *impl_;
  if (r.written != r.geometry.dims[2])
    throwFileError(r.path, "the segmentation ends after " + std::to_string(r.written) + " of its " +
                               std::to_string(r.geometry.dims[2]) + " slices");
  // Segments: every label of the table and every value present, by (layer, value).
  std::map<std::pair<int, int>, Label> segments;
  for (const Label& l : r.labels.labels())
    if (l.value != 0) segments[{l.layer, l.value}] = l;
  for (const auto& [layer, value] : r.present)
    if (!segments.count({layer, value})) {
      Label l;
      l.value = value;
      l.layer = layer;
      l.name = "Segment_" + std::to_string(value);
      l.color = LabelTable::defaultColor(value);
      l.colorGenerated = true;
      segments[{layer, value}] = l;
    }
  if (segments.empty()) throwFileError(r.path, "the label map has no label to write as a segment");
  if (segments.size() > 65535) throwFileError(r.path, "more than 65535 labels");
  std::map<std::pair<int, int>, std::uint16_t> numberOf;
  std::vector<Label> ordered;
  for (const auto& [key, l] : segments) {
    ordered.push_back(l);
    numberOf[key] = std::uint16_t(ordered.size());
  }
  // An empty frame for each segment with no voxel (segment 1 has the empty slices' frames), so
  // every segment comes back on reading.
  for (const auto& [key, l] : segments)
    if (!r.present.count(key) && !(r.emptySlices && numberOf[key] == 1))
      r.addEmptyFrame(0, key.first, key.second);
  // The last byte begun, and one more to make the length even, as DICOM asks.
  const std::int64_t bytes = (r.bits + 15) / 16 * 2;
  std::vector<std::uint8_t> tail;
  if (r.bits % 8) tail.push_back(r.carry);
  tail.resize(std::size_t(bytes - r.bits / 8), 0);
  if ((!tail.empty() && std::fwrite(tail.data(), 1, tail.size(), r.frames.get()) != tail.size()) ||
      std::fflush(r.frames.get()) != 0 || std::fclose(r.frames.release()) != 0)
    throwFileError(r.path, "write failed (disk full?)");
  r.packed = std::vector<std::uint8_t>();

  const std::string& temp = r.output.tempPath();
  {
    DcmFileFormat file;
    io::makeDicomSegHeader(file, r.path, r.geometry, ordered, std::int64_t(r.sources.size()),
                           r.options);
    const OFCondition saved = file.saveFile(temp.c_str(), EXS_LittleEndianExplicit);
    if (saved.bad())
      throwFileError(r.path, std::string("cannot write the DICOM segmentation: saving (") +
                                 saved.text() + ")");
  }
  reportProgress(r.options.progress, 0.95, "writing DICOM SEG");
  {
    std::ofstream out(temp, std::ios::binary | std::ios::app);
    std::string chunk;
    openSequence(chunk, 0x5200, 0x9230);
    for (const FrameSource& f : r.sources) {
      const Eigen::Vector3d p = (r.lps * Eigen::Vector4d(0, 0, double(f.k), 1)).head<3>();
      const std::string position = io::dicomDecimal(r.path, p[0]) + "\\" +
                                   io::dicomDecimal(r.path, p[1]) + "\\" +
                                   io::dicomDecimal(r.path, p[2]);
      const std::uint16_t number = f.value == 0 ? 1 : numberOf.at({f.layer, f.value});
      putFrameItem(chunk, number, std::uint32_t(f.k + 1), position);
      if (chunk.size() > (1u << 20))
        out.write(chunk.data(), std::streamsize(chunk.size())), chunk.clear();
    }
    closeSequence(chunk);
    // Pixel Data, OW as dcmseg writes it (the bytes of 1-bit pixels are the same either way).
    put16(chunk, 0x7FE0), put16(chunk, 0x0010), chunk.append("OW"), put16(chunk, 0);
    put32(chunk, std::uint32_t(bytes));
    out.write(chunk.data(), std::streamsize(chunk.size()));
    std::ifstream in(r.framesPath, std::ios::binary);
    out << in.rdbuf();
    out.flush();
    if (!in || !out) throwFileError(r.path, "write failed (disk full?)");
  }
  std::remove(r.framesPath.c_str());
  r.framesPath.clear();
  r.sources = std::vector<FrameSource>();
  reportProgress(r.options.progress, 1.0, "writing DICOM SEG");
  r.output.commit();
}

void writeDicomSeg(const Volume& volume, const std::string& path,
                   const DicomSegWriteOptions& options) {
  if (!volume.isLabelMap()) throwFileError(path, "only a label map can be written as DICOM SEG");
  DicomSegWriteOptions slabOptions = options;
  slabOptions.progress = {};
  DicomSegSlabWriter writer(path, volume.geometry(), volume.scalarType(), volume.layers(),
                            volume.labels(), slabOptions);
  // A slice of every layer at a time: one layer's straight from the volume, several copied
  // together (the layers are apart in memory).
  const std::int64_t nz = volume.dims()[2];
  const std::size_t slice =
      std::size_t(volume.dims()[0] * volume.dims()[1]) * scalarSize(volume.scalarType());
  std::vector<std::uint8_t> layers(volume.layers() > 1 ? slice * std::size_t(volume.layers()) : 0);
  for (std::int64_t k = 0; k < nz; ++k) {
    auto at = [&](int l) {
      return static_cast<const std::uint8_t*>(volume.layerData(l)) + std::size_t(k) * slice;
    };
    if (volume.layers() == 1) {
      writer.writeSlices(at(0), 1);
    } else {
      for (int l = 0; l < volume.layers(); ++l)
        std::memcpy(layers.data() + std::size_t(l) * slice, at(l), slice);
      writer.writeSlices(layers.data(), 1);
    }
    reportProgress(options.progress, 0.9 * double(k + 1) / double(nz), "writing DICOM SEG");
  }
  writer.finish();
  reportProgress(options.progress, 1.0, "writing DICOM SEG");
}

}  // namespace repose

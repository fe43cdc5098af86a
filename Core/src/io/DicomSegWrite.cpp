// DICOM SEG out through DCMTK's dcmseg: the IOD (patient, study, series, equipment, frame of
// reference, segments, functional groups, dimensions) is built and checked by dcmseg; the packed
// bits are written by Repose, frame after frame with no padding between frames, because dcmseg
// 3.6.7 pads each frame whose size is not a multiple of 8 (DCMTK issue 1132). Each segment also
// carries Repose's label value and layer in a private block, so reading the file back gives the
// same voxels even when the values are not 1..n.
#include "repose/io/DicomSegIO.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"
#include "repose/volume/SegmentTerminology.h"

#include "DcmtkCommon.h"
#include "DicomSegPrivate.h"

// clang-format off
#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <dcmtk/dcmfg/fgfracon.h>
#include <dcmtk/dcmfg/fgpixmsr.h>
#include <dcmtk/dcmfg/fgplanor.h>
#include <dcmtk/dcmfg/fgplanpo.h>
#include <dcmtk/dcmiod/cielabutil.h>
#include <dcmtk/dcmseg/segdoc.h>
#include <dcmtk/dcmseg/segment.h>

#include "DcmtkAttributes.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

namespace repose {
namespace {

// A DS value: at most 16 characters (PS3.5 6.2).
std::string decimal(const std::string& path, double v) {
  for (int digits = 10; digits >= 4; --digits) {
    char b[40];
    std::snprintf(b, sizeof b, "%.*g", digits, std::fabs(v) < 1e-9 ? 0.0 : v);
    if (std::strlen(b) <= 16) return b;
  }
  throwFileError(path, "the value " + std::to_string(v) + " does not fit DICOM's decimal strings");
}

void check(const std::string& path, const OFCondition& c, const std::string& what) {
  if (c.bad())
    throwFileError(path, "cannot write the DICOM segmentation: " + what + " (" + c.text() + ")");
}

// A name as DICOM's LO (SegmentLabel, CodeMeaning): no backslash (the value separator) or
// control characters, at most 64 characters (not cutting a UTF-8 sequence).
std::string longString(std::string s) {
  for (char& c : s)
    if (c == '\\')
      c = '/';
    else if (static_cast<unsigned char>(c) < 32)
      c = ' ';
  if (s.size() > 64) {
    std::size_t end = 64;
    while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
    s.resize(end);
  }
  return s;
}

// A code DICOM takes: a value and scheme of at most 16 characters (SH) and a meaning.
bool usable(const TerminologyCode& c) {
  return !c.value.empty() && c.value.size() <= 16 && !c.scheme.empty() && c.scheme.size() <= 16 &&
         !c.meaning.empty() && c.value.find('\\') == std::string::npos &&
         c.scheme.find('\\') == std::string::npos;
}

CodeSequenceMacro codeMacro(const TerminologyCode& c) {
  return CodeSequenceMacro(c.value.c_str(), c.scheme.c_str(), longString(c.meaning).c_str());
}

// The segment's codes as DICOM can hold them: a category and type it cannot hold give way to
// SCT "Tissue" (both, so they stay a pair); a modifier or region it cannot hold is left out.
SegmentTerminology dicomTerminology(const std::string& tags) {
  SegmentTerminology t = terminologyFromTags(tags).value_or(genericTissueTerminology());
  if (!usable(t.category) || !usable(t.type)) {
    const SegmentTerminology generic = genericTissueTerminology();
    t.category = generic.category;
    t.type = generic.type;
  }
  for (TerminologyCode* c : {&t.typeModifier, &t.region, &t.regionModifier})
    if (!usable(*c)) *c = {};
  if (t.region.empty()) t.regionModifier = {};
  return t;
}

// The values of one slice of a layer: calls fn(value, pixel) for every non-zero voxel.
template <class T, class Fn>
void forEachLabelled(const T* slice, std::int64_t pixels, Fn&& fn) {
  for (std::int64_t p = 0; p < pixels; ++p)
    if (slice[p] != 0) fn(static_cast<int>(slice[p]), p);
}

struct SegmentOut {
  int layer = 0, value = 0;
  Uint16 number = 0;
  Label label;
  std::string dicomName;  // SegmentLabel as written
};

}  // namespace

void writeDicomSeg(const Volume& volume, const std::string& path,
                   const DicomSegWriteOptions& options) {
  io::prepareDcmtk(path);
  if (!volume.isLabelMap()) throwFileError(path, "only a label map can be written as DICOM SEG");
  const ScalarType type = volume.scalarType();
  if (type != ScalarType::UInt8 && type != ScalarType::UInt16 && type != ScalarType::Int16 &&
      type != ScalarType::Int32)
    throwFileError(path, "a DICOM SEG needs integer labels");
  const VolumeGeometry& g = volume.geometry();
  if (g.dims[0] > 65535 || g.dims[1] > 65535)
    throwFileError(path, "slices of " + std::to_string(g.dims[0]) + "x" +
                             std::to_string(g.dims[1]) + " exceed DICOM's 65535 rows or columns");
  // The frames' plane: i along the rows, j along the columns (LPS); k must be their normal, as
  // a SEG's frames give only their plane's position.
  const Eigen::Matrix4d lps = flipLpsRas(g.ijkToRas);
  const Eigen::Vector3d spacing = g.spacing();
  const Eigen::Vector3d rowDir = lps.block<3, 1>(0, 0) / spacing[0];
  const Eigen::Vector3d colDir = lps.block<3, 1>(0, 1) / spacing[1];
  const Eigen::Vector3d sliceDir = lps.block<3, 1>(0, 2) / spacing[2];
  if (std::fabs(rowDir.dot(colDir)) > 1e-4 || rowDir.cross(colDir).dot(sliceDir) < 1 - 1e-4)
    throwFileError(path,
                   "a DICOM SEG's slices must be stacked along the normal of their rows and "
                   "columns (a right-handed, unsheared grid); resample this one first");

  // Segments: every label of the table and every value present, by (layer, value).
  std::map<std::pair<int, int>, SegmentOut> segments;
  for (const Label& l : volume.labels().labels())
    if (l.value != 0) segments[{l.layer, l.value}] = {l.layer, l.value, 0, l, ""};
  for (const LabelCount& c : countLabels(volume))
    if (!segments.count({c.layer, c.value})) {
      Label l;
      l.value = c.value;
      l.layer = c.layer;
      l.name = "Segment_" + std::to_string(c.value);
      l.color = LabelTable::defaultColor(c.value);
      l.colorGenerated = true;
      segments[{c.layer, c.value}] = {c.layer, c.value, 0, l, ""};
    }
  if (segments.empty()) throwFileError(path, "the label map has no label to write as a segment");
  if (segments.size() > 65535) throwFileError(path, "more than 65535 labels");

  const Uint16 rows = Uint16(g.dims[1]), columns = Uint16(g.dims[0]);
  IODGeneralEquipmentModule::EquipmentInfo equipment("Repose", "Repose", "1", REPOSE_VERSION);
  ContentIdentificationMacro content("1", "REPOSE", options.description.c_str(), "Repose");
  DcmSegmentation* created = nullptr;
  check(path, DcmSegmentation::createBinarySegmentation(created, rows, columns, equipment, content),
        "creating it");
  std::unique_ptr<DcmSegmentation> seg(created);
  // Patient and study from the DICOM the label map came from; its equipment and frame of
  // reference are not this object's: the label map is a new geometry (a posed body).
  if (!options.sourceDicom.empty())
    check(path, seg->importFromSourceImage(options.sourceDicom.c_str()),
          "copying patient and study from " + options.sourceDicom);
  check(path, seg->setEquipmentInfo(equipment), "equipment");
  char uid[100];
  check(path,
        seg->getFrameOfReference().setFrameOfReferenceUID(
            dcmGenerateUniqueIdentifier(uid, SITE_INSTANCE_UID_ROOT)),
        "frame of reference");
  seg->getSeries().setSeriesNumber(options.seriesNumber.c_str());
  seg->getSeries().setSeriesDescription(options.description.c_str());

  FGPixelMeasures measures;
  check(path,
        measures.setPixelSpacing(
            (decimal(path, spacing[1]) + "\\" + decimal(path, spacing[0])).c_str()),
        "pixel spacing");
  check(path, measures.setSliceThickness(decimal(path, spacing[2]).c_str()), "slice thickness");
  check(path, measures.setSpacingBetweenSlices(decimal(path, spacing[2]).c_str()), "slice spacing");
  check(path, seg->addForAllFrames(measures), "pixel measures");
  std::unique_ptr<FGPlaneOrientationPatient> orientation(FGPlaneOrientationPatient::createMinimal(
      decimal(path, rowDir[0]).c_str(), decimal(path, rowDir[1]).c_str(),
      decimal(path, rowDir[2]).c_str(), decimal(path, colDir[0]).c_str(),
      decimal(path, colDir[1]).c_str(), decimal(path, colDir[2]).c_str()));
  if (!orientation) throwFileError(path, "cannot write the DICOM segmentation: orientation");
  check(path, seg->addForAllFrames(*orientation), "plane orientation");

  bool anyNonAscii = false;
  for (auto& [key, s] : segments) {
    const Label& l = s.label;
    const SegmentTerminology t = dicomTerminology(l.tags);
    const std::string name =
        longString(l.name.empty() ? "Segment_" + std::to_string(l.value) : l.name);
    // dcmseg checks names as plain ASCII: one beyond it is set in the dataset afterwards.
    std::string ascii = name;
    for (char& c : ascii)
      if (static_cast<unsigned char>(c) > 127) c = '?';
    anyNonAscii = anyNonAscii || ascii != name;
    s.dicomName = name;
    DcmSegment* segment = nullptr;
    check(path,
          DcmSegment::create(segment, ascii.c_str(), codeMacro(t.category), codeMacro(t.type),
                             DcmSegTypes::SAT_AUTOMATIC, "Repose"),
          "segment " + name);
    std::unique_ptr<DcmSegment> owned(segment);
    if (!t.typeModifier.empty())
      segment->getSegmentedPropertyTypeModifierCode().push_back(
          new CodeSequenceMacro(codeMacro(t.typeModifier)));
    if (!t.region.empty()) {
      segment->getGeneralAnatomyCode().getAnatomicRegion().set(
          t.region.value.c_str(), t.region.scheme.c_str(), t.region.meaning.c_str());
      if (!t.regionModifier.empty())
        segment->getGeneralAnatomyCode().getAnatomicRegionModifier().push_back(
            new CodeSequenceMacro(codeMacro(t.regionModifier)));
    }
    double L = 0, a = 0, b = 0;
    IODCIELabUtil::rgb2DicomLab(L, a, b, l.color[0], l.color[1], l.color[2]);
    auto scaled = [](double v) { return Uint16(std::clamp(std::lround(v), 0L, 65535L)); };
    segment->setRecommendedDisplayCIELabValue(scaled(L), scaled(a), scaled(b));
    check(path, seg->addSegment(owned.release(), s.number), "segment " + l.name);
  }

  // Dimensions: segment, then position (as dcmqi writes them).
  char organization[100];
  dcmGenerateUniqueIdentifier(organization, SITE_INSTANCE_UID_ROOT);
  IODMultiframeDimensionModule& dims = seg->getDimensions();
  check(path,
        dims.addDimensionIndex(DCM_ReferencedSegmentNumber, organization,
                               DCM_SegmentIdentificationSequence, "ReferencedSegmentNumber"),
        "dimensions");
  check(path,
        dims.addDimensionIndex(DCM_ImagePositionPatient, organization, DCM_PlanePositionSequence,
                               "ImagePositionPatient"),
        "dimensions");
  auto item = std::make_unique<IODMultiframeDimensionModule::DimensionOrganizationItem>();
  item->setDimensionOrganizationUID(organization);
  dims.getDimensionOrganizationSequence().push_back(item.release());

  // Frames, slice by slice: one per segment present in the slice; a slice with none gets an
  // empty frame of the first segment, and so does a segment with no voxel, so the grid and every
  // segment come back on reading. dcmseg keeps each frame's bits; what each frame holds is noted
  // here (its slice, layer and value, 0 for an empty frame) so that the pixel data written at
  // the end is made from the volume once dcmseg's frames are freed: the largest objects held at
  // once are then two copies of the frames' bits, not three.
  const std::int64_t pixels = std::int64_t(rows) * columns;
  struct FrameSource {
    std::int64_t k;
    int layer, value;
  };
  std::vector<FrameSource> sources;
  std::vector<Uint8> mask(static_cast<std::size_t>(pixels));
  std::map<Uint16, bool> hasFrame;
  auto addFrame = [&](Uint16 number, std::int64_t k, int layer, int value) {
    const std::int64_t frames = std::int64_t(sources.size());
    const std::int64_t bytes = ((frames + 1) * pixels + 7) / 8;
    if (bytes > std::int64_t(0xFFFFFFFE))
      throwFileError(path,
                     "the frames need more than the 4 GB a DICOM object's pixel data can "
                     "hold (" +
                         std::to_string(frames + 1) + " frames of " + std::to_string(columns) +
                         "x" + std::to_string(rows) + "); write NIfTI or .seg.nrrd");
    const Eigen::Vector3d p = (lps * Eigen::Vector4d(0, 0, double(k), 1)).head<3>();
    std::unique_ptr<FGPlanePosPatient> position(FGPlanePosPatient::createMinimal(
        decimal(path, p[0]).c_str(), decimal(path, p[1]).c_str(), decimal(path, p[2]).c_str()));
    FGFrameContent frameContent;
    frameContent.setDimensionIndexValues(number, 0);
    frameContent.setDimensionIndexValues(Uint32(k + 1), 1);
    OFVector<FGBase*> groups{position.get(), &frameContent};
    check(path, seg->addFrame(mask.data(), number, groups), "frame");
    sources.push_back({k, layer, value});
    hasFrame[number] = true;
  };
  // Calls fn(slice) with slice k of a layer in its own scalar type.
  auto withSlice = [&](int layer, std::int64_t k, auto&& fn) {
    switch (type) {
      case ScalarType::UInt8:
        return fn(volume.data<std::uint8_t>(layer) + k * pixels);
      case ScalarType::UInt16:
        return fn(volume.data<std::uint16_t>(layer) + k * pixels);
      case ScalarType::Int16:
        return fn(volume.data<std::int16_t>(layer) + k * pixels);
      default:
        return fn(volume.data<std::int32_t>(layer) + k * pixels);
    }
  };
  std::map<std::pair<int, int>, Uint16> numberOf;
  for (const auto& [key, s] : segments) numberOf[key] = s.number;
  for (std::int64_t k = 0; k < g.dims[2]; ++k) {
    bool any = false;
    for (int layer = 0; layer < volume.layers(); ++layer) {
      // Values in this slice of this layer, then one frame each.
      std::map<int, std::vector<std::int64_t>> at;
      withSlice(layer, k, [&](const auto* slice) {
        forEachLabelled(slice, pixels, [&](int v, std::int64_t p) { at[v].push_back(p); });
      });
      for (const auto& [value, where] : at) {
        std::fill(mask.begin(), mask.end(), 0);
        for (std::int64_t p : where) mask[std::size_t(p)] = 1;
        addFrame(numberOf.at({layer, value}), k, layer, value);
        any = true;
      }
    }
    if (!any) {
      std::fill(mask.begin(), mask.end(), 0);
      addFrame(segments.begin()->second.number, k, 0, 0);
    }
    reportProgress(options.progress, 0.9 * double(k + 1) / double(g.dims[2]), "writing DICOM SEG");
  }
  std::fill(mask.begin(), mask.end(), 0);
  for (const auto& [key, s] : segments)
    if (!hasFrame[s.number]) addFrame(s.number, 0, 0, 0);
  mask = std::vector<Uint8>();

  DcmFileFormat file;
  check(path, seg->writeDataset(*file.getDataset()), "checking the object");
  DcmDataset* ds = file.getDataset();
  // Names beyond ASCII: in UTF-8 when the object has no character set of its own (from the
  // source DICOM); else they would be read in that one, so those characters stay '?'.
  if (anyNonAscii) {
    const std::string charset = io::dicomText(ds, DCM_SpecificCharacterSet);
    if (charset.empty() || charset == "ISO_IR 192") {
      ds->putAndInsertString(DCM_SpecificCharacterSet, "ISO_IR 192");
      DcmSequenceOfItems* named = nullptr;
      ds->findAndGetSequence(DCM_SegmentSequence, named);
      for (const auto& [key, s] : segments)
        if (DcmItem* item = named ? named->getItem(s.number - 1) : nullptr)
          item->putAndInsertString(DCM_SegmentLabel, s.dicomName.c_str());
    }
  }
  // The frames' bits one after the other with no padding between frames (see the top of this
  // file), in place of dcmseg's pixel data, made in the element itself.
  seg.reset();
  delete ds->remove(DCM_PixelData);
  {
    const std::int64_t bits = std::int64_t(sources.size()) * pixels;
    const Uint32 bytes = Uint32(((bits + 7) / 8 + 1) / 2 * 2);  // an even length, as DICOM asks
    auto pixelData = std::make_unique<DcmPixelData>(DCM_PixelData);
    Uint8* packed = nullptr;  // zeroed by DCMTK
    check(path, pixelData->createUint8Array(bytes, packed), "pixel data");
    for (std::size_t f = 0; f < sources.size();) {
      // The frames of one slice and layer, found in one pass over it.
      const FrameSource& first = sources[f];
      std::size_t last = f;
      while (last + 1 < sources.size() && sources[last + 1].k == first.k &&
             sources[last + 1].layer == first.layer)
        ++last;
      std::map<int, std::int64_t> frameOf;  // value -> frame
      for (std::size_t n = f; n <= last; ++n)
        if (sources[n].value != 0) frameOf[sources[n].value] = std::int64_t(n);
      if (!frameOf.empty())
        withSlice(first.layer, first.k, [&](const auto* slice) {
          int lastValue = 0;
          std::int64_t lastFrame = -1;
          forEachLabelled(slice, pixels, [&](int v, std::int64_t p) {
            if (v != lastValue) lastValue = v, lastFrame = frameOf.at(v);
            const std::int64_t bit = lastFrame * pixels + p;
            packed[bit >> 3] |= Uint8(1u << (bit & 7));
          });
        });
      f = last + 1;
    }
    check(path, ds->insert(pixelData.release(), true), "pixel data");
  }
  // Repose's value and layer of each segment (private block, DicomSegPrivate.h).
  DcmSequenceOfItems* items = nullptr;
  check(path, ds->findAndGetSequence(DCM_SegmentSequence, items), "segments");
  for (const auto& [key, s] : segments) {
    DcmItem* it = items->getItem(s.number - 1);
    if (!it)
      throwFileError(path,
                     "cannot write the DICOM segmentation: segment " + std::to_string(s.number));
    io::putReposeLabel(*it, s.value, s.layer);
  }
  AtomicOutput output(path);
  check(path, file.saveFile(output.tempPath().c_str(), EXS_LittleEndianExplicit), "saving");
  reportProgress(options.progress, 1.0, "writing DICOM SEG");
  output.commit();
}

}  // namespace repose

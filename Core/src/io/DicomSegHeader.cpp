// DICOM SEG's header through DCMTK's dcmseg (DicomSegHeader.h): dcmseg builds and checks the IOD;
// its frames are a placeholder removed again, as the writer streams the real ones after it.
#include "DicomSegHeader.h"

#include "repose/util/Error.h"
#include "repose/volume/SegmentTerminology.h"

#include "DcmtkCommon.h"
#include "DicomSegPrivate.h"

// clang-format off
#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
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
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

namespace repose::io {
namespace {

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

}  // namespace

std::string dicomDecimal(const std::string& path, double v) {
  for (int digits = 10; digits >= 4; --digits) {
    char b[40];
    std::snprintf(b, sizeof b, "%.*g", digits, std::fabs(v) < 1e-9 ? 0.0 : v);
    if (std::strlen(b) <= 16) return b;
  }
  throwFileError(path, "the value " + std::to_string(v) + " does not fit DICOM's decimal strings");
}

DicomSegPlane dicomSegPlane(const std::string& path, const VolumeGeometry& g) {
  if (g.dims[0] > 65535 || g.dims[1] > 65535)
    throwFileError(path, "slices of " + std::to_string(g.dims[0]) + "x" +
                             std::to_string(g.dims[1]) + " exceed DICOM's 65535 rows or columns");
  // The frames' plane: i along the rows, j along the columns (LPS); k must be their normal, as
  // a SEG's frames give only their plane's position.
  DicomSegPlane plane;
  plane.lps = flipLpsRas(g.ijkToRas);
  const Eigen::Vector3d spacing = g.spacing();
  plane.row = plane.lps.block<3, 1>(0, 0) / spacing[0];
  plane.column = plane.lps.block<3, 1>(0, 1) / spacing[1];
  const Eigen::Vector3d sliceDir = plane.lps.block<3, 1>(0, 2) / spacing[2];
  if (std::fabs(plane.row.dot(plane.column)) > 1e-4 ||
      plane.row.cross(plane.column).dot(sliceDir) < 1 - 1e-4)
    throwFileError(path,
                   "a DICOM SEG's slices must be stacked along the normal of their rows and "
                   "columns (a right-handed, unsheared grid); resample this one first");
  return plane;
}

void makeDicomSegHeader(DcmFileFormat& file, const std::string& path, const VolumeGeometry& g,
                        const std::vector<Label>& segments, std::int64_t frames,
                        const DicomSegWriteOptions& options) {
  prepareDcmtk(path);
  const DicomSegPlane plane = dicomSegPlane(path, g);
  if (segments.empty()) throwFileError(path, "the label map has no label to write as a segment");
  if (segments.size() > 65535) throwFileError(path, "more than 65535 labels");
  const Eigen::Vector3d spacing = g.spacing();
  const Eigen::Vector3d &rowDir = plane.row, &colDir = plane.column;

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
            (dicomDecimal(path, spacing[1]) + "\\" + dicomDecimal(path, spacing[0])).c_str()),
        "pixel spacing");
  check(path, measures.setSliceThickness(dicomDecimal(path, spacing[2]).c_str()),
        "slice thickness");
  check(path, measures.setSpacingBetweenSlices(dicomDecimal(path, spacing[2]).c_str()),
        "slice spacing");
  check(path, seg->addForAllFrames(measures), "pixel measures");
  std::unique_ptr<FGPlaneOrientationPatient> orientation(FGPlaneOrientationPatient::createMinimal(
      dicomDecimal(path, rowDir[0]).c_str(), dicomDecimal(path, rowDir[1]).c_str(),
      dicomDecimal(path, rowDir[2]).c_str(), dicomDecimal(path, colDir[0]).c_str(),
      dicomDecimal(path, colDir[1]).c_str(), dicomDecimal(path, colDir[2]).c_str()));
  if (!orientation) throwFileError(path, "cannot write the DICOM segmentation: orientation");
  check(path, seg->addForAllFrames(*orientation), "plane orientation");

  bool anyNonAscii = false;
  std::vector<std::string> dicomNames;
  for (const Label& l : segments) {
    const SegmentTerminology t = dicomTerminology(l.tags);
    const std::string name =
        longString(l.name.empty() ? "Segment_" + std::to_string(l.value) : l.name);
    // dcmseg checks names as plain ASCII: one beyond it is set in the dataset afterwards.
    std::string ascii = name;
    for (char& c : ascii)
      if (static_cast<unsigned char>(c) > 127) c = '?';
    anyNonAscii = anyNonAscii || ascii != name;
    dicomNames.push_back(name);
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
    Uint16 number = 0;
    check(path, seg->addSegment(owned.release(), number), "segment " + l.name);
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

  // dcmseg checks the object only with frames, each segment's own: an empty frame per segment
  // stands in for the frames the writer appends, and goes again below.
  {
    std::vector<Uint8> empty(std::size_t(rows) * columns, 0);
    const Eigen::Vector3d p = plane.lps.block<3, 1>(0, 3);
    std::unique_ptr<FGPlanePosPatient> position(FGPlanePosPatient::createMinimal(
        dicomDecimal(path, p[0]).c_str(), dicomDecimal(path, p[1]).c_str(),
        dicomDecimal(path, p[2]).c_str()));
    for (std::size_t n = 1; n <= segments.size(); ++n) {
      FGFrameContent frameContent;
      frameContent.setDimensionIndexValues(Uint32(n), 0);
      frameContent.setDimensionIndexValues(1, 1);
      OFVector<FGBase*> groups{position.get(), &frameContent};
      check(path, seg->addFrame(empty.data(), Uint16(n), groups), "frame");
    }
  }
  check(path, seg->writeDataset(*file.getDataset()), "checking the object");
  seg.reset();
  DcmDataset* ds = file.getDataset();
  delete ds->remove(DCM_PerFrameFunctionalGroupsSequence);
  delete ds->remove(DCM_PixelData);
  check(path, ds->putAndInsertString(DCM_NumberOfFrames, std::to_string(frames).c_str()),
        "number of frames");
  // Names beyond ASCII: in UTF-8 when the object has no character set of its own (from the
  // source DICOM); else they would be read in that one, so those characters stay '?'.
  if (anyNonAscii) {
    const std::string charset = dicomText(ds, DCM_SpecificCharacterSet);
    if (charset.empty() || charset == "ISO_IR 192") {
      ds->putAndInsertString(DCM_SpecificCharacterSet, "ISO_IR 192");
      DcmSequenceOfItems* named = nullptr;
      ds->findAndGetSequence(DCM_SegmentSequence, named);
      for (std::size_t n = 0; n < segments.size(); ++n)
        if (DcmItem* it = named ? named->getItem(static_cast<unsigned long>(n)) : nullptr)
          it->putAndInsertString(DCM_SegmentLabel, dicomNames[n].c_str());
    }
  }
  // Repose's value and layer of each segment (private block, DicomSegPrivate.h).
  DcmSequenceOfItems* items = nullptr;
  check(path, ds->findAndGetSequence(DCM_SegmentSequence, items), "segments");
  for (std::size_t n = 0; n < segments.size(); ++n) {
    DcmItem* it = items->getItem(static_cast<unsigned long>(n));
    if (!it)
      throwFileError(path, "cannot write the DICOM segmentation: segment " + std::to_string(n + 1));
    putReposeLabel(*it, segments[n].value, segments[n].layer);
  }
}

}  // namespace repose::io

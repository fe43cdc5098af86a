// Small DICOM SEG files written attribute by attribute with DCMTK's dcmdata, for the tests of the
// SEG reader: valid ones of any size (odd frame sizes, fractional, several segments) and, by
// changing one field, the broken ones a reader must refuse.
#pragma once

// clang-format off
#include <dcmtk/config/osconfig.h>
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace repose::test {

struct TinySeg {
  int rows = 3, columns = 5;
  std::string orientation = "1\\0\\0\\0\\1\\0";
  std::string pixelSpacing = "0.5\\0.75";  // between rows, between columns
  std::string spacingBetweenSlices = "2";  // "" leaves it out
  int segments = 2;
  std::vector<std::array<double, 3>> positions;   // LPS, one per frame
  std::vector<int> segmentOfFrame;                // ReferencedSegmentNumber per frame
  std::vector<std::vector<std::uint8_t>> frames;  // rows*columns values per frame (0/1 binary)
  bool fractional = false;
  int maxFractional = 255;
  // Broken variants.
  int framesDeclared = -1;        // NumberOfFrames when not the real count
  int frameWithoutPosition = -1;  // this frame gets no PlanePositionSequence
  std::size_t cutPixelBytes = 0;  // bytes cut off the end of PixelData
};

inline std::string ds(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

// Writes the SEG; segment s (1-based) is named "Segment s name", coloured by a CIELab that
// differs per segment, and coded SCT Tissue / SCT Liver.
inline void writeTinySeg(const TinySeg& t, const std::string& path) {
  DcmFileFormat file;
  DcmDataset* d = file.getDataset();
  d->putAndInsertString(DCM_SOPClassUID, UID_SegmentationStorage);
  d->putAndInsertString(DCM_SOPInstanceUID, "1.2.826.0.1.3680043.2.1125.1");
  d->putAndInsertString(DCM_Modality, "SEG");
  d->putAndInsertUint16(DCM_Rows, Uint16(t.rows));
  d->putAndInsertUint16(DCM_Columns, Uint16(t.columns));
  d->putAndInsertString(DCM_SegmentationType, t.fractional ? "FRACTIONAL" : "BINARY");
  if (t.fractional) {
    d->putAndInsertString(DCM_SegmentationFractionalType, "PROBABILITY");
    d->putAndInsertUint16(DCM_MaximumFractionalValue, Uint16(t.maxFractional));
  }
  const Uint16 bits = t.fractional ? 8 : 1;
  d->putAndInsertUint16(DCM_BitsAllocated, bits);
  d->putAndInsertUint16(DCM_BitsStored, bits);
  d->putAndInsertUint16(DCM_HighBit, Uint16(bits - 1));
  d->putAndInsertUint16(DCM_SamplesPerPixel, 1);
  d->putAndInsertString(DCM_PhotometricInterpretation, "MONOCHROME2");
  const int n = int(t.frames.size());
  d->putAndInsertString(DCM_NumberOfFrames,
                        std::to_string(t.framesDeclared >= 0 ? t.framesDeclared : n).c_str());
  DcmItem* shared = nullptr;
  d->findOrCreateSequenceItem(DCM_SharedFunctionalGroupsSequence, shared, 0);
  DcmItem* item = nullptr;
  shared->findOrCreateSequenceItem(DCM_PlaneOrientationSequence, item, 0);
  item->putAndInsertString(DCM_ImageOrientationPatient, t.orientation.c_str());
  shared->findOrCreateSequenceItem(DCM_PixelMeasuresSequence, item, 0);
  item->putAndInsertString(DCM_PixelSpacing, t.pixelSpacing.c_str());
  item->putAndInsertString(DCM_SliceThickness, "1");
  if (!t.spacingBetweenSlices.empty())
    item->putAndInsertString(DCM_SpacingBetweenSlices, t.spacingBetweenSlices.c_str());
  for (int f = 0; f < n; ++f) {
    DcmItem* frame = nullptr;
    d->findOrCreateSequenceItem(DCM_PerFrameFunctionalGroupsSequence, frame, f);
    if (f != t.frameWithoutPosition) {
      frame->findOrCreateSequenceItem(DCM_PlanePositionSequence, item, 0);
      const auto& p = t.positions[std::size_t(f)];
      item->putAndInsertString(DCM_ImagePositionPatient,
                               (ds(p[0]) + "\\" + ds(p[1]) + "\\" + ds(p[2])).c_str());
    }
    frame->findOrCreateSequenceItem(DCM_SegmentIdentificationSequence, item, 0);
    item->putAndInsertUint16(DCM_ReferencedSegmentNumber, Uint16(t.segmentOfFrame[std::size_t(f)]));
  }
  for (int s = 0; s < t.segments; ++s) {
    DcmItem* seg = nullptr;
    d->findOrCreateSequenceItem(DCM_SegmentSequence, seg, s);
    seg->putAndInsertUint16(DCM_SegmentNumber, Uint16(s + 1));
    seg->putAndInsertString(DCM_SegmentLabel,
                            ("Segment " + std::to_string(s + 1) + " name").c_str());
    seg->putAndInsertString(DCM_SegmentAlgorithmType, "MANUAL");
    const Uint16 lab[3] = {Uint16(30000 + 5000 * s), Uint16(40000), Uint16(25000 + 3000 * s)};
    seg->putAndInsertUint16Array(DCM_RecommendedDisplayCIELabValue, lab, 3);
    seg->findOrCreateSequenceItem(DCM_SegmentedPropertyCategoryCodeSequence, item, 0);
    item->putAndInsertString(DCM_CodeValue, "85756007");
    item->putAndInsertString(DCM_CodingSchemeDesignator, "SCT");
    item->putAndInsertString(DCM_CodeMeaning, "Tissue");
    seg->findOrCreateSequenceItem(DCM_SegmentedPropertyTypeCodeSequence, item, 0);
    item->putAndInsertString(DCM_CodeValue, "10200004");
    item->putAndInsertString(DCM_CodingSchemeDesignator, "SCT");
    item->putAndInsertString(DCM_CodeMeaning, "Liver");
  }
  const std::size_t pixels = std::size_t(t.rows) * std::size_t(t.columns);
  std::vector<Uint8> data;
  if (t.fractional) {
    for (const auto& f : t.frames) data.insert(data.end(), f.begin(), f.end());
  } else {
    data.assign((pixels * std::size_t(n) + 7) / 8, 0);
    for (int f = 0; f < n; ++f)
      for (std::size_t p = 0; p < pixels; ++p)
        if (t.frames[std::size_t(f)][p]) {
          const std::size_t bit = std::size_t(f) * pixels + p;
          data[bit / 8] = Uint8(data[bit / 8] | (1u << (bit % 8)));
        }
  }
  if (data.size() % 2) data.push_back(0);
  data.resize(data.size() - std::min(t.cutPixelBytes, data.size()));
  d->putAndInsertUint8Array(DCM_PixelData, data.data(), data.size());
  file.saveFile(path.c_str(), EXS_LittleEndianExplicit);
}

// Gives the SEG at `path` (as Repose writes one) a SpacingBetweenSlices of `spacing` mm in its
// shared Pixel Measures, saved over the file: a value its frames do not keep, as a SEG copied
// from another series has, which the reader notes. False if a step fails.
inline bool setSegSpacingBetweenSlices(const std::string& path, const char* spacing) {
  DcmFileFormat seg;
  // All of it: saved over the file it was read from, a PixelData left to be read later is lost.
  if (!seg.loadFile(path.c_str()).good() || !seg.loadAllDataIntoMemory().good()) return false;
  DcmItem *shared = nullptr, *measures = nullptr;
  return seg.getDataset()
             ->findAndGetSequenceItem(DCM_SharedFunctionalGroupsSequence, shared, 0)
             .good() &&
         shared->findAndGetSequenceItem(DCM_PixelMeasuresSequence, measures, 0).good() &&
         measures->putAndInsertString(DCM_SpacingBetweenSlices, spacing).good() &&
         seg.saveFile(path.c_str(), EXS_LittleEndianExplicit).good();
}

// What a SEG Repose wrote holds beyond its identity (UIDs, dates): its NumberOfFrames, then its
// bytes from the Per-frame Functional Groups Sequence to the end (every frame's position, slice
// and segment, then the pixel data). Two SEGs of the same label map written apart agree in it.
inline std::string segFramesOf(const std::string& path) {
  DcmFileFormat file;
  OFString frames;
  if (!file.loadFile(path.c_str()).good() ||
      !file.getDataset()->findAndGetOFString(DCM_NumberOfFrames, frames).good())
    return "unreadable: " + path;
  std::ifstream in(path, std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(in), {});
  const std::string tag("\x00\x52\x30\x92SQ", 6);  // (5200,9230) SQ, explicit VR little endian
  const std::size_t at = bytes.find(tag);
  if (at == std::string::npos) return "no per-frame functional groups: " + path;
  return std::string(frames.c_str()) + " frames\n" + bytes.substr(at);
}

// The lines of dicom3tools' dciodvfy (the standard's IOD and attribute checks) on `path` that
// say Error; "dciodvfy failed" when it did not run.
inline std::string dciodvfyErrors(const std::string& path) {
  const std::string command = "dciodvfy '" + path + "' 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return "dciodvfy failed";
  std::string out;
  char line[4096];
  while (std::fgets(line, sizeof line, pipe))
    if (std::string(line).find("Error") != std::string::npos) out += line;
  const int status = pclose(pipe);
  return status == -1 || (out.empty() && status != 0)
             ? "dciodvfy failed (" + std::to_string(status) + ")"
             : out;
}

}  // namespace repose::test

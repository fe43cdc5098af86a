#include "DicomScreen.h"

#include "repose/util/Error.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace repose::io {

namespace {

// VRs whose explicit-VR header has two reserved bytes and a 32-bit length.
bool longVr(const char vr[2]) {
  static const char* kLong[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                "SV", "UC", "UN", "UR", "UT", "UV"};
  for (const char* v : kLong)
    if (vr[0] == v[0] && vr[1] == v[1]) return true;
  return false;
}

bool looksLikeVr(const unsigned char* b) {
  return b[0] >= 'A' && b[0] <= 'Z' && b[1] >= 'A' && b[1] <= 'Z';
}

std::uint16_t u16(const unsigned char* b, bool big) {
  return big ? std::uint16_t(b[0] << 8 | b[1]) : std::uint16_t(b[1] << 8 | b[0]);
}
std::uint32_t u32(const unsigned char* b, bool big) {
  return big ? std::uint32_t(b[0]) << 24 | std::uint32_t(b[1]) << 16 | std::uint32_t(b[2]) << 8 |
                   b[3]
             : std::uint32_t(b[3]) << 24 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[1]) << 8 |
                   b[0];
}

std::string tagName(std::uint16_t group, std::uint16_t element) {
  char s[16];
  std::snprintf(s, sizeof s, "(%04X,%04X)", group, element);
  return s;
}

}  // namespace

bool screenDicomFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return true;  // GDCM reports unreadable files
  in.seekg(0, std::ios::end);
  const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
  unsigned char head[132];
  in.seekg(0);
  std::uint64_t pos = 0;
  if (size >= 132 && in.read(reinterpret_cast<char*>(head), 132) &&
      std::memcmp(head + 128, "DICM", 4) == 0)
    pos = 132;
  bool explicitVr = true, bigEndian = false, inMeta = pos == 132, looksDicom = pos == 132;
  std::string syntax;
  while (pos + 8 <= size) {
    unsigned char h[12];
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    const std::uint64_t avail = std::min<std::uint64_t>(12, size - pos);
    if (!in.read(reinterpret_cast<char*>(h), static_cast<std::streamsize>(avail))) return true;
    // The file meta group is explicit VR little endian; the data set follows its transfer syntax.
    bool big = inMeta ? false : bigEndian;
    std::uint16_t group = u16(h, big);
    if (inMeta && group != 0x0002) {
      inMeta = false;
      if (syntax == "1.2.840.10008.1.2.1.99") return true;  // deflated: GDCM inflates it
      explicitVr = syntax != "1.2.840.10008.1.2";
      bigEndian = syntax == "1.2.840.10008.1.2.2";
      big = bigEndian;
      group = u16(h, big);
    }
    const std::uint16_t element = u16(h + 2, big);
    if (pos == 0) {
      // No preamble: DICOM only if it starts with a meta or identifying group; guess the VR mode.
      looksDicom = group == 0x0002 || group == 0x0008;
      explicitVr = looksLikeVr(h + 4);
      inMeta = group == 0x0002;
    }
    if (!looksDicom) return false;
    std::uint64_t header = 8, length = 0;
    if (group == 0xFFFE) {  // item and delimiters: no VR in any transfer syntax
      length = u32(h + 4, big);
    } else if ((explicitVr || inMeta) && looksLikeVr(h + 4)) {
      const char vr[2] = {char(h[4]), char(h[5])};
      if (longVr(vr)) {
        if (avail < 12) return true;
        header = 12;
        length = u32(h + 8, big);
      } else {
        length = u16(h + 6, big);
      }
    } else {
      // Implicit VR, or an explicit-VR element whose VR bytes are not letters: GDCM then reads a
      // 32-bit length after the tag, as implicit VR does, so the same is checked here.
      length = u32(h + 4, big);
    }
    pos += header;
    // Undefined length: walk into the sequence or item (or the fragments of encapsulated pixel
    // data, whose items are then skipped whole: their bytes are compressed data, not elements).
    if (length == 0xFFFFFFFFu) continue;
    if (length > size - pos)
      throwFileError(path, "truncated or corrupt DICOM: element " + tagName(group, element) +
                               " claims " + std::to_string(length) + " bytes, " +
                               std::to_string(size - pos) + " remain");
    if (inMeta && group == 0x0002 && element == 0x0010 && length < 128) {
      char uid[128] = {};
      in.clear();
      in.seekg(static_cast<std::streamoff>(pos));
      in.read(uid, static_cast<std::streamsize>(length));
      syntax.assign(uid, static_cast<std::size_t>(length));
      while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' ')) syntax.pop_back();
    }
    pos += length;
  }
  return looksDicom;
}

}  // namespace repose::io

// A NRRD header checked line by line before teem reads it. teem (Debian 12's libteem 1.12) is the
// NRRD reader, as in Slicer, but on some corrupt headers it overflows a stack buffer or leaks what
// it allocated; each case here was found by Testing/Fuzz/FuzzNrrd or FuzzSegNrrd. A header that
// passes is read by teem, which still decides everything else (and reports what it refuses).
#pragma once

#include <string>

namespace repose::io {

// Throws repose::Error naming `path` and the header line at fault when the header is one of:
// - not NRRD: the first line is not the magic NRRD0001 to NRRD0005 (teem would try its other
//   formats, and its plain-text reader leaks on a malformed line);
// - a line holding a NUL byte, or a field line longer than 800 characters (teem formats an
//   unparseable field into a fixed stack buffer);
// - a per-axis field (sizes ... kinds, units, a "data file" list or template) before
//   "dimension", or a space field (space directions, origin, units, measurement frame) before
//   "space" or "space dimension": the NRRD format needs them first, and teem leaks on the
//   centers, kinds and data-file cases;
// - labels, units or space units that are not exactly one closed quoted string per axis (per
//   space axis for space units): teem leaks an unclosed string and a surplus one.
void checkNrrdHeader(const std::string& path);

}  // namespace repose::io

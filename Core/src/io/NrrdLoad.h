// teem's nrrdLoad for NRRD files alone, without its leak. nrrdLoad's inner reader (_nrrdRead) keeps
// a cleanup list that it does not free when a header parses but fails teem's consistency check
// (nrrdCheck: a kind that does not fit its axis size, and the like): 88 bytes per such file (found
// by Testing/Fuzz/FuzzSegNrrd with leak checking). This does what nrrdLoad does for a file whose
// magic was checked (NrrdHeaderCheck.h): teem's own NRRD format reader, then teem's check, and
// nothing left allocated on any path.
#pragma once

#include <teem/nrrd.h>

#include <string>

namespace repose::io {

// Reads the NRRD file `path` into `nrrd` (fresh from nrrdNew) with `nio` (its skipData and
// keepNrrdDataFileOpen honoured, as nrrdLoad does). Returns 0, or 1 with teem's message in biff
// (NRRD key), like nrrdLoad. The first line of the file must be the NRRD magic.
int loadNrrd(Nrrd* nrrd, const std::string& path, NrrdIoState* nio);

}  // namespace repose::io

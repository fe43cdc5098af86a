// The FDTD voxel model on disk, for openEMS: MODEL.h5 in the HDF5 layout CSXCAD's discrete
// material reads (CSPropDiscMaterial: /DiscData uint8 cells x fastest with the attributes DB_Size,
// epsR, kappa, density; /mesh/x|y|z cell boundaries in metres; root attribute Version 2), and
// beside it MODEL.csx.xml (a ContinuousStructure holding the DiscMaterial over a box of the
// model, grid lines on the cell boundaries in mm, for openEMS's CSX.ReadFromXML) and MODEL.json
// (frequency, materials, volumes and masses per tissue and per label). Written together or not
// at all (docs/FORMATS.md).
#pragma once

#include "repose/dosimetry/FdtdModel.h"

#include <map>
#include <string>

namespace repose {

struct FdtdModelFiles {
  std::string model, csx, report;  // .h5, .csx.xml, .json
};

// MODEL.h5 -> MODEL.csx.xml and MODEL.json; throws repose::Error unless the path ends in .h5.
FdtdModelFiles fdtdModelFiles(const std::string& h5Path);

struct FdtdWriteInfo {
  std::string input;         // G's file, for the report
  std::string tissueSource;  // where names and densities came from
  std::vector<std::string> warnings;
};

// Writes the three files; returns MODEL.json's text. Throws repose::Error naming the file.
std::string writeFdtdModel(const FdtdModel& model, const std::map<int, LabelTissue>& labels,
                           const std::string& h5Path, const FdtdWriteInfo& info);

}  // namespace repose

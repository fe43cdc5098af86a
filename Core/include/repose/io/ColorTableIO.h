// 3D Slicer colour tables (.ctbl): the names and colours of a label map written beside a file
// format that cannot carry them where Slicer looks (a NIfTI label map opens as grey values).
#pragma once

#include "repose/volume/Volume.h"

#include <string>
#include <vector>

namespace repose {

// Writes layer 0 of the label map's table, and every value present that the table does not name
// (generated name "label_<value>" and colour), as Slicer's vtkMRMLColorTableStorageNode reads a
// .ctbl or .txt:
// "# Color table file <path>", "# <N> values" (N = highest value + 1), then one line
// "value name R G B A" per label with colours 0-255, value 0 "Background" transparent. Spaces in
// names become '_' (Slicer turns '_' back into spaces). Atomic. Throws repose::Error naming the
// file for a negative label value (a colour table cannot index it).
void writeColorTable(const Volume& labelMap, const std::string& path);
// The same from a label table and the values present in layer 0 (a map written slab by slab).
void writeColorTable(const LabelTable& labels, const std::vector<int>& present,
                     const std::string& path);

// Reads a Slicer colour table file (.ctbl or .txt; parseColorTable): what writeColorTable
// writes, or Slicer's own tables such as GenericAnatomyColors.txt. Throws repose::Error naming
// the file (and the line) when it cannot be read.
LabelTable readColorTable(const std::string& path);

}  // namespace repose

// The label table in a NIfTI header extension: Caret/GIFTI XML (<LabelTable><Label Key=...>),
// as TotalSegmentator and Connectome Workbench write it with ecode 0.
#pragma once

#include "repose/volume/LabelTable.h"

#include <string>

namespace repose::nifti {

// Labels found in the XML text (empty table when there is no LabelTable). Key 0 is skipped.
LabelTable parseCaretLabelTable(const std::string& xml);
// XML text for the labels of layer 0, readable by parseCaretLabelTable and by Caret tools.
std::string formatCaretLabelTable(const LabelTable& labels);

}  // namespace repose::nifti

// The SlicerExecutionModel descriptions of `repose pose` and `repose warp` as 3D Slicer CLI
// modules (`repose pose --xml`): typed parameters Slicer builds a panel from, whose long flags are
// the commands' own options (camelCase where the option has a hyphen: ArgParser accepts both).
#pragma once

#include <string>
#include <vector>

namespace repose::cli {

// The XML Slicer reads from `<executable> --xml` (ModuleDescriptionParser.cxx) for "pose" or
// "warp", else "".
std::string slicerModuleXml(const std::string& command);

// 3D Slicer asks a CLI module for its description with the single argument --xml: prints it and
// returns true when `args` is exactly that.
bool printSlicerModuleXml(const std::vector<std::string>& args, const std::string& command);

}  // namespace repose::cli

#include "vtkSlicerReposeLogicRead.h"

#include <repose/io/VolumeIO.h>
#include <repose/rig/LabelConvention.h>
#include <repose/util/Error.h>
#include <repose/util/Memory.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

namespace vtkSlicerReposeLogicRead {

std::string FileStem(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  for (const std::string ext : {".nii.gz", ".seg.nrrd", ".pose.json", ".nii", ".nrrd", ".nhdr"})
    if (name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0)
      return name.substr(0, name.size() - ext.size());
  return name;
}

repose::Volume ReadVolume(const std::string& path, std::vector<std::string>* notes) {
  repose::ReadOptions options;
  if (notes) options.note = [notes](const std::string& n) { notes->push_back(n); };
  options.memoryLimitBytes = repose::memoryLeftWithin();
  options.budgetHint =
      "the workbench reads within half the physical memory; free memory, or use the command "
      "line's --memory";
  return repose::readVolume(path, options);
}

std::string NameLabels(repose::Volume& labels, const std::string& tissuesPath,
                       const std::string& source, const std::vector<repose::LabelCount>* counts) {
  std::optional<repose::TissueTable> tissues;
  if (!tissuesPath.empty()) {
    try {
      tissues = repose::readTissueTable(tissuesPath);
    } catch (const repose::Error&) {
      // The pose job reports a broken table; names then come from the convention.
    }
  }
  return repose::completeLabelNamesAndColors(labels, tissues ? &*tissues : nullptr, source, counts);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw repose::Error(path + ": cannot open");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string FilesStamp(const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  std::string stamp;
  for (const std::string& path : paths) {
    stamp += path;
    if (!path.empty()) {
      std::error_code ec;
      const fs::file_status status = fs::status(path, ec);
      if (ec || !fs::exists(status)) return "";
      // Size and time of a file; of a folder, the count, total size and latest time of its files,
      // so a series re-exported into the same folder is a different stamp.
      std::uintmax_t files = 0, bytes = 0;
      fs::file_time_type latest = fs::file_time_type::min();
      auto add = [&](const fs::path& file) {
        const std::uintmax_t size = fs::file_size(file, ec);
        const fs::file_time_type time = fs::last_write_time(file, ec);
        if (ec) return;
        ++files, bytes += size, latest = std::max(latest, time);
      };
      if (fs::is_directory(status)) {
        for (fs::recursive_directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec))
          if (it->is_regular_file(ec)) add(it->path());
      } else {
        add(path);
      }
      stamp += "\t" + std::to_string(files) + "\t" + std::to_string(bytes) + "\t" +
               std::to_string(latest.time_since_epoch().count());
    }
    stamp += "\n";
  }
  return stamp;
}

}  // namespace vtkSlicerReposeLogicRead

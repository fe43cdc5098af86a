// What `repose info` says about a volume, as JSON (the --json output) and as text for people.
#pragma once

#include "repose/io/VolumeIO.h"

#include <nlohmann/json.hpp>

namespace repose::cli {

nlohmann::json describeVolume(const Volume& volume, const std::string& path);
std::string formatVolumeText(const nlohmann::json& description);

}  // namespace repose::cli

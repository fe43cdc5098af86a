// Reading a JSON file's fields with one-line errors that name the file and the field
// ("<source>: <field>: <problem>"), as pose files and skeletons are read.
#pragma once

#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include <cmath>
#include <string>

namespace repose {

struct JsonFields {
  std::string source;
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw Error(source + ": " + field + ": " + problem);
  }
  double number(const nlohmann::json& j, const std::string& field) const {
    if (!j.is_number()) fail(field, "expected a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(field, "not a finite number");
    return v;
  }
  std::string string(const nlohmann::json& j, const std::string& field) const {
    if (!j.is_string()) fail(field, "expected a string");
    return j.get<std::string>();
  }
  Eigen::Vector3d vector3(const nlohmann::json& j, const std::string& field) const {
    if (!j.is_array() || j.size() != 3) fail(field, "expected an array of 3 numbers");
    return {number(j[0], field + "[0]"), number(j[1], field + "[1]"), number(j[2], field + "[2]")};
  }
};

}  // namespace repose

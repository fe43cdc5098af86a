// A small declarative argument parser for the `repose` subcommands: options, flags and
// positionals declared once, so `--help` and the errors come from the same declarations.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace repose::cli {

class ArgParser {
 public:
  ArgParser(std::string command, std::string summary);
  // An option taking a value (`--voxel 2` or `--voxel=2`); def is shown in help when not empty.
  ArgParser& option(const std::string& name, const std::string& metavar, const std::string& help,
                    const std::string& def = "");
  ArgParser& flag(const std::string& name, const std::string& help);
  ArgParser& positional(const std::string& name, const std::string& help);

  // Returns false when --help was asked (help printed to stdout). Throws UsageError.
  bool parse(const std::vector<std::string>& args);
  std::string help() const;

  bool has(const std::string& name) const;          // option given, or flag set
  std::string get(const std::string& name) const;   // value or default; positionals by name
  double getDouble(const std::string& name) const;  // UsageError naming the option if not a number
  long getInt(const std::string& name) const;
  // A number, or nothing when the value is `word` (a default decided elsewhere, e.g. "min").
  std::optional<double> getDoubleUnless(const std::string& name, const std::string& word) const;

 private:
  struct Spec {
    std::string name, metavar, help, def;
    bool isFlag = false;
  };
  std::string command_, summary_;
  std::vector<Spec> options_;
  std::vector<Spec> positionals_;
  std::map<std::string, std::string> values_;
};

// Thrown where another process reports the failure (the ranks other than 0 of `warp --mpi`):
// main exits with `code` and prints nothing.
struct QuietExit {
  int code = 1;
};

struct UsageError {
  std::string message;
};

// "A:B" with two different positive integers (body-part labels); UsageError naming `option`.
std::pair<int, int> parseLabelPair(const std::string& text, const std::string& option);

}  // namespace repose::cli

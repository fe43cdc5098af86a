#include "ArgParser.h"

#include <cctype>

#include <cstdlib>
#include <iostream>
#include <sstream>

namespace repose::cli {

ArgParser::ArgParser(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {
  flag("help", "show this help and exit");
}

ArgParser& ArgParser::option(const std::string& name, const std::string& metavar,
                             const std::string& help, const std::string& def) {
  options_.push_back({name, metavar, help, def, false});
  return *this;
}

ArgParser& ArgParser::flag(const std::string& name, const std::string& help) {
  options_.push_back({name, "", help, "", true});
  return *this;
}

ArgParser& ArgParser::positional(const std::string& name, const std::string& help) {
  positionals_.push_back({name, "", help, "", false});
  return *this;
}

namespace {

std::string kebabCase(const std::string& camel) {
  std::string out;
  for (char c : camel) {
    if (std::isupper(static_cast<unsigned char>(c))) {
      out += '-';
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

bool ArgParser::parse(const std::vector<std::string>& args) {
  std::size_t nextPositional = 0;
  for (std::size_t a = 0; a < args.size(); ++a) {
    const std::string& arg = args[a];
    if (arg.size() > 2 && arg.compare(0, 2, "--") == 0) {
      std::string name = arg.substr(2), value;
      bool inlineValue = false;
      if (auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        inlineValue = true;
      }
      const Spec* spec = nullptr;
      for (const Spec& s : options_)
        if (s.name == name) spec = &s;
      // 3D Slicer passes a CLI module's long flags as declared in its XML, where a flag must be
      // an identifier (ModuleDescriptionParser.cxx): --cageVertices stands for --cage-vertices.
      if (!spec) {
        const std::string kebab = kebabCase(name);
        for (const Spec& s : options_)
          if (s.name == kebab) spec = &s;
        if (spec) name = kebab;
      }
      if (!spec) throw UsageError{"unknown option --" + name};
      if (spec->isFlag) {
        if (inlineValue) throw UsageError{"--" + name + " takes no value"};
        values_[name] = "1";
      } else {
        if (!inlineValue) {
          if (a + 1 >= args.size()) throw UsageError{"--" + name + " needs a value"};
          value = args[++a];
        }
        values_[name] = value;
      }
      if (name == "help") {
        std::cout << help();
        return false;
      }
    } else {
      if (nextPositional >= positionals_.size())
        throw UsageError{"unexpected argument '" + arg + "'"};
      values_[positionals_[nextPositional++].name] = arg;
    }
  }
  if (nextPositional < positionals_.size())
    throw UsageError{"missing " + positionals_[nextPositional].name};
  return true;
}

std::string ArgParser::help() const {
  std::ostringstream out;
  out << "usage: repose " << command_;
  for (const Spec& p : positionals_) out << " " << p.name;
  out << " [options]\n\n" << summary_ << "\n";
  if (!positionals_.empty()) {
    out << "\narguments:\n";
    for (const Spec& p : positionals_) out << "  " << p.name << "\n      " << p.help << "\n";
  }
  out << "\noptions:\n";
  for (const Spec& s : options_) {
    out << "  --" << s.name;
    if (!s.isFlag) out << " " << s.metavar;
    out << "\n      " << s.help;
    if (!s.def.empty()) out << " (default: " << s.def << ")";
    out << "\n";
  }
  return out.str();
}

bool ArgParser::has(const std::string& name) const {
  return values_.count(name) > 0;
}

std::string ArgParser::get(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  for (const Spec& s : options_)
    if (s.name == name) return s.def;
  return "";
}

double ArgParser::getDouble(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0')
    throw UsageError{"--" + name + " expects a number, got '" + v + "'"};
  return d;
}

std::optional<double> ArgParser::getDoubleUnless(const std::string& name,
                                                 const std::string& word) const {
  if (get(name) == word) return std::nullopt;
  const std::string v = get(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0')
    throw UsageError{"--" + name + " expects a number or '" + word + "', got '" + v + "'"};
  return d;
}

long ArgParser::getInt(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const long n = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0')
    throw UsageError{"--" + name + " expects a whole number, got '" + v + "'"};
  return n;
}

std::pair<int, int> parseLabelPair(const std::string& text, const std::string& option) {
  const auto colon = text.find(':');
  const UsageError error{"--" + option + " expects two different positive labels A:B, got '" +
                         text + "'"};
  if (colon == std::string::npos) throw error;
  char* end1 = nullptr;
  char* end2 = nullptr;
  const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
  const long la = std::strtol(a.c_str(), &end1, 10), lb = std::strtol(b.c_str(), &end2, 10);
  if (a.empty() || b.empty() || *end1 || *end2 || la <= 0 || lb <= 0 || la == lb || la > 65535 ||
      lb > 65535)
    throw error;
  return {static_cast<int>(la), static_cast<int>(lb)};
}

}  // namespace repose::cli

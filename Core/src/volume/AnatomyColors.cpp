// Anatomy colours: the rules parsed once, matched by name; the class colour shaded in HSV.
#include "repose/volume/AnatomyColors.h"

#include "AnatomyColorRules.h"  // generated from Resources/Colors/anatomy_colors.csv
#include "repose/util/Error.h"
#include "repose/util/NameMatch.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace repose {
namespace {

struct ColorRule {
  std::string pattern;
  std::array<double, 3> rgb;
};

const std::vector<ColorRule>& rules() {
  static const std::vector<ColorRule> parsed = [] {
    std::vector<ColorRule> out;
    std::istringstream in(kAnatomyColorRulesCsv);
    std::string line;
    bool header = true;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      if (header) {  // pattern,red,green,blue
        header = false;
        continue;
      }
      // The pattern may hold commas (ICRP's names do): the colour is the last three fields.
      std::array<double, 3> rgb{};
      std::size_t end = line.size();
      for (int k = 2; k >= 0; --k) {
        const std::size_t comma = line.rfind(',', end - 1);
        if (comma == std::string::npos) throw std::logic_error("anatomy_colors.csv: " + line);
        rgb[std::size_t(k)] = std::stod(line.substr(comma + 1, end - comma - 1)) / 255.0;
        end = comma;
      }
      out.push_back({line.substr(0, end), rgb});
    }
    return out;
  }();
  return parsed;
}

const ColorRule* ruleFor(const std::string& name) {
  const std::string key = normalizedLabelName(name);
  if (key.empty()) return nullptr;
  for (const ColorRule& r : rules())
    if (globMatches(r.pattern, key)) return &r;
  return nullptr;
}

double fraction(double x) {
  return x - std::floor(x);
}

std::array<double, 3> toHsv(const std::array<double, 3>& rgb) {
  const double mx = std::max({rgb[0], rgb[1], rgb[2]}), mn = std::min({rgb[0], rgb[1], rgb[2]});
  const double d = mx - mn;
  double h = 0;
  if (d > 0) {
    if (mx == rgb[0])
      h = std::fmod((rgb[1] - rgb[2]) / d + 6, 6.0);
    else if (mx == rgb[1])
      h = (rgb[2] - rgb[0]) / d + 2;
    else
      h = (rgb[0] - rgb[1]) / d + 4;
  }
  return {h * 60, mx > 0 ? d / mx : 0, mx};
}

// The reference table by normalised name; loaded from $REPOSE_COLOR_TABLE until set in code.
struct ReferenceColors {
  std::mutex mutex;
  bool set = false;
  std::map<std::string, std::array<double, 3>> byName;
};
ReferenceColors& reference() {
  static ReferenceColors r;
  return r;
}

// A version folder's numbers ("Slicer-5.10" -> {5, 10}), compared as numbers, not text.
std::vector<int> versionOf(const std::string& folderName) {
  std::vector<int> numbers;
  std::size_t at = folderName.find('-');
  while (at != std::string::npos && at + 1 < folderName.size()) {
    std::size_t end = at + 1;
    while (end < folderName.size() && std::isdigit(static_cast<unsigned char>(folderName[end])))
      ++end;
    if (end == at + 1) break;
    int n = 0;  // capped, so a folder named with a long run of digits cannot overflow
    for (std::size_t d = at + 1; d < end; ++d) n = std::min(n * 10 + (folderName[d] - '0'), 99999);
    numbers.push_back(n);
    at = end < folderName.size() && folderName[end] == '.' ? end : std::string::npos;
  }
  return numbers;
}

// The newest of the colour files offered, by their share/Slicer-X.Y folder's version.
struct NewestColorFile {
  std::string file;  // "" until one is offered
  std::vector<int> version;
  void offer(const std::string& candidate, const std::vector<int>& candidateVersion) {
    if (!candidate.empty() && (file.empty() || candidateVersion > version))
      file = candidate, version = candidateVersion;
  }
};

// In one Slicer installation (its top folder, or a macOS bundle's Contents), the newest
// share/Slicer-X.Y/ColorFiles/<name> (file "" when there is none).
NewestColorFile colorFileIn(const std::filesystem::path& root, const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  NewestColorFile newest;
  for (const fs::path& top : {root, root / "Contents"})
    for (fs::directory_iterator it(top / "share", ec), end; !ec && it != end; it.increment(ec)) {
      const std::string folder = it->path().filename().string();
      if (folder.rfind("Slicer-", 0) != 0) continue;
      const fs::path file = it->path() / "ColorFiles" / name;
      if (fs::is_regular_file(file, ec)) newest.offer(file.string(), versionOf(folder));
    }
  return newest;
}

}  // namespace

std::string findSlicerColorTable(const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // The installation that launched us (Slicer's launcher sets SLICER_HOME for what it starts).
  if (const char* home = std::getenv("SLICER_HOME"); home && *home)
    if (std::string f = colorFileIn(home, name).file; !f.empty()) return f;
  // The Slicer on the PATH (often a link to the installation's launcher).
  if (const char* path = std::getenv("PATH")) {
    std::stringstream dirs(path);
    for (std::string dir; std::getline(dirs, dir, ':');) {
      if (dir.empty()) continue;
      const fs::path launcher = fs::path(dir) / "Slicer";
      if (!fs::exists(launcher, ec)) continue;
      const fs::path real = fs::canonical(launcher, ec);
      if (ec) continue;
      for (const fs::path& root : {real.parent_path(), real.parent_path().parent_path()})
        if (std::string f = colorFileIn(root, name).file; !f.empty()) return f;
    }
  }
  // Where the installers put it: a Slicer* folder in /opt, /usr/local, the home folder or its
  // Applications, or /Applications (macOS); the newest version among them.
  std::vector<fs::path> places{"/opt", "/usr/local", "/Applications"};
  if (const char* h = std::getenv("HOME"); h && *h)
    places.push_back(h), places.push_back(fs::path(h) / "Applications");
  NewestColorFile newest;
  for (const fs::path& place : places)
    for (fs::directory_iterator it(place, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().filename().string().rfind("Slicer", 0) != 0 || !it->is_directory(ec)) continue;
      const NewestColorFile in = colorFileIn(it->path(), name);
      newest.offer(in.file, in.version);
    }
  return newest.file;
}

namespace {

void fill(ReferenceColors& r, const LabelTable& table) {
  r.byName.clear();
  for (const Label& l : table.labels())
    if (l.value != 0 && !l.name.empty()) r.byName.emplace(normalizedLabelName(l.name), l.color);
  r.set = true;
}

}  // namespace

LabelTable parseColorTable(const std::string& text, const std::string& source) {
  LabelTable table;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    auto fail = [&](const std::string& why) {
      throw Error(source + ": line " + std::to_string(number) + ": " + why);
    };
    std::istringstream fields(line);
    Label l;
    std::string name;
    double rgb[3];
    if (!(fields >> l.value >> name >> rgb[0] >> rgb[1] >> rgb[2]))
      fail("expected \"value name R G B A\"");
    for (int k = 0; k < 3; ++k) {
      if (!(rgb[k] >= 0 && rgb[k] <= 255)) fail("a colour is 0 to 255");
      l.color[std::size_t(k)] = rgb[k] / 255.0;
    }
    std::replace(name.begin(), name.end(), '_', ' ');
    l.name = name;
    if (table.find(l.value)) fail("value " + std::to_string(l.value) + " listed twice");
    table.set(l);
  }
  return table;
}

void setReferenceColors(const LabelTable& table) {
  ReferenceColors& r = reference();
  const std::lock_guard<std::mutex> lock(r.mutex);
  fill(r, table);
}

void useReferenceColorsFromEnvironment() {
  ReferenceColors& r = reference();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.byName.clear();
  r.set = false;
}

std::optional<std::array<double, 3>> referenceColor(const std::string& name) {
  ReferenceColors& r = reference();
  const std::lock_guard<std::mutex> lock(r.mutex);
  if (!r.set) {
    // $REPOSE_COLOR_TABLE, else Slicer's own table when Slicer is installed; set but empty:
    // none (the rules alone).
    const char* named = std::getenv("REPOSE_COLOR_TABLE");
    const std::string path = named ? std::string(named) : findSlicerColorTable();
    if (path.empty()) {
      r.set = true;
    } else {
      const std::string source = path + (named ? " (REPOSE_COLOR_TABLE)" : " (3D Slicer's)");
      std::ifstream file(path);
      if (!file) throw Error(path + ": cannot open" + (named ? " (REPOSE_COLOR_TABLE)" : ""));
      std::stringstream text;
      text << file.rdbuf();
      fill(r, parseColorTable(text.str(), named ? path : source));
    }
  }
  const auto it = r.byName.find(normalizedLabelName(name));
  if (it == r.byName.end()) return std::nullopt;
  return it->second;
}

std::optional<std::array<double, 3>> anatomyColor(const std::string& name, int value, int variant) {
  if (variant == 0)
    if (const auto exact = referenceColor(name)) return exact;
  const ColorRule* rule = ruleFor(name);
  if (!rule) return std::nullopt;
  // Three low-discrepancy walks over the value (golden ratio, sqrt 2, 1/pi fractions) shade
  // brightness, hue and saturation around the class colour: labels of one class (ICRP 110's
  // dozens of bones, four vessel regions) differ in some direction even when their values are
  // close, and the class stays recognisable (hue within +-14 degrees).
  const double seed = value + 1013.0 * variant;
  const double a = fraction(seed * 0.6180339887), b = fraction(seed * 0.4142135624),
               c = fraction(seed * 0.3183098862);
  const std::array<double, 3> hsv = toHsv(rule->rgb);
  const double v = std::clamp(hsv[2] * (0.74 + 0.36 * a), 0.12, 1.0);
  const double s = std::clamp(hsv[1] * (0.7 + 0.6 * c) + 0.04 * (c - 0.5), 0.0, 1.0);
  return hsvToRgb(hsv[0] + 28 * (b - 0.5), s, v);
}

std::array<double, 3> hsvToRgb(double h, double s, double v) {
  h = std::fmod(std::fmod(h, 360.0) + 360.0, 360.0) / 60.0;
  const double c = v * s, x = c * (1 - std::fabs(std::fmod(h, 2.0) - 1)), m = v - c;
  std::array<double, 3> rgb{};
  switch (static_cast<int>(h)) {
    case 0:
      rgb = {c, x, 0};
      break;
    case 1:
      rgb = {x, c, 0};
      break;
    case 2:
      rgb = {0, c, x};
      break;
    case 3:
      rgb = {0, x, c};
      break;
    case 4:
      rgb = {x, 0, c};
      break;
    default:
      rgb = {c, 0, x};
      break;
  }
  for (double& ch : rgb) ch = std::clamp(ch + m, 0.0, 1.0);
  return rgb;
}

std::string anatomyColorRule(const std::string& name) {
  const ColorRule* rule = ruleFor(name);
  return rule ? rule->pattern : "";
}

}  // namespace repose

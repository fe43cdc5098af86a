#include "repose/pose/Sweep.h"

#include "repose/pose/PoseFrame.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

namespace repose {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ListLine {
  int number;
  fs::path path;
};

// The list's entries, relative paths taken from the list's folder.
std::vector<ListLine> readList(const std::string& listPath) {
  std::ifstream in(listPath);
  if (!in) throwFileError(listPath, "cannot be read");
  const fs::path base = fs::absolute(listPath).parent_path();
  std::vector<ListLine> out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    fs::path p = line.substr(first, last - first + 1);
    out.push_back({number, (p.is_absolute() ? p : base / p).lexically_normal()});
  }
  if (out.empty()) throwFileError(listPath, "lists nothing");
  return out;
}

[[noreturn]] void listError(const std::string& listPath, int line, const std::string& problem) {
  throw Error(listPath + ":" + std::to_string(line) + ": " + problem);
}

void requireUniqueName(std::set<std::string>& names, const std::string& name,
                       const std::string& listPath, int line) {
  if (!names.insert(name).second)
    listError(listPath, line, "a second entry named \"" + name + "\" (outputs go by name)");
}

}  // namespace

std::vector<SweepSubject> readSweepSubjects(const std::string& listPath) {
  std::vector<SweepSubject> out;
  std::set<std::string> names;
  for (const ListLine& l : readList(listPath)) {
    if (!fs::is_directory(l.path))
      listError(listPath, l.number, l.path.string() + " is not a folder");
    SweepSubject s;
    s.folder = l.path.string();
    s.name = l.path.filename().string();
    requireUniqueName(names, s.name, listPath, l.number);
    s.parts = (l.path / "S.nii.gz").string();
    if (!fs::exists(s.parts))
      listError(listPath, l.number,
                l.path.string() + " has no S.nii.gz (rig it: repose rig --input G --out FOLDER)");
    for (const char* g : {"G.nii.gz", "G.nii", "G.nrrd", "G.seg.nrrd", "G.dcm"}) {
      if (fs::exists(l.path / g)) {
        s.organs = (l.path / g).string();
        break;
      }
    }
    if (s.organs.empty() && fs::exists(l.path / "rig.json")) {
      std::ifstream rig(l.path / "rig.json");
      const json j = json::parse(rig, nullptr, false);
      if (j.is_object() && j.contains("input") && j["input"].is_string()) {
        fs::path input = j["input"].get<std::string>();
        if (!input.is_absolute()) input = l.path / input;
        if (fs::exists(input)) s.organs = input.lexically_normal().string();
      }
    }
    if (s.organs.empty())
      listError(listPath, l.number,
                l.path.string() + " has no G.nii.gz (nor a rig.json naming an existing input)");
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<SweepPose> readSweepPoses(const std::string& listPath) {
  std::vector<SweepPose> out;
  std::set<std::string> names;
  for (const ListLine& l : readList(listPath)) {
    if (!fs::is_regular_file(l.path))
      listError(listPath, l.number, l.path.string() + " is not a file");
    std::string name = l.path.filename().string();
    for (const std::string ext : {".pose.json", ".json"}) {
      if (name.size() > ext.size() &&
          name.compare(name.size() - ext.size(), ext.size(), ext) == 0) {
        name.resize(name.size() - ext.size());
        break;
      }
    }
    requireUniqueName(names, name, listPath, l.number);
    out.push_back({name, l.path.string()});
  }
  return out;
}

std::string sweepJobFolder(const std::string& outDir, const SweepSubject& subject,
                           const SweepPose& pose, const std::string& frameName, bool oneFrame) {
  fs::path dir = fs::path(outDir) / subject.name / pose.name;
  if (!oneFrame) dir /= frameName;
  return dir.string();
}

bool sweepJobComplete(const std::string& jobFolder, const std::string& organsPath,
                      LabelMapFiles labelMaps) {
  const fs::path dir = jobFolder;
  std::ifstream in(dir / "report.json");
  if (!in) return false;
  const json report = json::parse(in, nullptr, false);
  if (!report.is_object() || !report.contains("outputs") || !report.contains("input") ||
      report["input"] != organsPath)
    return false;
  std::vector<std::string> files;
  for (const auto& [key, value] : report["outputs"].items()) {
    if (value.is_string()) files.push_back(value.get<std::string>());
    if (value.is_array())
      for (const json& v : value)
        if (v.is_string()) files.push_back(v.get<std::string>());
  }
  if (files.empty()) return false;
  for (const std::string& f : labelMapFileNames(labelMaps))
    if (std::find(files.begin(), files.end(), f) == files.end()) return false;
  for (const std::string& f : files) {
    std::error_code ec;
    const auto size = fs::file_size(dir / f, ec);
    if (ec || size == 0) return false;
  }
  return true;
}

std::string sweepSceneFolder(const std::string& outDir, const SweepSubject& subject,
                             const std::string& sceneKey) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a, 64 bits: stable across runs and machines
  for (unsigned char c : sceneKey) h = (h ^ c) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return (fs::path(outDir) / subject.name / "scenes" / hex).string();
}

std::string sweepRecordToJson(const SweepRecord& r) {
  json j = {{"job", r.job},       {"subject", r.subject}, {"pose", r.pose}, {"frame", r.frame},
            {"status", r.status}, {"folder", r.folder},   {"rank", r.rank}, {"seconds", r.seconds}};
  if (!r.error.empty()) j["error"] = r.error;
  if (r.bodyVolumeChangePercent) j["body_volume_change_percent"] = *r.bodyVolumeChangePercent;
  if (r.worstLabelChangePercent) j["worst_label_change_percent"] = *r.worstLabelChangePercent;
  if (r.bonesMinDice) j["bones_min_dice"] = *r.bonesMinDice;
  if (r.targetsMet) j["quality_targets_met"] = *r.targetsMet;
  return j.dump();
}

SweepRecord sweepRecordFromJson(const std::string& text) {
  const json j = json::parse(text);
  SweepRecord r;
  r.subject = j.at("subject"), r.pose = j.at("pose"), r.frame = j.at("frame");
  r.status = j.at("status"), r.folder = j.at("folder");
  r.job = j.at("job"), r.rank = j.at("rank"), r.seconds = j.at("seconds");
  if (j.contains("error")) r.error = j["error"];
  if (j.contains("body_volume_change_percent"))
    r.bodyVolumeChangePercent = j["body_volume_change_percent"].get<double>();
  if (j.contains("worst_label_change_percent"))
    r.worstLabelChangePercent = j["worst_label_change_percent"].get<double>();
  if (j.contains("bones_min_dice")) r.bonesMinDice = j["bones_min_dice"].get<double>();
  if (j.contains("quality_targets_met")) r.targetsMet = j["quality_targets_met"].get<bool>();
  return r;
}

void readSweepFigures(SweepRecord& r, const std::string& reportPath) {
  std::ifstream in(reportPath);
  const json report = json::parse(in, nullptr, false);
  if (!report.is_object()) return;
  if (report.contains("body"))
    r.bodyVolumeChangePercent = report["body"].value("volume_change_percent", 0.0);
  if (!report.contains("quality")) return;
  const json& q = report["quality"];
  if (q.contains("labels_within_1_percent"))
    r.worstLabelChangePercent = q["labels_within_1_percent"].value("worst_change_percent", 0.0);
  if (q.contains("bones_rigid")) r.bonesMinDice = q["bones_rigid"].value("min_dice", 0.0);
  if (q.contains("all_met")) r.targetsMet = q["all_met"].get<bool>();
}

namespace {

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(const std::optional<double>& v, int digits = 4) {
  if (!v) return "";
  std::ostringstream s;
  s.precision(digits);
  s << std::fixed << *v;
  return s.str();
}

std::string xmlText(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else
      out += c;
  }
  return out;
}

// Two bars per job (body volume change, worst label change, in %), jobs grouped by subject;
// failed jobs as a red cross on the axis.
std::string summarySvg(const std::vector<SweepRecord>& records) {
  const double barW = 9, gap = 6, groupGap = 18, left = 60, top = 40, plotH = 260;
  double lo = -1, hi = 1;
  for (const SweepRecord& r : records) {
    for (const auto& v : {r.bodyVolumeChangePercent, r.worstLabelChangePercent}) {
      if (v) lo = std::min(lo, *v), hi = std::max(hi, *v);
    }
  }
  lo = std::floor(lo), hi = std::ceil(hi);
  auto y = [&](double v) { return top + plotH * (hi - v) / (hi - lo); };
  std::ostringstream bars, labels;
  double x = left + gap;
  std::string subject;
  for (const SweepRecord& r : records) {
    if (!subject.empty() && r.subject != subject) x += groupGap;
    if (r.subject != subject) {
      labels << "<text x='" << x << "' y='" << top + plotH + 48
             << "' font-size='11' font-weight='bold'>" << xmlText(r.subject) << "</text>\n";
      subject = r.subject;
    }
    const std::string name = r.pose + (r.frame.empty() || r.frame == r.pose ? "" : "/" + r.frame);
    if (r.status == "failed") {
      bars << "<text x='" << x << "' y='" << y(0) + 4 << "' fill='#c00' font-size='14'>&#x2717;"
           << "<title>" << xmlText(name + ": " + r.error) << "</title></text>\n";
    } else {
      const std::pair<std::optional<double>, const char*> series[] = {
          {r.bodyVolumeChangePercent, "#4878a8"}, {r.worstLabelChangePercent, "#e0892a"}};
      for (int s = 0; s < 2; ++s) {
        if (!series[s].first) continue;
        const double v = *series[s].first, y0 = y(std::max(v, 0.0)), y1 = y(std::min(v, 0.0));
        bars << "<rect x='" << x + s * barW << "' y='" << y0 << "' width='" << barW << "' height='"
             << std::max(y1 - y0, 0.5) << "' fill='" << series[s].second << "'><title>"
             << xmlText(name) << ": " << number(v, 3) << " %</title></rect>\n";
      }
    }
    labels << "<text transform='translate(" << x + barW << "," << top + plotH + 6
           << ") rotate(60)' font-size='9'>" << xmlText(name) << "</text>\n";
    x += 2 * barW + gap;
  }
  const double width = std::max(x + 40, 360.0), height = top + plotH + 120;
  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << height
      << "' font-family='sans-serif'>\n<rect width='100%' height='100%' fill='white'/>\n"
      << "<text x='" << left << "' y='20' font-size='13'>Posture sweep: volume change per job "
      << "(%)</text>\n"
      << "<rect x='" << width - 190 << "' y='10' width='10' height='10' fill='#4878a8'/><text x='"
      << width - 176 << "' y='19' font-size='10'>body volume</text>\n"
      << "<rect x='" << width - 100 << "' y='10' width='10' height='10' fill='#e0892a'/><text x='"
      << width - 86 << "' y='19' font-size='10'>worst label</text>\n";
  for (double t = lo; t <= hi + 1e-9; t += std::max(1.0, std::round((hi - lo) / 8))) {
    svg << "<line x1='" << left << "' x2='" << x << "' y1='" << y(t) << "' y2='" << y(t)
        << "' stroke='" << (t == 0 ? "#000" : "#ddd") << "'/><text x='" << left - 6 << "' y='"
        << y(t) + 3 << "' font-size='10' text-anchor='end'>" << t << "</text>\n";
  }
  svg << bars.str() << labels.str() << "</svg>\n";
  return svg.str();
}

}  // namespace

std::string writeSweepSummary(const std::string& outDir, std::vector<SweepRecord> records,
                              const SweepSummary& summary) {
  std::stable_sort(records.begin(), records.end(),
                   [](const SweepRecord& a, const SweepRecord& b) { return a.job < b.job; });
  json all = json::array();
  std::map<std::string, int> byStatus;
  std::ostringstream csv;
  csv << "subject,pose,frame,status,body_volume_change_percent,worst_label_change_percent,"
         "bones_min_dice,quality_targets_met,seconds,rank,folder,error\n";
  for (const SweepRecord& r : records) {
    all.push_back(json::parse(sweepRecordToJson(r)));
    ++byStatus[r.status];
    csv << csvField(r.subject) << ',' << csvField(r.pose) << ',' << csvField(r.frame) << ','
        << r.status << ',' << number(r.bodyVolumeChangePercent) << ','
        << number(r.worstLabelChangePercent) << ',' << number(r.bonesMinDice) << ','
        << (r.targetsMet ? (*r.targetsMet ? "yes" : "no") : "") << ',' << number(r.seconds, 2)
        << ',' << r.rank << ',' << csvField(r.folder) << ',' << csvField(r.error) << '\n';
  }
  const json out = {{"ranks", summary.ranks},       {"mpi", summary.mpi},
                    {"seconds", summary.seconds},   {"jobs", records.size()},
                    {"done", byStatus["done"]},     {"skipped", byStatus["skipped"]},
                    {"failed", byStatus["failed"]}, {"records", all}};
  const fs::path dir = outDir;
  const std::string text = out.dump(2) + "\n";
  writeTextFileAtomically((dir / "sweep.json").string(), text);
  writeTextFileAtomically((dir / "sweep.csv").string(), csv.str());
  writeTextFileAtomically((dir / "sweep.svg").string(), summarySvg(records));
  return text;
}

}  // namespace repose

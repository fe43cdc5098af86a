// The cage settings tried in turn until one passes the checks (CageLadder.h).
#include "repose/cage/CageLadder.h"

#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace repose {
namespace {

constexpr int kMostVertices = 2000;  // buildCage's bound

nlohmann::json settingJson(const CageSetting& s) {
  return {{"vertices", s.vertices}, {"dilate_mm", s.dilateMm}};
}

CageSetting settingOf(const nlohmann::json& j) {
  return {j.at("vertices").get<int>(), j.at("dilate_mm").get<double>()};
}

// A dilation as the ladder gives it: a tenth of a millimetre is as fine as the cage's working
// grid (several millimetres) can tell.
double roundedMm(double mm) {
  return std::round(mm * 10) / 10;
}

}  // namespace

std::string CageChoice::json() const {
  nlohmann::json tries = nlohmann::json::array();
  for (const CageAttempt& a : tried) {
    nlohmann::json t = settingJson(a.setting);
    t["failed"] = a.failure.empty() ? nlohmann::json() : nlohmann::json(a.failure);
    tries.push_back(t);
  }
  return nlohmann::json{{"asked", settingJson(asked)},
                        {"used", settingJson(used)},
                        {"fallback", fallback()},
                        {"tried", tries}}
      .dump();
}

CageChoice CageChoice::fromJson(const std::string& text) {
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    CageChoice c;
    c.asked = settingOf(j.at("asked"));
    c.used = settingOf(j.at("used"));
    for (const nlohmann::json& t : j.at("tried")) {
      CageAttempt a;
      a.setting = settingOf(t);
      if (t.contains("failed") && t["failed"].is_string())
        a.failure = t["failed"].get<std::string>();
      c.tried.push_back(a);
    }
    return c;
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("cage choice: ") + e.what());
  }
}

CageChoice CageChoice::given(const CageSetting& setting) {
  CageChoice c;
  c.asked = c.used = setting;
  c.tried.push_back({setting, ""});
  return c;
}

std::vector<CageSetting> cageLadder(const CageSetting& asked) {
  std::vector<CageSetting> out;
  auto add = [&](int vertices, double dilateMm) {
    const CageSetting s{std::clamp(vertices, 50, kMostVertices), dilateMm};
    if (std::find(out.begin(), out.end(), s) == out.end()) out.push_back(s);
  };
  add(asked.vertices, asked.dilateMm);
  // More vertices first: the same body outline, followed more closely.
  for (const int v : {2 * asked.vertices, 1000, kMostVertices})
    if (v > asked.vertices) add(v, asked.dilateMm);
  // Then a smaller dilation (the pose's contact cuts were found for the asked one, and stay
  // within a smaller cage's reach), then a larger one, each at the asked and twice the vertices.
  for (const double factor : {0.6, 1.5}) {
    const double d = roundedMm(asked.dilateMm * factor);
    if (!(d > 0)) continue;
    add(asked.vertices, d);
    add(2 * asked.vertices, d);
  }
  return out;
}

Cage buildCageTrying(const Volume& parts, const CageOptions& options, CageChoice* choice,
                     const CageBuildFn& build) {
  CageChoice c;
  c.asked = {options.targetVertices, options.dilateMm};
  const std::vector<CageSetting> ladder = cageLadder(c.asked);
  std::string failures;
  for (std::size_t i = 0; i < ladder.size(); ++i) {
    CageOptions o = options;
    o.targetVertices = ladder[i].vertices;
    o.dilateMm = ladder[i].dilateMm;
    if (i > 0 && options.progress)
      o.progress = [&, i](double f, const std::string& stage) {
        return options.progress(f, stage + " (again with " +
                                       describeCageSetting(ladder[i].vertices, ladder[i].dilateMm) +
                                       ")");
      };
    try {
      Cage cage = build ? build(parts, o) : buildCage(parts, o);
      c.used = ladder[i];
      c.tried.push_back({ladder[i], ""});
      if (choice) *choice = c;
      return cage;
    } catch (const CageCheckError& e) {
      c.tried.push_back({ladder[i], e.failed});
      failures += (failures.empty() ? "" : "; ") +
                  describeCageSetting(ladder[i].vertices, ladder[i].dilateMm) + ": " + e.failed;
    }
  }
  throw Error("the automatic cage failed its checks at every setting tried (" + failures +
              "); give the cage another size (cage vertices, dilation)");
}

}  // namespace repose

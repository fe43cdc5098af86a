#include "repose/dosimetry/ColeCole.h"

#include "DielectricTables.h"  // generated from Resources/Dielectric/*.csv
#include "repose/util/Error.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

namespace repose {
namespace {

std::string lowerCase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double number(const std::string& text, const std::string& where, const char* column) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw Error(where + column + " must be a number, not \"" + text + "\"");
}

}  // namespace

std::complex<double> complexPermittivity(const ColeColeTissue& t, double frequencyHz) {
  const double omega = 2 * M_PI * frequencyHz;
  std::complex<double> eps = t.epsInfinity;
  for (int n = 0; n < 4; ++n) {
    if (t.delta[n] == 0) continue;
    const std::complex<double> jwt(0, omega * t.tauSeconds[n]);
    eps += t.delta[n] / (1.0 + std::pow(jwt, 1.0 - t.alpha[n]));
  }
  eps += t.ionicConductivity / std::complex<double>(0, omega * kVacuumPermittivity);
  return eps;
}

DielectricValues dielectricAt(const ColeColeTissue& t, double frequencyHz) {
  const std::complex<double> eps = complexPermittivity(t, frequencyHz);
  DielectricValues v;
  v.relativePermittivity = eps.real();
  v.conductivity = -eps.imag() * 2 * M_PI * frequencyHz * kVacuumPermittivity;
  return v;
}

std::vector<ColeColeTissue> parseColeColeTable(const std::string& csv, const std::string& source) {
  static const char* kHeader =
      "tissue,ef,sigma_S_m,del1,tau1_ps,alf1,del2,tau2_ns,alf2,del3,tau3_us,alf3,del4,tau4_ms,alf4";
  static const char* kColumns[] = {"ef",   "sigma_S_m", "del1",    "tau1_ps", "alf1",
                                   "del2", "tau2_ns",   "alf2",    "del3",    "tau3_us",
                                   "alf3", "del4",      "tau4_ms", "alf4"};
  static const double kTauUnit[4] = {1e-12, 1e-9, 1e-6, 1e-3};
  std::vector<ColeColeTissue> tissues;
  std::istringstream in(csv);
  std::string line;
  int lineNumber = 0;
  bool header = true;
  while (std::getline(in, line)) {
    ++lineNumber;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::string where = source + ":" + std::to_string(lineNumber) + ": ";
    if (header) {
      if (line != kHeader) throw Error(where + "expected the header " + kHeader);
      header = false;
      continue;
    }
    std::vector<std::string> f;
    std::stringstream row(line);
    for (std::string x; std::getline(row, x, ',');) f.push_back(x);
    if (f.size() != 15) throw Error(where + "expected 15 fields (" + kHeader + ")");
    ColeColeTissue t;
    t.name = f[0];
    if (t.name.empty()) throw Error(where + "a tissue needs a name");
    double v[14];
    for (int k = 0; k < 14; ++k) v[k] = number(f[k + 1], where, kColumns[k]);
    t.epsInfinity = v[0];
    t.ionicConductivity = v[1];
    for (int n = 0; n < 4; ++n) {
      t.delta[n] = v[2 + 3 * n];
      t.tauSeconds[n] = v[3 + 3 * n] * kTauUnit[n];
      t.alpha[n] = v[4 + 3 * n];
      if (t.delta[n] < 0 || t.tauSeconds[n] < 0 || t.alpha[n] < 0 || t.alpha[n] >= 1)
        throw Error(where + "dispersion " + std::to_string(n + 1) +
                    ": del and tau must be >= 0 and 0 <= alf < 1");
    }
    if (t.epsInfinity < 1 || t.ionicConductivity < 0)
      throw Error(where + "ef must be >= 1 and sigma_S_m >= 0");
    for (const ColeColeTissue& other : tissues)
      if (lowerCase(other.name) == lowerCase(t.name))
        throw Error(where + "tissue \"" + t.name + "\" given twice");
    tissues.push_back(std::move(t));
  }
  if (tissues.empty()) throw Error(source + ": no tissue");
  return tissues;
}

const std::vector<ColeColeTissue>& gabrielTissues() {
  static const std::vector<ColeColeTissue> table =
      parseColeColeTable(kGabrielColeColeCsv, "gabriel1996_cole_cole.csv");
  return table;
}

const ColeColeTissue* findGabrielTissue(const std::string& name) {
  const std::string key = lowerCase(name);
  for (const ColeColeTissue& t : gabrielTissues())
    if (lowerCase(t.name) == key) return &t;
  return nullptr;
}

double parseFrequencyHz(const std::string& text) {
  std::string s;
  for (const char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) s += c;
  const std::string low = lowerCase(s);
  double scale = 1;
  std::string digits = low;
  for (const auto& [suffix, factor] : std::initializer_list<std::pair<const char*, double>>{
           {"ghz", 1e9}, {"mhz", 1e6}, {"khz", 1e3}, {"hz", 1.0}}) {
    const std::string sx(suffix);
    if (low.size() > sx.size() && low.compare(low.size() - sx.size(), sx.size(), sx) == 0) {
      digits = low.substr(0, low.size() - sx.size());
      scale = factor;
      break;
    }
  }
  double value = 0;
  try {
    std::size_t used = 0;
    value = std::stod(digits, &used);
    if (used != digits.size()) value = -1;
  } catch (const std::exception&) {
    value = -1;
  }
  const double hz = value * scale;
  if (!(hz > 0) || !std::isfinite(hz))
    throw Error("frequency \"" + text +
                "\": expected a number with Hz, kHz, MHz or GHz (e.g. 900MHz)");
  if (hz < kMinDielectricFrequencyHz || hz > kMaxDielectricFrequencyHz)
    throw Error("frequency \"" + text +
                "\": outside 10 Hz to 20 GHz, the range of the tissue model (Gabriel 1996)");
  return hz;
}

}  // namespace repose

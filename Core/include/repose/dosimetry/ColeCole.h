// Dielectric properties of body tissues at a frequency, from the four-term Cole-Cole model of
// Gabriel et al. (Phys. Med. Biol. 41, 1996): eps*(w) = ef + sum_n del_n / (1 + (j w tau_n)^(1 -
// alf_n)) + sigma_i / (j w eps0). The parameters (Resources/Dielectric/gabriel1996_cole_cole.csv,
// with their source) are compiled into Core, so an installed repose keeps them.
#pragma once

#include <array>
#include <complex>
#include <string>
#include <vector>

namespace repose {

// The range the exporters accept: the model is fitted from 10 Hz to 100 GHz; above 20 GHz the
// FDTD cells of a whole body become impractical and the fits lose their measured support.
constexpr double kMinDielectricFrequencyHz = 10.0;
constexpr double kMaxDielectricFrequencyHz = 20e9;
constexpr double kVacuumPermittivity = 8.8541878128e-12;  // F/m (CODATA 2018)

struct ColeColeTissue {
  std::string name;  // Gabriel's name, e.g. "Muscle", "Bone (Cortical)"
  double epsInfinity = 1;
  double ionicConductivity = 0;                  // S/m
  std::array<double, 4> delta{0, 0, 0, 0};       // dispersion magnitudes
  std::array<double, 4> tauSeconds{0, 0, 0, 0};  // relaxation times
  std::array<double, 4> alpha{0, 0, 0, 0};       // distribution parameters
};

struct DielectricValues {
  double relativePermittivity = 1;  // Re(eps*)
  double conductivity = 0;          // S/m: -w eps0 Im(eps*), ionic and dielectric losses together
};

// The complex relative permittivity at frequencyHz (> 0).
std::complex<double> complexPermittivity(const ColeColeTissue& tissue, double frequencyHz);
DielectricValues dielectricAt(const ColeColeTissue& tissue, double frequencyHz);

// The compiled-in table, in the file's order (44 tissues of Gabriel's summary table, then Air).
const std::vector<ColeColeTissue>& gabrielTissues();
// The tissue of that name (case-insensitive), or nullptr.
const ColeColeTissue* findGabrielTissue(const std::string& name);
// Parses a table in the compiled file's layout; throws repose::Error "<source>:<line>: ...".
std::vector<ColeColeTissue> parseColeColeTable(const std::string& csv, const std::string& source);

// "900MHz", "2.45 GHz", "10 kHz", "100Hz", "9e8": the frequency in Hz. Throws repose::Error
// naming the text when it is not a positive frequency or lies outside the range above.
double parseFrequencyHz(const std::string& text);

}  // namespace repose

#include "repose/dosimetry/FdtdModelIO.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"
#include "repose/util/XmlText.h"

#include <hdf5.h>
#include <hdf5_hl.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace repose {
namespace {

// An HDF5 identifier closed on every path (the C API has no RAII of its own).
class H5Handle {
 public:
  H5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~H5Handle() {
    if (id_ >= 0) close_(id_);
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void check(bool ok, const std::string& path, const std::string& what) {
  if (!ok) throw Error(path + ": cannot write the FDTD model (" + what + ")");
}

std::string materialName(const FdtdModel& model, std::size_t m) {
  const FdtdMaterial& material = model.materials[m];
  int sameTissue = 0;
  for (const FdtdMaterial& other : model.materials) sameTissue += other.tissue == material.tissue;
  if (sameTissue <= 1) return material.tissue;
  std::ostringstream s;
  s << material.tissue << " " << material.densityKgM3 << " kg/m3";
  return s.str();
}

// HDF5 prints its own error stack to stderr by default; our one-line error says it instead.
// The process's handler is put back afterwards (another HDF5 user may rely on it).
class QuietHdf5Errors {
 public:
  QuietHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &function_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, function_, data_); }
  QuietHdf5Errors(const QuietHdf5Errors&) = delete;
  QuietHdf5Errors& operator=(const QuietHdf5Errors&) = delete;

 private:
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
};

void writeHdf5(const FdtdModel& model, const std::string& path, const std::string& finalPath) {
  const QuietHdf5Errors quiet;
  H5Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  check(file.ok(), finalPath, "create");
  const double version = 2.0;
  check(H5LTset_attribute_double(file.get(), "/", "Version", &version, 1) >= 0, finalPath,
        "Version");
  const double frequency = model.frequencyHz;
  check(H5LTset_attribute_double(file.get(), "/", "frequency_Hz", &frequency, 1) >= 0, finalPath,
        "frequency");
  {
    H5Handle mesh(H5Gcreate2(file.get(), "/mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    check(mesh.ok(), finalPath, "/mesh");
    static const char* kAxes[] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      std::vector<float> metres;
      for (const double mm : model.lines(a)) metres.push_back(float(mm * 1e-3));
      const hsize_t n = metres.size();
      check(H5LTmake_dataset_float(mesh.get(), kAxes[a], 1, &n, metres.data()) >= 0, finalPath,
            std::string("/mesh/") + kAxes[a]);
    }
  }
  // The cells, z slowest and x fastest as CSXCAD indexes them; chunked by slice and deflated
  // (whole-body grids are mostly runs of one material).
  const hsize_t dims[3] = {hsize_t(model.dims[2]), hsize_t(model.dims[1]), hsize_t(model.dims[0])};
  H5Handle space(H5Screate_simple(3, dims, nullptr), H5Sclose);
  H5Handle props(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  const hsize_t chunk[3] = {1, dims[1], dims[2]};
  check(space.ok() && props.ok() && H5Pset_chunk(props.get(), 3, chunk) >= 0 &&
            H5Pset_deflate(props.get(), 1) >= 0,
        finalPath, "dataset properties");
  H5Handle data(H5Dcreate2(file.get(), "/DiscData", H5T_STD_U8LE, space.get(), H5P_DEFAULT,
                           props.get(), H5P_DEFAULT),
                H5Dclose);
  check(data.ok(), finalPath, "/DiscData");
  check(H5Dwrite(data.get(), H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, model.index.data()) >=
            0,
        finalPath, "write /DiscData (disk full?)");
  const int count = int(model.materials.size());
  std::vector<float> eps, kappa, density;
  std::string names;
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    eps.push_back(float(model.materials[m].dielectric.relativePermittivity));
    kappa.push_back(float(model.materials[m].dielectric.conductivity));
    density.push_back(float(model.materials[m].densityKgM3));
    names += (m ? "," : "") + materialName(model, m);
  }
  const std::size_t n = eps.size();
  check(H5LTset_attribute_int(file.get(), "/DiscData", "DB_Size", &count, 1) >= 0 &&
            H5LTset_attribute_float(file.get(), "/DiscData", "epsR", eps.data(), n) >= 0 &&
            H5LTset_attribute_float(file.get(), "/DiscData", "kappa", kappa.data(), n) >= 0 &&
            H5LTset_attribute_float(file.get(), "/DiscData", "density", density.data(), n) >= 0 &&
            H5LTset_attribute_string(file.get(), "/DiscData", "Name", names.c_str()) >= 0,
        finalPath, "material attributes");
  check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL) >= 0, finalPath, "flush (disk full?)");
}

std::string number(double v) {
  std::ostringstream s;
  s << std::setprecision(10) << v;
  return s.str();
}

std::string csxXml(const FdtdModel& model, const std::string& h5Absolute) {
  std::ostringstream x;
  const auto lines = [&](int a) {
    std::string out;
    for (const double mm : model.lines(a)) out += (out.empty() ? "" : ",") + number(mm);
    return out;
  };
  const Eigen::Vector3d lo = model.cornerMm;
  const Eigen::Vector3d hi =
      lo + Eigen::Vector3d(double(model.dims[0]), double(model.dims[1]), double(model.dims[2]))
               .cwiseProduct(model.spacingMm);
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<!-- Written by repose export-fdtd: the body as a CSXCAD discrete material. Drawing units\n"
    << "     are mm (DeltaUnit 1e-3) in RAS (x right, y anterior, z superior); the grid lines are\n"
    << "     the cell boundaries; add an air margin and boundaries before simulating. Load it "
       "first:\n"
    << "     CSX.ReadFromXML(path) clears the structure. -->\n"
    << "<ContinuousStructure CoordSystem=\"0\">\n"
    << "  <Properties>\n"
    << "    <DiscMaterial ID=\"0\" Name=\"body\" File=\"" << escapeXml(h5Absolute)
    << "\" Scale=\"1000\" UseDBBackground=\"1\">\n"
    << "      <Property Epsilon=\"1\" Kappa=\"0\" Density=\"0\"/>\n"
    << "      <Primitives>\n"
    << "        <Box Priority=\"0\">\n"
    << "          <P1 X=\"" << number(lo.x()) << "\" Y=\"" << number(lo.y()) << "\" Z=\""
    << number(lo.z()) << "\"/>\n"
    << "          <P2 X=\"" << number(hi.x()) << "\" Y=\"" << number(hi.y()) << "\" Z=\""
    << number(hi.z()) << "\"/>\n"
    << "        </Box>\n"
    << "      </Primitives>\n"
    << "    </DiscMaterial>\n"
    << "  </Properties>\n"
    << "  <RectilinearGrid DeltaUnit=\"0.001\" CoordSystem=\"0\">\n"
    << "    <XLines>" << lines(0) << "</XLines>\n"
    << "    <YLines>" << lines(1) << "</YLines>\n"
    << "    <ZLines>" << lines(2) << "</ZLines>\n"
    << "  </RectilinearGrid>\n"
    << "</ContinuousStructure>\n";
  return x.str();
}

double percentChange(double after, double before) {
  return before > 0 ? 100.0 * (after - before) / before : 0.0;
}

nlohmann::json report(const FdtdModel& model, const std::map<int, LabelTissue>& labels,
                      const FdtdModelFiles& files, const FdtdWriteInfo& info) {
  namespace fs = std::filesystem;
  nlohmann::json j;
  j["input"] = info.input;
  j["frequency_hz"] = model.frequencyHz;
  j["tissue_model"] =
      "four-term Cole-Cole, Gabriel et al. 1996 (Phys. Med. Biol. 41:2271), summary table of "
      "report AL/OE-TR-1996-0037";
  j["names_and_densities"] = info.tissueSource;
  j["files"] = {{"model", fs::path(files.model).filename().string()},
                {"csxcad_xml", fs::path(files.csx).filename().string()}};
  j["grid"] = {{"dims", {model.dims[0], model.dims[1], model.dims[2]}},
               {"spacing_mm", {model.spacingMm.x(), model.spacingMm.y(), model.spacingMm.z()}},
               {"corner_ras_mm", {model.cornerMm.x(), model.cornerMm.y(), model.cornerMm.z()}},
               {"axes", "x = R, y = A, z = S; cell (0,0,0) at corner_ras_mm"},
               {"resampled", model.resampled}};
  double bodyMass = 0, bodyVolume = 0, bodyInput = 0;
  nlohmann::json materials = nlohmann::json::array();
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    const FdtdMaterial& x = model.materials[m];
    nlohmann::json e = {{"index", m},
                        {"name", materialName(model, m)},
                        {"tissue", x.tissue},
                        {"eps_r", x.dielectric.relativePermittivity},
                        {"sigma_s_m", x.dielectric.conductivity},
                        {"density_kg_m3", x.densityKgM3},
                        {"labels", x.labels},
                        {"cells", x.voxels},
                        {"volume_ml", x.volumeMl}};
    if (m > 0) {
      e["mass_kg"] = x.massKg();
      e["input_volume_ml"] = x.inputVolumeMl;
      e["volume_change_percent"] = percentChange(x.volumeMl, x.inputVolumeMl);
      bodyMass += x.massKg();
      bodyVolume += x.volumeMl;
      bodyInput += x.inputVolumeMl;
    }
    materials.push_back(e);
  }
  j["materials"] = materials;
  nlohmann::json perLabel = nlohmann::json::array();
  for (const auto& [value, c] : model.labels) {
    const LabelTissue& l = labels.at(value);
    perLabel.push_back({{"label", value},
                        {"name", l.name},
                        {"tissue", l.tissue},
                        {"rule", l.rule},
                        {"density_kg_m3", l.densityKgM3},
                        {"density_source", l.densitySource},
                        {"material", c.material},
                        {"cells", c.voxels},
                        {"input_voxels", c.inputVoxels},
                        {"mass_kg", l.densityKgM3 * c.volumeMl * 1e-6},
                        {"volume_change_percent", percentChange(c.volumeMl, c.inputVolumeMl)}});
  }
  j["labels"] = perLabel;
  j["body"] = {{"mass_kg", bodyMass},
               {"volume_ml", bodyVolume},
               {"input_volume_ml", bodyInput},
               {"volume_change_percent", percentChange(bodyVolume, bodyInput)}};
  j["overlap_voxels"] = model.overlapVoxels;
  j["warnings"] = info.warnings;
  return j;
}

}  // namespace

FdtdModelFiles fdtdModelFiles(const std::string& h5Path) {
  const std::string suffix = ".h5";
  if (h5Path.size() <= suffix.size() ||
      h5Path.compare(h5Path.size() - suffix.size(), suffix.size(), suffix) != 0)
    throw Error(h5Path + ": the FDTD model is written as HDF5: name it MODEL.h5");
  const std::string stem = h5Path.substr(0, h5Path.size() - suffix.size());
  return {h5Path, stem + ".csx.xml", stem + ".json"};
}

std::string writeFdtdModel(const FdtdModel& model, const std::map<int, LabelTissue>& labels,
                           const std::string& h5Path, const FdtdWriteInfo& info) {
  const FdtdModelFiles files = fdtdModelFiles(h5Path);
  AtomicOutput h5(files.model), csx(files.csx), json(files.report);
  writeHdf5(model, h5.tempPath(), files.model);
  const std::string absolute = std::filesystem::absolute(files.model).lexically_normal().string();
  const std::string text = report(model, labels, files, info).dump(2) + "\n";
  for (const auto& [output, content] :
       {std::pair<AtomicOutput*, std::string>{&csx, csxXml(model, absolute)},
        std::pair<AtomicOutput*, std::string>{&json, text}}) {
    std::ofstream out(output->tempPath(), std::ios::binary);
    out << content;
    out.close();
    if (!out) throw Error(output->finalPath() + ": cannot write (disk full?)");
  }
  commitTogether({&h5, &csx, &json});
  return text;
}

}  // namespace repose

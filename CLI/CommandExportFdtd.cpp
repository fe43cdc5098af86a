// `repose export-fdtd --input POSED_G --frequency 900MHz --out MODEL.h5`: a posed body as the
// voxel model of openEMS's FDTD solver: per cell a material index; per material the tissue's
// permittivity and conductivity at the frequency (Gabriel's Cole-Cole model) and its density.
// Writes MODEL.h5, MODEL.csx.xml and MODEL.json together or not at all (docs/DOSIMETRY.md).
#include "ArgParser.h"
#include "StderrLine.h"
#include "Commands.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "TerminalProgress.h"

#include "repose/dosimetry/FdtdModel.h"
#include "repose/io/AtomicOutput.h"
#include "repose/dosimetry/FdtdModelIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>

namespace repose::cli {

int runExportFdtd(const Args& args) {
  ArgParser p("export-fdtd",
              "Write a (posed) label map as an openEMS FDTD voxel model: MODEL.h5 in the HDF5\n"
              "layout of CSXCAD's discrete material (a material index per cell; per material\n"
              "relative permittivity, conductivity and mass density), MODEL.csx.xml (the model\n"
              "as a CSXCAD structure, for CSX.ReadFromXML) and MODEL.json (frequency, tissues,\n"
              "volumes and masses). Each label gets a tissue of Gabriel et al. 1996 by its name\n"
              "(the phantom's, ICRP 110's or TotalSegmentator's), or by --tissue-map.");
  p.option("input", "FILE", "label map G, posed or not (NIfTI, NRRD, .seg.nrrd, DICOM)")
      .option("out", "MODEL.h5", "the HDF5 model; MODEL.csx.xml and MODEL.json go beside it")
      .option("frequency", "F", "frequency, 10Hz to 20GHz (e.g. 900MHz, 2.45GHz)", "900MHz")
      .option("tissues", "CSV",
              "label,name,density_kg_m3,rigid[,bone]: names and mass densities (default: G's "
              "label convention, see --labels)")
      .option("labels", "NAME",
              "G's label convention for names and densities without --tissues: auto, phantom, "
              "icrp110, totalsegmentator or a CSV (as repose rig)",
              "auto")
      .option("tissue-map", "CSV", "label,tissue: the tissue of a label, before the name rules")
      .option("default-tissue", "NAME",
              "the tissue of labels no rule names (else they are an error), e.g. Muscle")
      .option("spacing-mm", "S",
              "resample to cells of S mm (or SX,SY,SZ) by nearest neighbour; needed when G's "
              "axes are oblique")
      .option("threads", "N", "worker threads (0: all cores)", "0")
      .flag("list-tissues", "print the tissues and their values at --frequency, then exit")
      .flag("json", "print MODEL.json on stdout");
  declareMemoryOption(p, "G, or a model grid, larger than this is refused before it is made");
  if (!p.parse(args)) return 0;
  const double frequency = parseFrequencyHz(p.get("frequency"));
  if (p.has("list-tissues")) {
    std::cout << "# at " << std::setprecision(6) << frequency / 1e6
              << " MHz\ntissue,eps_r,sigma_S_m\n";
    for (const ColeColeTissue& t : gabrielTissues()) {
      const DielectricValues v = dielectricAt(t, frequency);
      std::cout << t.name << "," << v.relativePermittivity << "," << v.conductivity << "\n";
    }
    return 0;
  }
  for (const char* required : {"input", "out"})
    if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
  const std::string input = p.get("input"), out = p.get("out");
  const FdtdModelFiles files = fdtdModelFiles(out);
  for (const std::string& f : {files.model, files.csx, files.report})
    refuseOverwritingInput(input, f);
  std::optional<Eigen::Vector3d> spacing;
  if (p.has("spacing-mm")) spacing = parseCellSizeMm(p.get("spacing-mm"));
  const bool quiet = p.has("json");
  // Options that name files are checked before G is read (a typo fails at once).
  std::optional<TissueTable> tissues;
  if (p.has("tissues")) tissues = readTissueTable(p.get("tissues"));
  LabelTissueOptions tissueOptions;
  tissueOptions.userCsv = p.has("tissue-map") ? p.get("tissue-map") : "";
  tissueOptions.defaultTissue = p.has("default-tissue") ? p.get("default-tissue") : "";

  const double budget = parseMemoryBudget(p.get("memory"));
  const Volume organs = readVolume(input, readOptionsWithin(budget, !quiet));
  std::map<int, LabelTissue> labels =
      labelNamesAndDensities(organs, tissues ? &*tissues : nullptr,
                             p.has("tissues") ? p.get("tissues") : "", p.get("labels"), input);
  assignTissues(labels, tissueOptions);

  FdtdModelOptions options;
  options.frequencyHz = frequency;
  options.spacingMm = spacing;
  options.threads = static_cast<int>(p.getInt("threads"));
  options.progress = quiet ? ProgressFn{} : terminalProgress();
  options.memoryBytes = memoryLeftWithin(budget);
  const FdtdModel model = buildFdtdModel(organs, labels, options, input);

  FdtdWriteInfo info;
  info.input = input;
  info.tissueSource = p.has("tissues") ? p.get("tissues") : labels.begin()->second.densitySource;
  if (model.overlapVoxels > 0)
    info.warnings.push_back(std::to_string(model.overlapVoxels) +
                            " voxels where segments overlap took the last segment's tissue");
  const std::string report = writeFdtdModel(model, labels, out, info);
  for (const std::string& w : info.warnings) stderrLine("repose export-fdtd: warning: " + w);
  if (quiet) {
    std::cout << report;
    return 0;
  }
  const nlohmann::json j = nlohmann::json::parse(report);
  std::cout << "wrote " << files.model << " (" << model.dims[0] << "x" << model.dims[1] << "x"
            << model.dims[2] << " cells, " << model.materials.size() - 1 << " materials, "
            << std::fixed << std::setprecision(2) << j["body"]["mass_kg"].get<double>() << " kg at "
            << std::defaultfloat << std::setprecision(6) << frequency / 1e6 << " MHz), "
            << files.csx << ", " << files.report << "\n";
  if (model.resampled)
    std::cout << "resampled: body volume " << std::showpos << std::fixed << std::setprecision(2)
              << j["body"]["volume_change_percent"].get<double>() << " %\n";
  return 0;
}

}  // namespace repose::cli

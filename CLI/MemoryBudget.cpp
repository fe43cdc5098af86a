#include "MemoryBudget.h"
#include "StderrLine.h"

#include "ArgParser.h"
#include "TerminalProgress.h"

#include "repose/io/LabelProxy.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/SliceCache.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <iostream>
#include <cstdlib>
#include <sstream>
#include <thread>

namespace repose::cli {

void declareMemoryOption(ArgParser& p, const std::string& aboveIt) {
  p.option("memory", "BYTES", "memory budget, e.g. 2G (default: half the RAM); " + aboveIt, "");
}

double parseMemoryBudget(const std::string& text) {
  if (text.empty()) return memoryBudgetByDefault();
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const std::string unit = end ? std::string(end) : "";
  double scale = 1;
  if (unit == "K" || unit == "k")
    scale = 1024;
  else if (unit == "M" || unit == "m")
    scale = 1024.0 * 1024;
  else if (unit == "G" || unit == "g")
    scale = 1024.0 * 1024 * 1024;
  else if (!unit.empty())
    throw UsageError{"--memory: unknown unit in '" + text + "' (use K, M or G)"};
  if (!(v > 0)) throw UsageError{"--memory must be positive"};
  return v * scale;
}

namespace {
int localRanks() {
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  return local ? std::max(1, std::atoi(local)) : 1;
}
}  // namespace

double rankMemoryBudget(const std::string& memory) {
  const double budget = parseMemoryBudget(memory);
  return memory.empty() ? budget / localRanks() : budget;
}

int rankThreads(int threads) {
  if (threads > 0) return threads;
  return std::max(1, int(std::thread::hardware_concurrency()) / localRanks());
}

ReadOptions readOptionsWithin(double budget, bool progress) {
  ReadOptions r;
  if (progress) r.progress = terminalProgress();
  r.note = [](const std::string& n) { stderrLine("repose: note: " + n); };
  // Core's rule for every front end (the workbench and Python read by it too): the budget less
  // the resident set now; never 0 (no limit), so a budget already used up refuses every read.
  r.memoryLimitBytes = memoryLeftWithin(budget);
  return r;
}

Volume readLabelsWithinBudget(const std::string& path, double budget, double bytesPerVoxelNeeded,
                              int& factor) {
  factor = 1;
  if (formatForPath(path) != FileFormat::Nifti) {
    // No proxy without reading slices in place (NIfTI only): in core, or refused with the numbers.
    Volume v = readVolume(path, readOptionsWithin(budget, false));
    const double need = double(v.numVoxels()) * bytesPerVoxelNeeded;
    const double held = double(v.numVoxels()) * double(scalarSize(v.scalarType())) * v.layers();
    if (need - held > memoryLeftWithin(budget))
      throw Error(path + ": working on it needs " + gib(need) + " (" +
                  std::to_string(v.numVoxels()) + " voxels), more than the memory budget of " +
                  gib(budget) +
                  " leaves; raise --memory, or convert it to NIfTI for the "
                  "downsampled proxy");
    return v;
  }
  const NiftiLayout layout = readNiftiLayout(path);
  const double available = memoryLeftWithin(budget);
  const std::int64_t voxels = layout.geometry.numVoxels();
  if (double(voxels) * bytesPerVoxelNeeded <= available)
    return readVolume(path, readOptionsWithin(budget, false));
  // The proxy must fit with the same overhead; the cache gets a quarter of what is left.
  factor = proxyFactor(voxels, static_cast<std::size_t>(std::ceil(bytesPerVoxelNeeded)),
                       0.5 * available);
  const double cacheBytes = 0.25 * available;
  if (available <= 1)
    throw Error(path + ": the memory budget of " + gib(budget) + " is already used up");
  SliceCache cache(path, static_cast<std::size_t>(cacheBytes));
  return labelModeProxy(cache, factor, terminalProgress());
}

}  // namespace repose::cli

// Throughput of the volume readers and writers on a label map shaped like a body (nested
// ellipsoids, so it compresses like real segmentations, unlike noise). Reports voxels/s.
#include "repose/io/VolumeIO.h"
#include "repose/volume/LabelStatistics.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <unistd.h>

namespace {

using namespace repose;

// A cube of side n with ten nested ellipsoid shells, 1 mm voxels.
const Volume& bodyLikeLabels(std::int64_t n) {
  static std::map<std::int64_t, Volume> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  Volume v(VolumeGeometry::make({n, n, n}, {1, 1, 1}, {0, 0, 0}), ScalarType::UInt8);
  auto* d = v.data<std::uint8_t>();
  const double c = (n - 1) / 2.0;
  for (std::int64_t k = 0; k < n; ++k)
    for (std::int64_t j = 0; j < n; ++j)
      for (std::int64_t i = 0; i < n; ++i) {
        const double x = (i - c) / (0.35 * n), y = (j - c) / (0.25 * n), z = (k - c) / (0.48 * n);
        const double r = std::sqrt(x * x + y * y + z * z);
        d[v.index(i, j, k)] = r < 1 ? static_cast<std::uint8_t>(1 + int(r * 10)) : 0;
      }
  v.setLabelMap(true);
  return cache.emplace(n, std::move(v)).first->second;
}

std::string scratch(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("repose-bench-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

void BM_Write(benchmark::State& state, const std::string& ext) {
  const Volume& v = bodyLikeLabels(state.range(0));
  const std::string path = scratch("w" + ext);
  for (auto _ : state) writeVolume(v, path);
  state.counters["voxels/s"] =
      benchmark::Counter(double(v.numVoxels()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["MB"] = double(std::filesystem::file_size(path)) / 1e6;
}

void BM_Read(benchmark::State& state, const std::string& ext) {
  const Volume& v = bodyLikeLabels(state.range(0));
  const std::string path = scratch("r" + ext);
  writeVolume(v, path);
  for (auto _ : state) benchmark::DoNotOptimize(readVolume(path));
  state.counters["voxels/s"] =
      benchmark::Counter(double(v.numVoxels()) * state.iterations(), benchmark::Counter::kIsRate);
}

void BM_CountLabels(benchmark::State& state) {
  const Volume& v = bodyLikeLabels(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(countLabels(v));
  state.counters["voxels/s"] =
      benchmark::Counter(double(v.numVoxels()) * state.iterations(), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_Write, nii_gz, std::string(".nii.gz"))
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Write, nii, std::string(".nii"))
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Write, seg_nrrd, std::string(".seg.nrrd"))
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Read, nii_gz, std::string(".nii.gz"))
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Read, nii, std::string(".nii"))
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Read, seg_nrrd, std::string(".seg.nrrd"))
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CountLabels)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ec;
  std::filesystem::remove_all(
      std::filesystem::temp_directory_path() / ("repose-bench-" + std::to_string(getpid())), ec);
  return 0;
}

// Transfer mesh benchmark: CGAL Mesh_3 on the 2 mm phantom at the seed's default size (5% of the
// diagonal) and at 8.5 mm, which gives ~36K vertices (the seed's mesh scale).
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"

#include <benchmark/benchmark.h>

namespace {

using namespace repose;

const Volume& phantomParts() {
  static const Volume parts = [] {
    PhantomOptions o;
    o.voxelMm = 2;
    return Phantom(o).makeVolumes().second;
  }();
  return parts;
}

// The argument is the tet size in tenths of a mm (0: the default); Mesh_3 runs sequentially.
void BM_BuildTransferMesh(benchmark::State& state) {
  const Volume& parts = phantomParts();
  TransferMeshOptions options;
  options.sizeMm = static_cast<double>(state.range(0)) / 10;
  TransferMeshReport report;
  for (auto _ : state) benchmark::DoNotOptimize(buildTransferMesh(parts, options, &report));
  state.counters["vertices"] = report.vertices;
  state.counters["tets"] = report.tets;
}
BENCHMARK(BM_BuildTransferMesh)->Arg(0)->Arg(85)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

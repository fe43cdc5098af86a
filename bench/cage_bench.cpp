// Cage benchmarks: Green coordinates embedding throughput, inside tests (solid-angle winding
// numbers for scattered points, ray crossings for whole grids) and ARAP on a ~500-vertex cage.
// The cage is the phantom's own (4 mm phantom, built once per run).
#include "repose/cage/ArapDeformer.h"
#include "repose/cage/CageBuilder.h"
#include "repose/cage/GreenCoordinates.h"
#include "repose/cage/GridWinding.h"
#include "repose/cage/WindingNumber.h"
#include "repose/phantom/Phantom.h"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>

namespace {

using namespace repose;

const Volume& phantomParts() {
  static const Volume parts = [] {
    PhantomOptions o;
    o.voxelMm = 4;
    return Phantom(o).makeVolumes().second;
  }();
  return parts;
}

const TriangleMesh& phantomCage(int vertices) {
  static std::map<int, TriangleMesh> cache;
  auto it = cache.find(vertices);
  if (it != cache.end()) return it->second;
  CageOptions o;
  o.targetVertices = vertices;
  return cache.emplace(vertices, buildCage(phantomParts(), o).mesh).first->second;
}

Eigen::MatrixX3d pointsInBox(const TriangleMesh& cage, int count) {
  const Eigen::Vector3d lo = cage.vertices.colwise().minCoeff(),
                        hi = cage.vertices.colwise().maxCoeff();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  Eigen::MatrixX3d p(count, 3);
  for (int r = 0; r < count; ++r)
    for (int c = 0; c < 3; ++c) p(r, c) = lo[c] + u(rng) * (hi[c] - lo[c]);
  return p;
}

void BM_GreenCoordinates(benchmark::State& state) {
  const TriangleMesh& cage = phantomCage(static_cast<int>(state.range(0)));
  const Eigen::MatrixX3d points = pointsInBox(cage, 2000);
  for (auto _ : state) benchmark::DoNotOptimize(computeGreenCoordinates(cage, points));
  state.counters["cage_faces"] = double(cage.faces.rows());
  state.counters["points*faces/s"] = benchmark::Counter(
      double(points.rows()) * cage.faces.rows() * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["points/s"] =
      benchmark::Counter(double(points.rows()) * state.iterations(), benchmark::Counter::kIsRate);
}

void BM_WindingNumberPoints(benchmark::State& state) {
  const TriangleMesh& cage = phantomCage(static_cast<int>(state.range(0)));
  const Eigen::MatrixX3d points = pointsInBox(cage, 20000);
  for (auto _ : state) benchmark::DoNotOptimize(windingNumbers(cage, points));
  state.counters["points/s"] =
      benchmark::Counter(double(points.rows()) * state.iterations(), benchmark::Counter::kIsRate);
}

void BM_WindingNumberGrid(benchmark::State& state) {
  const TriangleMesh& cage = phantomCage(static_cast<int>(state.range(0)));
  const double voxel = state.range(1) / 10.0;
  const Eigen::Vector3d lo = cage.vertices.colwise().minCoeff(),
                        hi = cage.vertices.colwise().maxCoeff();
  std::array<std::int64_t, 3> dims;
  for (int c = 0; c < 3; ++c) dims[c] = static_cast<std::int64_t>((hi[c] - lo[c]) / voxel) + 1;
  const VolumeGeometry g = VolumeGeometry::make(dims, Eigen::Vector3d::Constant(voxel), lo);
  for (auto _ : state) benchmark::DoNotOptimize(windingNumbersOnGrid(cage, g));
  state.counters["voxels"] = double(g.numVoxels());
  state.counters["voxels/s"] =
      benchmark::Counter(double(g.numVoxels()) * state.iterations(), benchmark::Counter::kIsRate);
}

// A bend of the right arm's cage vertices about the shoulder: a realistic drag.
Eigen::MatrixX3d armTargets(const TriangleMesh& cage, const std::vector<int>& handles,
                            double angle) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d pivot(120, 0, 950);
  Eigen::MatrixX3d t(handles.size(), 3);
  for (std::size_t h = 0; h < handles.size(); ++h) {
    const Eigen::Vector3d p = cage.vertices.row(handles[h]);
    const Eigen::Vector3d q = p.x() > 180 ? Eigen::Vector3d(R * (p - pivot) + pivot) : p;
    t.row(h) = q.transpose();
  }
  return t;
}

std::vector<int> armAndFeetHandles(const TriangleMesh& cage) {
  std::vector<int> h;
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v)
    if (cage.vertices(v, 0) > 180 || cage.vertices(v, 2) < 60) h.push_back(static_cast<int>(v));
  return h;
}

void BM_ArapIteration(benchmark::State& state) {
  const TriangleMesh& cage = phantomCage(static_cast<int>(state.range(0)));
  ArapDeformer arap(cage);
  const std::vector<int> handles = armAndFeetHandles(cage);
  arap.setHandles(handles);
  const Eigen::MatrixX3d targets = armTargets(cage, handles, 0.5);
  ArapOptions one;
  one.maxIterations = 1;
  one.tolerance = 0;
  Eigen::MatrixX3d warm = arap.solve(targets).positions;  // a frame starts from the last one
  for (auto _ : state) benchmark::DoNotOptimize(arap.solve(targets, &warm, one));
  state.counters["cage_vertices"] = double(cage.vertices.rows());
}

void BM_ArapSolveFromRest(benchmark::State& state) {
  const TriangleMesh& cage = phantomCage(static_cast<int>(state.range(0)));
  ArapDeformer arap(cage);
  const std::vector<int> handles = armAndFeetHandles(cage);
  arap.setHandles(handles);
  const Eigen::MatrixX3d targets = armTargets(cage, handles, 0.5);
  int iterations = 0;
  for (auto _ : state) iterations = arap.solve(targets).iterations;
  state.counters["iterations"] = iterations;
}

void BM_ArapFactorize(benchmark::State& state) {
  const TriangleMesh& cage = phantomCage(static_cast<int>(state.range(0)));
  ArapDeformer arap(cage);
  const std::vector<int> handles = armAndFeetHandles(cage);
  for (auto _ : state) arap.setHandles(handles);
}

}  // namespace

// Multithreaded: rates must come from wall-clock time, not the main thread's CPU time.
BENCHMARK(BM_GreenCoordinates)->Arg(300)->Arg(500)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WindingNumberPoints)->Arg(500)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WindingNumberGrid)
    ->Args({500, 40})
    ->Args({500, 20})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ArapIteration)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ArapSolveFromRest)->Arg(500)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ArapFactorize)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();

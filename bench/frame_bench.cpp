// One interaction frame at the seed's sizes: deformed cage -> Green coordinates of V_c -> both
// rigidity solves, on the 2 mm phantom with a ~500-vertex cage and a transfer mesh of ~36K
// vertices (--benchmark_filter to pick parts). Prints where the time goes.
#include "BenchPoses.h"
#include "repose/cage/CageBuilder.h"
#include "repose/cage/GreenCoordinates.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"
#include "repose/pose/PoseRig.h"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <iostream>

namespace {

using namespace repose;

struct Scene {
  TriangleMesh cage;
  TransferMesh mesh;
  std::unique_ptr<CageDeformation> deformation;
  Eigen::MatrixX3d deformedCage;
  // The suite's arm raised 90 degrees as rigid handle groups (RigidHandles.h) on the same mesh.
  std::vector<RigidHandle> handles;
  HandleInfluence influence;
};

// TM size in mm giving about 36K vertices on the 2 mm phantom (REPOSE_FRAME_TM_MM overrides).
double tmSize() {
  const char* env = std::getenv("REPOSE_FRAME_TM_MM");
  return env ? std::atof(env) : 8.5;
}

const Scene& scene() {
  static const Scene s = [] {
    Scene s;
    PhantomOptions po;
    po.voxelMm = 2;
    const Volume parts = Phantom(po).makeVolumes().second;
    CageOptions co;
    co.targetVertices = 500;
    s.cage = buildCage(parts, co).mesh;
    TransferMeshOptions to;
    to.sizeMm = tmSize();
    s.mesh = buildTransferMesh(parts, to);
    s.deformation = std::make_unique<CageDeformation>(s.mesh, s.cage);
    // Raise the right arm 60 degrees about the shoulder with ARAP: a realistic drag.
    s.deformedCage = bench::raiseRightArm60(s.cage);
    const Pose pose =
        readPoseFile(std::string(REPOSE_SOURCE_DIR) + "/bench/poses/arm_raise90.pose.json");
    s.handles = resolveHandles(pose, s.cage, s.mesh, parts.labels());
    setMotions(s.handles, pose.frames()[0].second);
    s.influence = computeHandleInfluence(s.mesh, s.cage, s.handles);
    std::cout << "frame scene: cage " << s.cage.vertices.rows() << " vertices / "
              << s.cage.faces.rows() << " faces, TM " << s.mesh.vertices.rows() << " vertices / "
              << s.mesh.tets.rows() << " tets, V_c "
              << s.deformation->embedding().cageVertices.size() << ", outliers "
              << s.deformation->embedding().outliers() << " (TM size " << tmSize() << " mm)\n";
    return s;
  }();
  return s;
}

// The frame during a drag (preview precision; see GreenPrecision) and the exact one used for
// exports, with their Green products alone.
void BM_Frame(benchmark::State& state, GreenPrecision precision) {
  const Scene& s = scene();
  for (auto _ : state)
    benchmark::DoNotOptimize(s.deformation->deform(s.deformedCage, nullptr, precision));
  state.counters["TM_vertices"] = double(s.mesh.vertices.rows());
  state.counters["coefficient_MB"] = double(s.deformation->coefficientBytes()) / 1e6;
  state.counters["FPS"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

// A frame of a pose of rigid handle groups: the posed cage, Green coordinates, the groups'
// dual-quaternion blend on every V_c vertex they carry, the rigidity solves.
void BM_FrameWithHandles(benchmark::State& state, GreenPrecision precision) {
  const Scene& s = scene();
  for (auto _ : state) {
    const Eigen::MatrixX3d cage = poseCage(s.cage, s.handles);
    benchmark::DoNotOptimize(
        s.deformation->deform(cage, s.influence, s.handles, nullptr, precision));
  }
  state.counters["rigid_vertices"] = double(s.influence.rigidVertices());
  state.counters["FPS"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

// The baseline: the same frame written plainly, as with libigl or a first implementation: the
// double Green coordinates of V_c held densely ([phi psi], 8 bytes a coefficient) and applied with
// Eigen's matrix product, then the same rigidity solves.
void BM_FrameDenseBaseline(benchmark::State& state) {
  const Scene& s = scene();
  const std::vector<int>& vc = s.deformation->embedding().cageVertices;
  Eigen::MatrixX3d rest(Eigen::Index(vc.size()), 3);
  for (std::size_t i = 0; i < vc.size(); ++i)
    rest.row(Eigen::Index(i)) = s.mesh.vertices.row(vc[i]);
  const GreenCoordinates gc = computeGreenCoordinates(s.cage, rest);
  for (auto _ : state)
    benchmark::DoNotOptimize(
        s.deformation->solver().solve(applyGreenCoordinates(gc, s.cage, s.deformedCage)));
  state.counters["coefficient_MB"] = double(gc.phi.size() + gc.psi.size()) * 8 / 1e6;
  state.counters["FPS"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_FrameGreenProduct(benchmark::State& state, GreenPrecision precision) {
  const Scene& s = scene();
  for (auto _ : state)
    benchmark::DoNotOptimize(s.deformation->greenPositions(s.deformedCage, precision));
}

void BM_FrameRigiditySolves(benchmark::State& state) {
  const Scene& s = scene();
  const Eigen::MatrixX3d targets = s.deformation->greenPositions(s.deformedCage);
  for (auto _ : state) benchmark::DoNotOptimize(s.deformation->solver().solve(targets));
  state.counters["outliers"] = double(s.deformation->embedding().outliers());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Frame, preview, GreenPrecision::Preview)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, exact, GreenPrecision::Exact)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FrameWithHandles, preview, GreenPrecision::Preview)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FrameWithHandles, exact, GreenPrecision::Exact)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FrameGreenProduct, preview, GreenPrecision::Preview)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FrameGreenProduct, exact, GreenPrecision::Exact)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameDenseBaseline)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameRigiditySolves)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();

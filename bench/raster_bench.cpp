// Rasterization at the seed's sizes: the deformed full-resolution label map (output voxels per
// second, in-core, file I/O excluded) against a VTK baseline (vtkProbeFilter of the deformed TM
// carrying rest positions, then the same nearest-label lookup), and one live 512x512 slice.
// 2 mm phantom (REPOSE_RASTER_VOXEL_MM overrides), TM of ~36K vertices, right arm raised 60 deg.
#include "BenchPoses.h"
#include "repose/cage/CageBuilder.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"
#include "repose/io/NrrdIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/raster/Rasterizer.h"

#include <benchmark/benchmark.h>

#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkProbeFilter.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkCellType.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <iostream>

namespace {

using namespace repose;

struct Scene {
  Volume organs, parts;
  TriangleMesh cage;
  TransferMesh mesh;
  Eigen::MatrixX3d deformed;
  VolumeGeometry output;
  std::vector<std::uint8_t> outer;
};

double voxelMm() {
  const char* env = std::getenv("REPOSE_RASTER_VOXEL_MM");
  return env ? std::atof(env) : 2.0;
}

const Scene& scene() {
  static const Scene s = [] {
    Scene s;
    PhantomOptions po;
    po.voxelMm = voxelMm();
    std::tie(s.organs, s.parts) = Phantom(po).makeVolumes();
    CageOptions co;
    co.targetVertices = 500;
    s.cage = buildCage(s.parts, co).mesh;
    TransferMeshOptions to;
    to.sizeMm = 8.5;
    s.mesh = buildTransferMesh(s.parts, to);
    const CageDeformation deformation(s.mesh, s.cage);
    s.deformed = deformation.deform(bench::raiseRightArm60(s.cage));
    s.output = deformedGrid(s.organs.geometry(), s.deformed);
    s.outer = outerFaces(s.mesh);
    // For the baselines that run outside this process (bench/run_bench.py: plastimatch warp):
    // the input G, the displacement field of this very deformation on the output grid, and our
    // posed labels to compare theirs with.
    if (const char* dir = std::getenv("REPOSE_RASTER_EXPORT_DIR")) {
      const std::string d = dir;
      writeVolume(s.organs, d + "/G.nii");
      writeDisplacementFieldNrrd(
          rasterizeDisplacement(s.mesh, s.deformed, s.organs.geometry(), s.output), s.output,
          d + "/transform.nrrd");
      RasterOptions o;
      o.outerFaces = &s.outer;
      writeVolume(rasterizeLabels(s.organs, s.mesh, s.deformed, s.output, o), d + "/posed_G.nii");
    }
    std::cout << "raster scene: " << voxelMm() << " mm phantom, input " << s.organs.numVoxels()
              << " voxels, output " << s.output.dims[0] << "x" << s.output.dims[1] << "x"
              << s.output.dims[2] << " = " << s.output.numVoxels() << " voxels, TM "
              << s.mesh.vertices.rows() << " vertices / " << s.mesh.tets.rows() << " tets\n";
    return s;
  }();
  return s;
}

void BM_RasterizeLabels(benchmark::State& state) {
  const Scene& s = scene();
  RasterOptions o;
  o.outerFaces = &s.outer;
  RasterReport r;
  for (auto _ : state)
    benchmark::DoNotOptimize(rasterizeLabels(s.organs, s.mesh, s.deformed, s.output, o, &r));
  state.counters["output_voxels_per_s"] = benchmark::Counter(
      double(s.output.numVoxels()) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["inside_tets"] = double(r.voxelWrites);
  state.counters["shell"] = double(r.shellVoxels);
}

// The same with the files a file-to-file tool reads and writes (plastimatch's baseline):
// read G (.nii), rasterize, write the posed labels (.nii), uncompressed.
void BM_RasterizeLabelsFileToFile(benchmark::State& state) {
  const Scene& s = scene();
  const char* dir = std::getenv("REPOSE_RASTER_EXPORT_DIR");
  if (!dir) {
    state.SkipWithError("REPOSE_RASTER_EXPORT_DIR is not set");
    return;
  }
  const std::string d = dir;
  RasterOptions o;
  o.outerFaces = &s.outer;
  for (auto _ : state) {
    const Volume G = readVolume(d + "/G.nii");
    writeVolume(rasterizeLabels(G, s.mesh, s.deformed, s.output, o), d + "/ours_file.nii");
  }
  state.counters["output_voxels_per_s"] = benchmark::Counter(
      double(s.output.numVoxels()) * double(state.iterations()), benchmark::Counter::kIsRate);
}

// The deformed TM as VTK sees it: tets at the deformed positions, the rest positions as point data.
vtkSmartPointer<vtkUnstructuredGrid> vtkDeformedMesh(const Scene& s) {
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto rest = vtkSmartPointer<vtkDoubleArray>::New();
  rest->SetName("rest");
  rest->SetNumberOfComponents(3);
  for (Eigen::Index v = 0; v < s.mesh.vertices.rows(); ++v) {
    points->InsertNextPoint(s.deformed(v, 0), s.deformed(v, 1), s.deformed(v, 2));
    rest->InsertNextTuple3(s.mesh.vertices(v, 0), s.mesh.vertices(v, 1), s.mesh.vertices(v, 2));
  }
  grid->SetPoints(points);
  grid->GetPointData()->AddArray(rest);
  grid->Allocate(s.mesh.tets.rows());
  for (Eigen::Index t = 0; t < s.mesh.tets.rows(); ++t) {
    const vtkIdType ids[4] = {s.mesh.tets(t, 0), s.mesh.tets(t, 1), s.mesh.tets(t, 2),
                              s.mesh.tets(t, 3)};
    grid->InsertNextCell(VTK_TETRA, 4, ids);
  }
  return grid;
}

// vtkImageData holding an axis-aligned grid (the phantom's grids are RAS-aligned).
vtkSmartPointer<vtkImageData> vtkGrid(const VolumeGeometry& g) {
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(int(g.dims[0]), int(g.dims[1]), int(g.dims[2]));
  const Eigen::Vector3d o = g.origin(), sp = g.spacing();
  image->SetOrigin(o.x(), o.y(), o.z());
  image->SetSpacing(sp.x(), sp.y(), sp.z());
  return image;
}

// vtkProbeFilter of the deformed TM at every point of `image`, then the nearest input label at
// the interpolated rest position: what one would write with VTK alone.
std::vector<std::uint8_t> vtkProbeLabels(const Scene& s, vtkUnstructuredGrid* mesh,
                                         vtkImageData* image) {
  auto probe = vtkSmartPointer<vtkProbeFilter>::New();
  probe->SetInputData(image);
  probe->SetSourceData(mesh);
  probe->Update();
  auto* out = probe->GetOutput();
  auto* valid = out->GetPointData()->GetArray(probe->GetValidPointMaskArrayName());
  auto* r = out->GetPointData()->GetArray("rest");
  const auto d = s.organs.dims();
  const std::uint8_t* G = s.organs.data<std::uint8_t>();
  std::vector<std::uint8_t> labels(static_cast<std::size_t>(out->GetNumberOfPoints()), 0);
  for (vtkIdType p = 0; p < out->GetNumberOfPoints(); ++p) {
    if (valid->GetComponent(p, 0) == 0) continue;
    double q[3];
    r->GetTuple(p, q);
    const Eigen::Vector3d ijk = s.organs.geometry().rasToVoxel(Eigen::Vector3d(q[0], q[1], q[2]));
    const std::int64_t x = std::llround(ijk.x()), y = std::llround(ijk.y()),
                       z = std::llround(ijk.z());
    if (x >= 0 && y >= 0 && z >= 0 && x < d[0] && y < d[1] && z < d[2])
      labels[p] = G[x + d[0] * (y + d[1] * z)];
  }
  return labels;
}

// The VTK baseline of the full label map, on the same deformed TM and output grid.
void BM_VtkProbeFilterBaseline(benchmark::State& state) {
  const Scene& s = scene();
  const auto mesh = vtkDeformedMesh(s);
  const auto image = vtkGrid(s.output);
  for (auto _ : state) benchmark::DoNotOptimize(vtkProbeLabels(s, mesh, image).data());
  state.counters["output_voxels_per_s"] = benchmark::Counter(
      double(s.output.numVoxels()) * double(state.iterations()), benchmark::Counter::kIsRate);
}

// The plane of a live slice: size x size pixels through the middle of the deformed body.
VolumeGeometry livePlane(const Scene& s, SliceOrientation orientation, int size) {
  const Eigen::Vector3d lo = s.deformed.colwise().minCoeff(), hi = s.deformed.colwise().maxCoeff();
  const int axis = orientation == SliceOrientation::Axial     ? 2
                   : orientation == SliceOrientation::Coronal ? 1
                                                              : 0;
  return slicePlaneGrid(orientation, 0.5 * (lo[axis] + hi[axis]), lo, hi, size);
}

// The VTK baseline of a live slice: during a drag every frame moves the mesh, so each iteration
// hands the probe new points (its cell locator is rebuilt, as it would be in an application).
void BM_VtkProbeSliceBaseline(benchmark::State& state) {
  const Scene& s = scene();
  const auto orientation = static_cast<SliceOrientation>(state.range(0));
  const auto mesh = vtkDeformedMesh(s);
  const auto image = vtkGrid(livePlane(s, orientation, int(state.range(1))));
  for (auto _ : state) {
    mesh->GetPoints()->Modified();
    benchmark::DoNotOptimize(vtkProbeLabels(s, mesh, image).data());
  }
}

// One live slice: size x size, axial, coronal or sagittal through the middle of the deformed body.
void BM_LiveSlice(benchmark::State& state) {
  const Scene& s = scene();
  const VolumeGeometry plane =
      livePlane(s, static_cast<SliceOrientation>(state.range(0)), int(state.range(2)));
  RasterOptions o;
  o.outerFaces = &s.outer;
  o.threads = int(state.range(1));
  for (auto _ : state)
    benchmark::DoNotOptimize(rasterizeLabels(s.organs, s.mesh, s.deformed, plane, o));
}

}  // namespace

BENCHMARK(BM_RasterizeLabels)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RasterizeLabelsFileToFile)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VtkProbeFilterBaseline)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(1);
// Arguments: orientation (0 axial, 1 coronal, 2 sagittal), threads (0: all cores), pixels a side.
BENCHMARK(BM_LiveSlice)
    ->ArgsProduct({{0, 1, 2}, {1, 0}, {512}})
    ->ArgsProduct({{0}, {0}, {256, 1024}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
// Arguments: orientation, pixels a side.
BENCHMARK(BM_VtkProbeSliceBaseline)
    ->ArgsProduct({{0, 1, 2}, {512}})
    ->ArgsProduct({{0}, {256, 1024}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();

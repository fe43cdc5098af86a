// restTetTissues: the rest scan of the label rounding's targets, counting per tet (RestTissues.h).
#include "repose/raster/RestTissues.h"

#include "RasterScan.h"

#include <algorithm>
#include <mutex>
#include <unordered_map>

namespace repose {

TetTissues restTetTissues(const TransferMesh& mesh, const Volume& organs,
                          const RasterOptions& options) {
  const VolumeGeometry& g = organs.geometry();
  RasterOptions rest;
  rest.threads = options.threads;
  rest.shellMm = options.shellMm;
  rest.outerFaces = options.outerFaces;
  rest.restParts = options.restParts;
  // The shell as the labels' scan has it: whose tissue a shell voxel is, and no background
  // claimed (roundingTargets' rest scan copies the same from the frame's shell).
  raster::Shell shell = raster::makeShell(mesh, g, g, rest);
  shell.claimsBackground = false;
  const raster::ScanInput in = raster::makeScanInput(mesh, mesh.vertices, g, g);
  const Eigen::Index nt = mesh.tets.rows();
  const std::int64_t nx = organs.dims()[0], plane = nx * organs.dims()[1];
  // (tet, label) -> voxels, per thread, merged as each thread finishes.
  using Counts = std::unordered_map<std::int64_t, std::int64_t>;
  std::int64_t maxLabel = 0;
  for (std::int64_t v = 0, n = organs.numVoxels(); v < n; ++v)
    maxLabel = std::max<std::int64_t>(maxLabel, std::int64_t(organs.valueAsDouble(v)));
  const std::int64_t stride = maxLabel + 1;
  Counts all;
  std::mutex merging;
  // What every thread's worker reads and where it merges its counts.
  struct Shared {
    const TransferMesh& mesh;
    const Volume& organs;
    std::int64_t nx, plane, stride;
    Counts& all;
    std::mutex& merging;
  };
  struct Worker {
    const Shared& shared;
    Counts mine;
    void operator()(std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                    const Eigen::Vector3d&, const Eigen::Vector3d&, std::int32_t tet) {
      const TransferMesh& mesh = shared.mesh;
      if (!mesh.rigid.empty() && mesh.rigid[std::size_t(tet)]) return;  // a piece: rigid
      const std::int64_t row = k * shared.plane + j * shared.nx;
      for (std::int64_t i = i0; i <= i1; ++i) {
        const double label = shared.organs.valueAsDouble(row + i);
        if (label > 0) ++mine[std::int64_t(tet) * shared.stride + std::int64_t(label)];
      }
    }
    void flush() {
      const std::lock_guard<std::mutex> lock(shared.merging);
      for (const auto& [key, n] : mine) shared.all[key] += n;
      mine.clear();
    }
  };
  struct Writer {
    Shared shared;
    Worker worker() const { return Worker{shared, {}}; }
  };
  raster::runScan(in, shell, rest, "tissues at rest", nullptr, 1.0,
                  Writer{Shared{mesh, organs, nx, plane, stride, all, merging}});
  std::vector<std::vector<std::pair<int, int>>> per(static_cast<std::size_t>(nt));
  for (const auto& [key, n] : all)
    per[std::size_t(key / stride)].emplace_back(int(key % stride), int(n));
  TetTissues out;
  out.offsets.reserve(std::size_t(nt) + 1);
  out.offsets.push_back(0);
  for (auto& list : per) {
    std::sort(list.begin(), list.end());
    out.entries.insert(out.entries.end(), list.begin(), list.end());
    out.offsets.push_back(int(out.entries.size()));
  }
  return out;
}

}  // namespace repose

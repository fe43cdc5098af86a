// Dosimetry in Python: the peak spatial-average SAR of a local SAR grid (IEC/IEEE 62704-1 cube
// rules, Core's dosimetry/SarAveraging.h), which repose.openems applies to openEMS's fields.
#include "PythonCommon.h"

#include "repose/dosimetry/SarAveraging.h"
#include "repose/util/Error.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>

namespace repose::python {
namespace {

using Grid3 = py::array_t<double, py::array::f_style | py::array::forcecast>;
using Line = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<double> values(const Grid3& a) {
  return std::vector<double>(a.data(), a.data() + a.size());
}

template <class T>
py::array_t<T, py::array::f_style> shaped(const std::vector<T>& v, const std::array<int, 3>& dims) {
  py::array_t<T, py::array::f_style> out({dims[0], dims[1], dims[2]});
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

py::dict averageSar(const Grid3& density, const Grid3& localSar, const Line& ex, const Line& ey,
                    const Line& ez, double massKg, int threads, py::object progress) {
  if (density.ndim() != 3 || localSar.ndim() != 3) {
    throw Error("average_sar: density and local_sar must be 3D arrays [x, y, z]");
  }
  SarCellGrid grid;
  const Line* edges[3] = {&ex, &ey, &ez};
  for (int a = 0; a < 3; ++a) {
    grid.dims[a] = int(density.shape(a));
    if (localSar.shape(a) != density.shape(a)) {
      throw Error("average_sar: density and local_sar differ in shape");
    }
    grid.edges[a].assign(edges[a]->data(), edges[a]->data() + edges[a]->size());
  }
  const std::vector<double> rho = values(density), sar = values(localSar);
  PythonProgress p(std::move(progress));
  SarAveragingOptions o;
  o.massKg = massKg;
  o.threads = threads;
  o.progress = p.fn();
  SarAveraged r;
  try {
    py::gil_scoped_release release;
    r = averageSarIec62704(grid, rho, sar, o);
  } catch (const Cancelled&) {
    p.rethrow();
    throw;
  }
  std::vector<std::uint8_t> kind(r.kind.size());
  for (std::size_t c = 0; c < kind.size(); ++c) kind[c] = std::uint8_t(r.kind[c]);
  py::dict out;
  out["sar"] = shaped(r.sar, grid.dims);
  out["kind"] = shaped(kind, grid.dims);
  out["cube_edge_m"] = shaped(r.cubeEdge, grid.dims);
  out["peak"] = r.peak;
  if (r.peakCell >= 0) {
    const std::int64_t nx = grid.dims[0], nxy = nx * grid.dims[1];
    out["peak_cell"] = py::make_tuple(r.peakCell % nx, (r.peakCell % nxy) / nx, r.peakCell / nxy);
  } else {
    out["peak_cell"] = py::none();
  }
  py::dict counts;
  const char* names[5] = {"background", "centred", "covered", "face_cube", "none"};
  for (int k = 0; k < 5; ++k) counts[names[k]] = r.count[std::size_t(k)];
  out["counts"] = counts;
  return out;
}

}  // namespace

void bindDosimetry(py::module_& m) {
  m.def("average_sar", &averageSar, py::arg("density"), py::arg("local_sar"), py::arg("edges_x"),
        py::arg("edges_y"), py::arg("edges_z"), py::arg("mass_kg") = 0.010, py::arg("threads") = 0,
        py::arg("progress") = py::none(),
        R"doc(Peak spatial-average SAR by IEC/IEEE 62704-1's cube rules (docs/DOSIMETRY.md).

density (kg/m^3, 0 = background) and local_sar (W/kg) are arrays [x, y, z] of a rectilinear grid
whose cell boundaries along x, y, z are edges_x, edges_y, edges_z (metres, one more than the
cells). Returns a dict: "sar" (W/kg per cell, averaged over mass_kg), "kind" (per cell: 0
background, 1 centre of a valid cube, 2 inside valid cubes, 3 at a face cube's face, 4 no cube
fits), "cube_edge_m", "peak", "peak_cell" (x, y, z indices) and "counts" (cells per kind).)doc");
}

}  // namespace repose::python

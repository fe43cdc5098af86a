// CGAL Surface_mesher (restricted Delaunay refinement, Boissonnat & Oudot 2005, the seed's [12]),
// Surface_mesh_simplification with Garland-Heckbert plane quadrics, and PMP checks.
#include "CageSurfaceCgal.h"

#include "repose/util/Error.h"

#include <CGAL/Complex_2_in_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_with_circumcenter_3.h>
#include <CGAL/Robust_circumcenter_traits_3.h>
#include <CGAL/Surface_mesh_cell_base_3.h>
#include <CGAL/Surface_mesh_vertex_base_3.h>
#include <CGAL/Triangulation_data_structure_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/facets_in_complex_2_to_triangle_mesh.h>
#include <CGAL/Implicit_surface_3.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_default_criteria_3.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_filter.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_placement.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/Random.h>
#include <CGAL/make_surface_mesh.h>

namespace repose::cage {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMS = CGAL::Surface_mesh_simplification;

Mesh toCgal(const TriangleMesh& m) {
  Mesh out;
  std::vector<Mesh::Vertex_index> v;
  v.reserve(m.vertices.rows());
  for (Eigen::Index i = 0; i < m.vertices.rows(); ++i)
    v.push_back(
        out.add_vertex(Kernel::Point_3(m.vertices(i, 0), m.vertices(i, 1), m.vertices(i, 2))));
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f)
    if (out.add_face(v[m.faces(f, 0)], v[m.faces(f, 1)], v[m.faces(f, 2)]) == Mesh::null_face())
      throw Error("cage: the surface is not a manifold triangle mesh (face " + std::to_string(f) +
                  ")");
  return out;
}

TriangleMesh fromCgal(const Mesh& m) {
  TriangleMesh out;
  std::map<Mesh::Vertex_index, int> index;
  out.vertices.resize(m.number_of_vertices(), 3);
  int n = 0;
  for (Mesh::Vertex_index v : m.vertices()) {
    const auto& p = m.point(v);
    out.vertices.row(n) << p.x(), p.y(), p.z();
    index[v] = n++;
  }
  out.faces.resize(m.number_of_faces(), 3);
  int f = 0;
  for (Mesh::Face_index face : m.faces()) {
    int c = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(m.halfedge(face), m))
      out.faces(f, c++) = index[v];
    ++f;
  }
  return out;
}

// Time stamps on the triangulation's vertices and cells. Without them CGAL orders its handles
// (the mesher's queue of bad facets, the complex's edge map) by memory address, so the same field
// gave different cages whenever the allocator placed blocks differently (AddressSanitizer's
// allocator with address-space randomization does): with them handles compare by creation order
// and the cage depends on the input alone.
template <class Base>
class Stamped : public Base {
 public:
  using Has_timestamp = CGAL::Tag_true;
  template <class Tds>
  struct Rebind_TDS {
    using Other = Stamped<typename Base::template Rebind_TDS<Tds>::Other>;
  };
  using Base::Base;
  std::size_t time_stamp() const { return stamp_; }
  void set_time_stamp(const std::size_t& stamp) { stamp_ = stamp; }

 private:
  std::size_t stamp_ = std::size_t(-1);
};

// CGAL's Surface_mesh_default_triangulation_3 with stamped vertices and cells.
using MesherTraits = CGAL::Robust_circumcenter_traits_3<Kernel>;
using MesherTds = CGAL::Triangulation_data_structure_3<
    Stamped<CGAL::Surface_mesh_vertex_base_3<MesherTraits>>,
    Stamped<CGAL::Delaunay_triangulation_cell_base_with_circumcenter_3<
        MesherTraits, CGAL::Surface_mesh_cell_base_3<MesherTraits>>>>;
using MesherTriangulation = CGAL::Delaunay_triangulation_3<MesherTraits, MesherTds>;

// Field value at a point of the mesher's space, which is the grid's millimetre frame.
struct FieldFunction {
  using GT = MesherTriangulation::Geom_traits;
  const CageField* field;
  GT::FT operator()(const GT::Point_3& p) const {
    return field->at(Eigen::Vector3d(p.x(), p.y(), p.z()));
  }
};

}  // namespace

TriangleMesh meshZeroLevelSet(const CageField& field, double facetRadiusMm,
                              double approximationMm) {
  using Tr = MesherTriangulation;
  using C2t3 = CGAL::Complex_2_in_triangulation_3<Tr>;
  using GT = Tr::Geom_traits;
  using Surface = CGAL::Implicit_surface_3<GT, FieldFunction>;
  const Eigen::Vector3d s = field.spacing();
  // Grid millimetres: (i*sx, j*sy, k*sz). The inside point must be inside the level set.
  const Eigen::Vector3d inside = field.grid.rasToVoxel(field.insidePoint).cwiseProduct(s);
  const Eigen::Vector3d extent = (field.grid.dims[0] - 1) * Eigen::Vector3d(s[0], 0, 0) +
                                 (field.grid.dims[1] - 1) * Eigen::Vector3d(0, s[1], 0) +
                                 (field.grid.dims[2] - 1) * Eigen::Vector3d(0, 0, s[2]);
  double r2 = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d c((corner & 1) ? extent[0] : 0, (corner & 2) ? extent[1] : 0,
                            (corner & 4) ? extent[2] : 0);
    r2 = std::max(r2, (c - inside).squaredNorm());
  }
  // The mesher draws its initial points from CGAL's default generator, seeded from the clock:
  // reseed it so the same segmentation always gives the same cage.
  CGAL::get_default_random() = CGAL::Random(0);
  Tr tr;
  C2t3 c2t3(tr);
  Surface surface(FieldFunction{&field},
                  GT::Sphere_3(GT::Point_3(inside.x(), inside.y(), inside.z()), r2), 1e-6);
  CGAL::Surface_mesh_default_criteria_3<Tr> criteria(30.0, facetRadiusMm, approximationMm);
  CGAL::make_surface_mesh(c2t3, surface, criteria, CGAL::Manifold_tag(), 40);
  Mesh mesh;
  CGAL::facets_in_complex_2_to_triangle_mesh(c2t3, mesh);
  if (mesh.number_of_faces() == 0) throw Error("cage: surface meshing produced no triangle");
  TriangleMesh out = fromCgal(mesh);
  for (Eigen::Index i = 0; i < out.vertices.rows(); ++i) {
    const Eigen::Vector3d ijk = out.vertices.row(i).transpose().cwiseQuotient(s);
    out.vertices.row(i) = field.grid.voxelToRas(ijk.x(), ijk.y(), ijk.z()).transpose();
  }
  return out;
}

const char* simplificationName(Simplification s) {
  return s == Simplification::GarlandHeckbert ? "garland-heckbert" : "lindstrom-turk";
}

TriangleMesh simplifyMesh(const TriangleMesh& input, int targetVertices, Simplification policy,
                          const std::vector<bool>& frozen) {
  Mesh mesh = toCgal(input);
  if (static_cast<int>(mesh.number_of_vertices()) <= targetVertices) return input;
  // Vertex i of `input` is vertex index i of `mesh` (toCgal adds them in order).
  auto constrained = mesh.add_property_map<Mesh::Edge_index, bool>("e:frozen", false).first;
  if (!frozen.empty())
    for (Mesh::Edge_index e : mesh.edges())
      if (frozen[mesh.vertex(e, 0)] || frozen[mesh.vertex(e, 1)]) constrained[e] = true;
  // A closed genus-g triangle mesh has E = 3V - 6 + 6g edges: stop at the edge count of V targets.
  const std::size_t targetEdges = static_cast<std::size_t>(3 * targetVertices - 6);
  SMS::Count_stop_predicate<Mesh> stop(targetEdges);
  if (policy == Simplification::GarlandHeckbert) {
    using GH = SMS::GarlandHeckbert_plane_policies<Mesh, Kernel>;
    GH gh(mesh);
    SMS::edge_collapse(mesh, stop,
                       CGAL::parameters::get_cost(gh.get_cost())
                           .get_placement(gh.get_placement())
                           .filter(SMS::Bounded_normal_change_filter<>())
                           .edge_is_constrained_map(constrained));
  } else {
    SMS::edge_collapse(
        mesh, stop,
        CGAL::parameters::get_cost(SMS::LindstromTurk_cost<Mesh>())
            .get_placement(
                SMS::Bounded_normal_change_placement<SMS::LindstromTurk_placement<Mesh>>())
            .filter(SMS::Bounded_normal_change_filter<>())
            .edge_is_constrained_map(constrained));
  }
  mesh.collect_garbage();
  return fromCgal(mesh);
}

std::vector<Eigen::Vector3d> selfIntersectionSites(const TriangleMesh& m) {
  const Mesh mesh = toCgal(m);
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(mesh, std::back_inserter(pairs));
  std::vector<Eigen::Vector3d> sites;
  for (const auto& [f, g] : pairs)
    for (Mesh::Face_index face : {f, g}) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(face), mesh)) {
        const auto& p = mesh.point(v);
        c += Eigen::Vector3d(p.x(), p.y(), p.z()) / 3;
      }
      sites.push_back(c);
    }
  return sites;
}

MeshChecks checkAndOrient(TriangleMesh& m) {
  MeshChecks c;
  Mesh mesh;
  try {
    mesh = toCgal(m);
  } catch (const Error&) {
    return c;  // not even a manifold polygon mesh: every check fails
  }
  c.closed = CGAL::is_closed(mesh);
  std::vector<Mesh::Halfedge_index> nonManifold;  // one halfedge per non-manifold vertex
  PMP::non_manifold_vertices(mesh, std::back_inserter(nonManifold));
  c.manifold = nonManifold.empty() && CGAL::is_valid_polygon_mesh(mesh);
  if (c.closed && c.manifold) {
    if (!PMP::is_outward_oriented(mesh)) {
      PMP::reverse_face_orientations(mesh);
      m.faces.col(1).swap(m.faces.col(2));
    }
    c.outward = PMP::is_outward_oriented(mesh);
  }
  c.selfIntersectionFree = !PMP::does_self_intersect(mesh);
  return c;
}

}  // namespace repose::cage

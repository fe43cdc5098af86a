// The only translation unit with CGAL Mesh_3 (slow to compile): a labelled-image domain made in
// memory from S, meshed with the sizing field as cell and facet size, cells in the complex kept
// with their subdomain (the body-part label) as tet label.
#include "repose/mesh/TransferMesh.h"

#include "repose/util/Error.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/Mesh_3/initialize_triangulation_from_labeled_image.h>
#include <CGAL/make_mesh_3.h>

#include <Eigen/LU>
#include <cstring>
#include <iostream>
#include <map>
#include <sstream>

namespace repose {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Labeled_mesh_domain_3<Kernel>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;
using Point = Kernel::Point_3;

// Mesh_3 works in the padded image's millimetre frame; this maps it to RAS.
struct Frame {
  VolumeGeometry grid;  // S's geometry
  Eigen::Vector3d spacing;
  std::int64_t pad = 2;
  Eigen::Vector3d toRas(double x, double y, double z) const {
    return grid.voxelToRas(x / spacing[0] - pad, y / spacing[1] - pad, z / spacing[2] - pad);
  }
};

// Sizing field as Mesh_3 wants it: a size at a point of the image frame.
struct SizeFunction {
  using FT = Kernel::FT;
  using Point_3 = Kernel::Point_3;
  using Index = Domain::Index;
  const SizingField* field;
  const Frame* frame;
  double scale;
  FT operator()(const Point_3& p, int, const Index&) const {
    return scale * field->at(frame->toRas(p.x(), p.y(), p.z()));
  }
};

// CGAL's labelled-image initializer reports to std::cout, where `repose ... --json` writes its
// JSON: its lines go nowhere while it runs.
class QuietStdout {
 public:
  QuietStdout() : old_(std::cout.rdbuf(sink_.rdbuf())) {}
  ~QuietStdout() { std::cout.rdbuf(old_); }
  QuietStdout(const QuietStdout&) = delete;
  QuietStdout& operator=(const QuietStdout&) = delete;

 private:
  std::ostringstream sink_;
  std::streambuf* old_;
};

// Subdomain index -> the body part it meshes, for finding the parts' connected components (a
// piece inside a part belongs to the part's component).
struct PartOfSubdomain {
  using result_type = std::uint16_t;
  const std::vector<std::pair<int, int>>* subdomains = nullptr;  // null: the index is the part
  std::uint16_t operator()(std::uint16_t word) const {
    return subdomains ? std::uint16_t((*subdomains)[word].first) : word;
  }
};

}  // namespace

TransferMesh buildTransferMesh(const Volume& parts, const TransferMeshOptions& options,
                               TransferMeshReport* report) {
  if (!isIntegerType(parts.scalarType()))
    throw Error("the transfer mesh needs a label map (integer voxels), not float32");
  const VolumeGeometry& g = parts.geometry();
  Frame frame{g, g.spacing(), 2};
  // The image is padded with background so labels touching the volume border are closed.
  const std::int64_t nx = g.dims[0] + 2 * frame.pad, ny = g.dims[1] + 2 * frame.pad,
                     nz = g.dims[2] + 2 * frame.pad;
  _image* img = _createImage(nx, ny, nz, 1, frame.spacing[0], frame.spacing[1], frame.spacing[2], 2,
                             WK_FIXED, SGN_UNSIGNED);
  if (!img) throw Error("cannot allocate the meshing image");
  auto* data = static_cast<std::uint16_t*>(img->data);
  std::memset(data, 0, static_cast<std::size_t>(nx * ny * nz) * 2);
  // With rigid tissue every (body part, bone label) pair present is a subdomain of its own.
  const Volume* rigid = options.rigidTissue;
  if (rigid && rigid->dims() != parts.dims()) {
    _freeImage(img);
    throw Error("the rigid-tissue map is not on the grid of the body-part map");
  }
  std::map<std::pair<int, int>, std::uint16_t> subdomainOf;
  std::vector<std::pair<int, int>> subdomains{{0, 0}};  // index -> (part, bone)
  std::int64_t body = 0;
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) {
        const double v = parts.valueAsDouble(parts.index(i, j, k));
        if (v < 0 || v > 65535) {
          _freeImage(img);
          throw Error("labels must be in 0..65535 to be meshed");
        }
        std::uint16_t word = static_cast<std::uint16_t>(v);
        if (rigid && word != 0) {
          const std::pair<int, int> key{int(v), int(rigid->valueAsDouble(parts.index(i, j, k)))};
          auto [it, fresh] = subdomainOf.try_emplace(key, std::uint16_t(subdomains.size()));
          if (fresh) {
            if (subdomains.size() > 65535) {
              _freeImage(img);
              throw Error("too many (body part, bone) pairs to mesh");
            }
            subdomains.push_back(key);
          }
          word = it->second;
        }
        data[(i + frame.pad) + nx * ((j + frame.pad) + ny * (k + frame.pad))] = word;
        body += v != 0;
      }
  if (body == 0) {
    _freeImage(img);
    throw Error("the segmentation is empty: there is nothing to mesh");
  }
  const CGAL::Image_3 image(img);  // takes ownership

  SizingField uniform;
  const SizingField* sizing = options.sizing;
  if (!sizing) {
    double size = options.sizeMm;
    if (size <= 0) {
      const auto [lo, hi] = g.rasBounds();
      size = 0.05 * (hi - lo).norm();
    }
    uniform = SizingField::uniform(g, size);
    sizing = &uniform;
  }
  reportProgress(options.progress, 0.05, "transfer mesh");
  CGAL::Random rng(0);  // the same S and field give the same mesh in a fresh process
  CGAL::get_default_random() = CGAL::Random(0);
  const Domain domain = Domain::create_labeled_image_mesh_domain(
      image, CGAL::parameters::relative_error_bound = 1e-6, CGAL::parameters::p_rng = &rng);
  const double voxel = frame.spacing.maxCoeff();
  const SizeFunction cellSize{sizing, &frame, 1.0};
  const SizeFunction facetSize{sizing, &frame, 1.0};
  // Facets follow the label boundaries to within a voxel; cells take the field's size.
  namespace p = CGAL::parameters;
  const Criteria criteria(p::facet_angle = 25, p::facet_size = facetSize, p::facet_distance = voxel,
                          p::cell_radius_edge_ratio = 3, p::cell_size = cellSize);
  // Exudation removes slivers (without it dihedral angles go down to 0.1 degree, which makes the
  // tets' linear maps ill-conditioned); no time limit, since a limit makes the result depend on
  // the machine's speed. Perturbation costs seconds for little more.
  // The initial points come from every connected component of every body part (points on its
  // surface seen from its deepest voxel), not only from rays shot from the image's centre: those
  // can miss a small part, and a hand on 8 mm slices got no tet at all (CGAL's
  // initialize_triangulation_from_labeled_image, as in its mesh_3D_image_with_custom_initialization
  // example). Components of parts, not of every (part, piece) subdomain: seeding each bone
  // fragment of a thick-slice map made five times the tets.
  C3t3 c3t3;
  {
    const QuietStdout quiet;
    initialize_triangulation_from_labeled_image(c3t3, domain, image, criteria, std::uint16_t(),
                                                false,
                                                PartOfSubdomain{rigid ? &subdomains : nullptr});
  }
  CGAL::refine_mesh_3(c3t3, domain, criteria, CGAL::parameters::no_perturb(),
                      CGAL::parameters::exude(CGAL::parameters::time_limit = 0,
                                              CGAL::parameters::sliver_bound = 10));
  reportProgress(options.progress, 0.9, "transfer mesh");

  TransferMesh mesh;
  std::map<Tr::Vertex_handle, int> index;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::RowVector4i> tets;
  std::vector<int> labels;
  std::vector<int> rigidTets;
  TransferMeshReport r;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    Eigen::RowVector4i t;
    for (int v = 0; v < 4; ++v) {
      const Tr::Vertex_handle h = c->vertex(v);
      auto [it, fresh] = index.try_emplace(h, static_cast<int>(vertices.size()));
      if (fresh) {
        const auto& p = h->point().point();
        vertices.push_back(frame.toRas(p.x(), p.y(), p.z()));
      }
      t[v] = it->second;
    }
    tets.push_back(t);
    const int subdomain = static_cast<int>(c3t3.subdomain_index(c));
    labels.push_back(rigid ? subdomains.at(std::size_t(subdomain)).first : subdomain);
    if (rigid) rigidTets.push_back(subdomains.at(std::size_t(subdomain)).second);
  }
  if (tets.empty())
    throw Error("meshing produced no tetrahedron (is the segmentation thinner than a voxel?)");
  mesh.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v) mesh.vertices.row(v) = vertices[v];
  mesh.tets.resize(static_cast<Eigen::Index>(tets.size()), 4);
  mesh.labels.resize(static_cast<Eigen::Index>(tets.size()));
  for (std::size_t i = 0; i < tets.size(); ++i)
    mesh.tets.row(i) = tets[i], mesh.labels[i] = labels[i];
  mesh.rigid = std::move(rigidTets);
  // CGAL's cells are positively oriented in the image frame; a mirrored IJK->RAS (LPS-like grids)
  // flips them all, which is not an inversion.
  mesh.sourceSpacingMm = g.spacing().maxCoeff();
  cleanTransferMesh(mesh, g.ijkToRas.block<3, 3>(0, 0).determinant() < 0 ? -1.0 : 1.0, r);
  if (mesh.tets.rows() == 0) throw Error("meshing produced only degenerate tetrahedra");
  // The balls of tiny tets where labels meet (TetEdgeCollapse.cpp): edges under half the finest
  // voxel go (docs/ARCHITECTURE.md, "The transfer mesh").
  const int collapsed = collapseShortEdges(mesh, 0.5 * frame.spacing.minCoeff());
  if (collapsed > 0) {
    const int inverted = r.invertedTets, degenerate = r.degenerateTets;
    cleanTransferMesh(mesh, 1.0, r);
    r.invertedTets = inverted, r.degenerateTets += degenerate;
  }
  r.collapsedEdges = collapsed;
  if (report) *report = r;
  reportProgress(options.progress, 1.0, "transfer mesh");
  return mesh;
}

}  // namespace repose

// ARAP cage deformation: rigid handle motions give rigid results, the energy never increases,
// bad handle sets are refused, and results agree with CGAL's Surface_mesh_deformation (ARAP).
#include "TestMeshes.h"

#include "repose/cage/ArapDeformer.h"
#include "repose/util/Error.h"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_deformation.h>
#include <gtest/gtest.h>

using namespace repose;
using namespace repose::test;

namespace {

// An ellipsoid cage, 300 mm long, with handles on both ends (x < -100 and x > 100).
TriangleMesh limbCage() {
  TriangleMesh m = sphereMesh({0, 0, 0}, 1, 3);
  m.vertices = m.vertices * Eigen::Vector3d(150, 60, 50).asDiagonal();
  return m;
}

std::vector<int> verticesWhere(const TriangleMesh& m, bool (*pred)(const Eigen::Vector3d&)) {
  std::vector<int> out;
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
    if (pred(m.vertices.row(v))) out.push_back(static_cast<int>(v));
  return out;
}

// Left end fixed, right end rotated by `angle` about the z axis through the right end's centre
// and lifted: a bend.
Eigen::MatrixX3d bendTargets(const TriangleMesh& m, const std::vector<int>& left,
                             const std::vector<int>& right, double angle) {
  Eigen::MatrixX3d t(left.size() + right.size(), 3);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d pivot(120, 0, 0);
  for (std::size_t i = 0; i < left.size(); ++i) t.row(i) = m.vertices.row(left[i]);
  for (std::size_t i = 0; i < right.size(); ++i)
    t.row(left.size() + i) =
        (R * (m.vertices.row(right[i]).transpose() - pivot) + pivot + Eigen::Vector3d(0, 40, 0))
            .transpose();
  return t;
}

}  // namespace

TEST(ArapDeformer, RigidMotionOfAllHandlesMovesTheCageRigidly) {
  const TriangleMesh cage = limbCage();
  ArapDeformer arap(cage);
  const auto handles =
      verticesWhere(cage, [](const Eigen::Vector3d& p) { return std::fabs(p.x()) > 100; });
  ASSERT_GT(handles.size(), 10u);
  arap.setHandles(handles);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(10, -300, 42);
  Eigen::MatrixX3d targets(handles.size(), 3);
  for (std::size_t h = 0; h < handles.size(); ++h)
    targets.row(h) = cage.vertices.row(handles[h]) * R.transpose() + t;
  ArapOptions o;
  o.maxIterations = 2000;
  o.tolerance = 1e-15;  // iterate to convergence: the rigid motion is the exact minimum
  const ArapResult r = arap.solve(targets, nullptr, o);
  const Eigen::MatrixX3d expected = (cage.vertices * R.transpose()).rowwise() + t;
  EXPECT_LT((r.positions - expected).rowwise().norm().maxCoeff(), 1e-6 * 300);
  EXPECT_LT(arap.energy(r.positions), 1e-9);
}

TEST(ArapDeformer, EnergyDecreasesMonotonically) {
  const TriangleMesh cage = limbCage();
  ArapDeformer arap(cage);
  const auto left = verticesWhere(cage, [](const Eigen::Vector3d& p) { return p.x() < -100; });
  const auto right = verticesWhere(cage, [](const Eigen::Vector3d& p) { return p.x() > 100; });
  std::vector<int> handles = left;
  handles.insert(handles.end(), right.begin(), right.end());
  arap.setHandles(handles);
  ArapOptions o;
  o.maxIterations = 40;
  o.tolerance = 0;
  const ArapResult r = arap.solve(bendTargets(cage, left, right, 0.8), nullptr, o);
  ASSERT_EQ(r.iterations, 40);
  for (std::size_t i = 1; i < r.energies.size(); ++i)
    EXPECT_LE(r.energies[i], r.energies[i - 1] * (1 + 1e-12)) << "iteration " << i;
  EXPECT_LT(r.energies.back(), r.energies.front());
  // Converging: the last step gains far less than the first.
  EXPECT_LT(r.energies[38] - r.energies[39], 1e-2 * (r.energies[0] - r.energies[1]));
  // Handles sit exactly on their targets.
  const Eigen::MatrixX3d targets = bendTargets(cage, left, right, 0.8);
  for (std::size_t h = 0; h < handles.size(); ++h)
    EXPECT_LT((r.positions.row(handles[h]) - targets.row(h)).norm(), 1e-12);
}

TEST(ArapDeformer, RefusesBadHandleSets) {
  ArapDeformer arap(limbCage());
  EXPECT_THROW(arap.setHandles({}), Error);
  EXPECT_THROW(arap.setHandles({0, 100000}), Error);
  EXPECT_THROW(arap.setHandles({3, 3}), Error);
  EXPECT_THROW(arap.solve(Eigen::MatrixX3d::Zero(1, 3)), Error);  // no handles set yet
  arap.setHandles({0, 1});
  EXPECT_THROW(arap.solve(Eigen::MatrixX3d::Zero(3, 3)), Error);  // wrong target count
}

TEST(ArapDeformer, AgreesWithCgalSurfaceMeshDeformation) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  using Deformation =
      CGAL::Surface_mesh_deformation<Mesh, CGAL::Default, CGAL::Default, CGAL::ORIGINAL_ARAP>;
  const TriangleMesh cage = limbCage();
  const auto left = verticesWhere(cage, [](const Eigen::Vector3d& p) { return p.x() < -100; });
  const auto right = verticesWhere(cage, [](const Eigen::Vector3d& p) { return p.x() > 100; });
  std::vector<int> handles = left;
  handles.insert(handles.end(), right.begin(), right.end());
  const Eigen::MatrixX3d targets = bendTargets(cage, left, right, 0.6);

  Mesh mesh;
  std::vector<Mesh::Vertex_index> vs;
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v)
    vs.push_back(mesh.add_vertex(
        Kernel::Point_3(cage.vertices(v, 0), cage.vertices(v, 1), cage.vertices(v, 2))));
  for (Eigen::Index f = 0; f < cage.faces.rows(); ++f)
    mesh.add_face(vs[cage.faces(f, 0)], vs[cage.faces(f, 1)], vs[cage.faces(f, 2)]);
  Deformation cgal(mesh);
  cgal.insert_roi_vertices(mesh.vertices().begin(), mesh.vertices().end());
  for (int h : handles) cgal.insert_control_vertex(vs[h]);
  ASSERT_TRUE(cgal.preprocess());
  for (std::size_t h = 0; h < handles.size(); ++h)
    cgal.set_target_position(vs[handles[h]],
                             Kernel::Point_3(targets(h, 0), targets(h, 1), targets(h, 2)));
  cgal.deform(500, 1e-10);

  ArapDeformer arap(cage);
  arap.setHandles(handles);
  ArapOptions o;
  o.maxIterations = 500;
  o.tolerance = 1e-10;
  const ArapResult ours = arap.solve(targets, nullptr, o);
  double worst = 0;
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v) {
    const auto& p = mesh.point(vs[v]);
    worst =
        std::max(worst, (ours.positions.row(v) - Eigen::RowVector3d(p.x(), p.y(), p.z())).norm());
  }
  // Same energy and weights: the converged cages agree to a small fraction of the 300 mm length.
  EXPECT_LT(worst, 0.5) << "max vertex distance to CGAL's result, mm";
  std::cout << "max distance to CGAL ARAP: " << worst << " mm after " << ours.iterations
            << " iterations\n";
}

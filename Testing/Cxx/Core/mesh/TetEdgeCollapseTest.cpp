// collapseShortEdges (mesh/TetEdgeCollapse.cpp) on boxes of tets with balls of tiny tets put in
// where Mesh_3 leaves them: inside, on the surface and on an interface between two labels. The
// balls go, every tet stays positive, the mesh stays a manifold with the same boundary, the box's
// volume is kept (exactly when the ball is inside) and every label keeps its tets; a lone tet, or
// any edge the link condition forbids, is left alone.
#include "../../TestTetMeshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>

using namespace repose;

namespace {

double totalVolume(const TransferMesh& m) {
  double v = 0;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) v += tetVolume(m.vertices, m.tets.row(t));
  return v;
}

double shortestEdge(const TransferMesh& m) {
  double l = 1e300;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        l = std::min(l, (m.vertices.row(m.tets(t, a)) - m.vertices.row(m.tets(t, b))).norm());
  return l;
}

// Faces of the mesh and how many tets hold each: 1 on the boundary, 2 inside, never more.
std::map<std::array<int, 3>, int> faceCounts(const TransferMesh& m) {
  std::map<std::array<int, 3>, int> faces;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (k != skip) f[std::size_t(n++)] = m.tets(t, k);
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  return faces;
}

// The boundary's area: the surface the mesh encloses.
double boundaryArea(const TransferMesh& m) {
  double a = 0;
  for (const auto& [f, n] : faceCounts(m))
    if (n == 1)
      a += 0.5 * (m.vertices.row(f[1]) - m.vertices.row(f[0]))
                     .cross(m.vertices.row(f[2]) - m.vertices.row(f[0]))
                     .norm();
  return a;
}

// Splits, `times` over, a tet at corner `v` at a point a tiny step inside it (1 tet into 4), each
// time one of the new tets at v: a ball of tets with edges of `size` mm and less around v.
void growBall(TransferMesh& m, int v, int times, double size, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.2, 1.0);
  for (int i = 0; i < times; ++i) {
    std::vector<Eigen::Index> at;
    for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
      for (int k = 0; k < 4; ++k)
        if (m.tets(t, k) == v) at.push_back(t);
    const Eigen::Index t = at[std::size_t(rng()) % at.size()];
    const Eigen::RowVector4i c = m.tets.row(t);
    // A point inside the tet, near v.
    Eigen::Vector3d w(u(rng), u(rng), u(rng));
    Eigen::Vector3d q = m.vertices.row(v).transpose();
    double edge = 0;
    for (int k = 0; k < 4; ++k)
      if (c[k] != v) edge = std::max(edge, (m.vertices.row(c[k]) - m.vertices.row(v)).norm());
    int j = 0;
    for (int k = 0; k < 4; ++k)
      if (c[k] != v)
        q += size / edge / 3 * w[j++] * (m.vertices.row(c[k]) - m.vertices.row(v)).transpose();
    const int p = int(m.vertices.rows());
    m.vertices.conservativeResize(p + 1, 3);
    m.vertices.row(p) = q.transpose();
    const int label = m.labels[t];
    m.tets.conservativeResize(m.tets.rows() + 3, 4);
    m.labels.conservativeResize(m.labels.size() + 3);
    for (int k = 0; k < 4; ++k) {
      Eigen::RowVector4i s = c;
      s[k] = p;
      const Eigen::Index row = k == 0 ? t : m.tets.rows() - 4 + k;
      m.tets.row(row) = s;
      m.labels[row] = label;
    }
  }
}

int vertexAt(const TransferMesh& m, const Eigen::Vector3d& p) {
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
    if ((m.vertices.row(v).transpose() - p).norm() < 1e-9) return int(v);
  return -1;
}

void expectValid(const TransferMesh& m) {
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
    EXPECT_GT(tetVolume(m.vertices, m.tets.row(t)), 0) << "tet " << t;
  for (const auto& [f, n] : faceCounts(m)) EXPECT_LE(n, 2) << "a face in " << n << " tets";
}

}  // namespace

TEST(TetEdgeCollapse, ABallOfTinyTetsInsideGoesAndTheVolumeIsExact) {
  TransferMesh m = test::tetBox({0, 0, 0}, {40, 40, 40}, {4, 4, 4});
  std::mt19937 rng(1);
  growBall(m, vertexAt(m, {20, 20, 20}), 40, 0.05, rng);
  const double volume = totalVolume(m), area = boundaryArea(m);
  const Eigen::Index tets = m.tets.rows();
  ASSERT_LT(shortestEdge(m), 0.05);
  const int collapsed = collapseShortEdges(m, 1.0);
  EXPECT_GE(collapsed, 40);
  EXPECT_GE(shortestEdge(m), 1.0);
  EXPECT_LE(m.tets.rows(), tets - 80);  // each collapse drops the tets around its edge
  expectValid(m);
  EXPECT_NEAR(totalVolume(m), volume, 1e-9 * volume);  // inside: the box tiles the same space
  EXPECT_NEAR(boundaryArea(m), area, 1e-9 * area);
  EXPECT_EQ(m.vertices.rows(), 5 * 5 * 5);  // no vertex left unused
}

TEST(TetEdgeCollapse, ABallOnTheSurfaceGoesAndTheSurfaceStaysClosed) {
  TransferMesh m = test::tetBox({0, 0, 0}, {40, 40, 40}, {4, 4, 4});
  std::mt19937 rng(2);
  growBall(m, vertexAt(m, {20, 20, 40}), 30, 0.05, rng);  // a vertex of the top face
  growBall(m, vertexAt(m, {40, 40, 40}), 10, 0.05, rng);  // a corner
  const double volume = totalVolume(m);
  collapseShortEdges(m, 1.0);
  EXPECT_GE(shortestEdge(m), 1.0);
  expectValid(m);
  // Every boundary edge in exactly two boundary faces: a closed surface.
  std::map<std::pair<int, int>, int> edges;
  for (const auto& [f, n] : faceCounts(m))
    if (n == 1)
      for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3;
        ++edges[{std::min(f[std::size_t(a)], f[std::size_t(b)]),
                 std::max(f[std::size_t(a)], f[std::size_t(b)])}];
      }
  for (const auto& [e, n] : edges) EXPECT_EQ(n, 2);
  // The surface moved by at most the ball's size: the volume by at most that times the area.
  EXPECT_NEAR(totalVolume(m), volume, 0.1 * 40 * 40);
}

TEST(TetEdgeCollapse, ABallOnAnInterfaceLeavesBothLabelsTheirTets) {
  TransferMesh m = test::tetBox({0, 0, 0}, {40, 40, 40}, {4, 4, 4});
  std::map<int, double> before;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += m.vertices.row(m.tets(t, k)).transpose() / 4;
    m.labels[t] = c.x() < 20 ? 1 : 2;
  }
  std::mt19937 rng(3);
  growBall(m, vertexAt(m, {20, 20, 20}), 40, 0.05, rng);
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
    before[m.labels[t]] += tetVolume(m.vertices, m.tets.row(t));
  collapseShortEdges(m, 1.0);
  expectValid(m);
  EXPECT_GE(shortestEdge(m), 1.0);
  std::map<int, double> after;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
    after[m.labels[t]] += tetVolume(m.vertices, m.tets.row(t));
  ASSERT_EQ(after.size(), 2u);
  for (const auto& [label, v] : before) EXPECT_NEAR(after[label], v, 1e-3 * v) << "label " << label;
}

TEST(TetEdgeCollapse, ALoneTetOrAnEdgeLongerThanTheBoundIsLeftAlone) {
  TransferMesh lone;
  lone.vertices.resize(4, 3);
  lone.vertices << 0, 0, 0, 0.01, 0, 0, 0, 1, 0, 0, 0, 1;
  lone.tets.resize(1, 4);
  lone.tets << 0, 1, 2, 3;
  lone.labels = Eigen::VectorXi::Constant(1, 1);
  EXPECT_EQ(collapseShortEdges(lone, 1.0), 0);  // the link condition: it would vanish
  EXPECT_EQ(lone.tets.rows(), 1);

  TransferMesh box = test::tetBox({0, 0, 0}, {40, 40, 40}, {4, 4, 4});
  const TransferMesh copy = box;
  EXPECT_EQ(collapseShortEdges(box, 5.0), 0);  // every edge is 10 mm or more
  EXPECT_TRUE(box.tets == copy.tets);
  EXPECT_TRUE(box.vertices == copy.vertices);
}

// The checks a pose runs on its posed mesh before and after the voxels: rigid pieces run into
// each other (raster/PieceOverlap.h) and the body volume the posed tets predict
// (mesh/VolumePrediction.h), against volumes computed by hand.
#include "repose/mesh/VolumePrediction.h"
#include "repose/raster/PieceOverlap.h"

#include "../TestTetMeshes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace repose;

namespace {

// Two 20 mm cubes side by side along x, each a piece of its own bone (G labels 11 and 12) in its
// own body part (S labels 3 and 4), with a 2 mm gap between them.
TransferMesh twoBones() {
  TransferMesh a = test::tetBox({0, 0, 0}, {20, 20, 20}, {2, 2, 2}, 3);
  TransferMesh b = test::tetBox({22, 0, 0}, {42, 20, 20}, {2, 2, 2}, 4);
  TransferMesh m = test::concatenate(a, b);
  m.rigid.assign(std::size_t(m.tets.rows()), 11);
  for (Eigen::Index t = a.tets.rows(); t < m.tets.rows(); ++t) m.rigid[std::size_t(t)] = 12;
  return m;
}

VolumeGeometry grid1mm() {
  VolumeGeometry g;
  g.dims = {60, 30, 30};
  g.ijkToRas = Eigen::Matrix4d::Identity();
  g.ijkToRas.block<3, 1>(0, 3) = Eigen::Vector3d(-10.25, -5.25, -5.25);
  return g;
}

}  // namespace

TEST(PieceOverlap, PiecesApartShareNoVoxel) {
  const TransferMesh m = twoBones();
  EXPECT_TRUE(pieceOverlaps(m, m.vertices, grid1mm()).empty());
  // Moved together as one, still apart.
  Eigen::MatrixX3d moved = m.vertices;
  moved.rowwise() += Eigen::RowVector3d(3, -2, 1);
  EXPECT_TRUE(pieceOverlaps(m, moved, grid1mm()).empty());
}

TEST(PieceOverlap, APieceMovedIntoAnotherIsCountedByItsVoxels) {
  const TransferMesh m = twoBones();
  Eigen::MatrixX3d moved = m.vertices;
  // The second bone 8 mm into the first: 6 mm x 20 x 20 of overlap, 2400 voxels of 1 mm^3.
  for (Eigen::Index v = 27; v < moved.rows(); ++v) moved(v, 0) -= 8;
  const std::vector<PieceOverlap> o = pieceOverlaps(m, moved, grid1mm());
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].a.label, 11);
  EXPECT_EQ(o[0].a.part, 3);
  EXPECT_EQ(o[0].b.label, 12);
  EXPECT_EQ(o[0].b.part, 4);
  EXPECT_NEAR(double(o[0].voxels), 2400, 0.05 * 2400);
  // The same bone label in two body parts (a left and a right humerus alike in G) is two pieces.
  TransferMesh same = m;
  std::fill(same.rigid.begin(), same.rigid.end(), 11);
  const std::vector<PieceOverlap> s = pieceOverlaps(same, moved, grid1mm());
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].a.part, 3);
  EXPECT_EQ(s[0].b.part, 4);
  // Soft tissue over a piece is no collision.
  TransferMesh soft = m;
  for (Eigen::Index t = 48; t < soft.tets.rows(); ++t) soft.rigid[std::size_t(t)] = 0;
  EXPECT_TRUE(pieceOverlaps(soft, moved, grid1mm()).empty());
}

TEST(VolumePrediction, ARigidMotionKeepsEveryPartAndAStretchIsNamedWithWhatDragsIt) {
  // Two parts sharing the face x = 20.
  TransferMesh m = test::tetBox({0, 0, 0}, {40, 20, 20}, {4, 2, 2}, 3);
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += m.vertices.row(m.tets(t, k)).transpose() / 4;
    m.labels[t] = c.x() < 20 ? 3 : 4;
  }
  const Eigen::Isometry3d turn(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  Eigen::MatrixX3d rigid(m.vertices.rows(), 3);
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
    rigid.row(v) = (turn * Eigen::Vector3d(m.vertices.row(v))).transpose();
  const VolumePrediction same = predictVolumeChange(m, rigid);
  EXPECT_NEAR(same.restMm3, 40.0 * 20 * 20, 1e-6);
  EXPECT_NEAR(same.changePercent(), 0, 1e-9);
  for (const PartVolumeChange& p : same.parts) EXPECT_NEAR(p.changePercent(), 0, 1e-9);
  // Part 4 pulled away along x drags part 3's vertices at their shared face: part 3 does not
  // move except there, so its tets next to part 4 stretch.
  Eigen::MatrixX3d pulled = m.vertices;
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
    if (m.vertices(v, 0) >= 20 - 1e-9) pulled(v, 0) += 10;
  const VolumePrediction p = predictVolumeChange(m, pulled);
  // Part 3 spans x 0..20, its last layer of cubes (10 mm) now spans 20 mm: +50 %.
  EXPECT_EQ(p.worstPart, 3);
  EXPECT_EQ(p.draggedBy, 4);
  EXPECT_NEAR(p.changePercent(), 100.0 * 10 * 20 * 20 / (40 * 20 * 20), 1e-6);
  EXPECT_EQ(p.parts.size(), 2u);
  EXPECT_NEAR(p.parts[0].changePercent(), 50, 1e-6);
  EXPECT_NEAR(p.parts[1].changePercent(), 0, 1e-6);
}

TEST(VolumePrediction, ATetTurnedInsideOutCountsAgainstTheBody) {
  TransferMesh m = test::tetBox({0, 0, 0}, {10, 10, 10}, {1, 1, 1}, 1);
  Eigen::MatrixX3d mirrored = m.vertices;
  mirrored.col(0) *= -1;  // every tet inside out: the prediction says the body is gone twice over
  const VolumePrediction p = predictVolumeChange(m, mirrored);
  EXPECT_NEAR(p.changePercent(), -200, 1e-9);
  EXPECT_THROW(predictVolumeChange(m, Eigen::MatrixX3d::Zero(3, 3)), std::exception);
}

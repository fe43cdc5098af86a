// Fixtures the rasterizer's tests share: the 4 mm phantom's scene (organs, parts, cage, transfer
// mesh, deformation), made once per test binary, and a bone whose end lies in soft tets.
#pragma once

#include "TestTetMeshes.h"

#include "repose/cage/CageBuilder.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"

#include <Eigen/Geometry>
#include <memory>
#include <tuple>

namespace repose::test {

inline VolumeGeometry unitGrid(std::array<std::int64_t, 3> dims) {
  return VolumeGeometry::make(dims, {1, 1, 1}, {0, 0, 0});
}

struct PhantomScene {
  Phantom phantom;
  Volume organs, parts;
  TriangleMesh cage;
  TransferMesh mesh;
  std::unique_ptr<CageDeformation> deformation;
};

inline const PhantomScene& phantomScene() {
  static const PhantomScene* s = [] {
    PhantomOptions po;
    po.voxelMm = 4;
    auto* p = new PhantomScene{Phantom(po), {}, {}, {}, {}, nullptr};
    std::tie(p->organs, p->parts) = p->phantom.makeVolumes();
    p->cage = buildCage(p->parts, {}).mesh;
    p->mesh = buildTransferMesh(p->parts, {});
    p->deformation = std::make_unique<CageDeformation>(p->mesh, p->cage);
    return p;
  }();
  return *s;
}

// A bone (label 5) filling a box meshed as tets: those beyond x = 14 are soft, and their far
// vertices follow a shear (the other side of a bent joint) instead of the bone's turn `motion`.
struct BoneEnd {
  TransferMesh mesh;
  Eigen::Isometry3d motion;
  Eigen::MatrixX3d deformed;
  int softTets = 0;
  // The bone's labels (G, label `bone`) and its body part (S, label 1) on a 36 x 36 x 14 grid.
  VolumeGeometry grid;
  Volume G, S;
};
inline BoneEnd boneEndInSoftTets() {
  BoneEnd b;
  b.mesh = tetBox({2, 2, 2}, {20, 11, 11}, {6, 3, 3});
  b.mesh.rigid.assign(std::size_t(b.mesh.tets.rows()), 0);
  for (Eigen::Index t = 0; t < b.mesh.tets.rows(); ++t) {
    double x = 0;
    for (int c = 0; c < 4; ++c) x += b.mesh.vertices(b.mesh.tets(t, c), 0) / 4;
    if (x < 14)
      b.mesh.rigid[std::size_t(t)] = 5;
    else
      ++b.softTets;
  }
  b.motion = Eigen::Translation3d(14, 12, 6) * Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()) *
             Eigen::Translation3d(-2, -6, -6);
  b.deformed = b.mesh.vertices;
  for (Eigen::Index v = 0; v < b.deformed.rows(); ++v) {
    const Eigen::Vector3d p = b.mesh.vertices.row(v).transpose();
    Eigen::Vector3d q = b.motion * p;
    if (p.x() > 14) q.y() -= 0.8 * (p.x() - 14);  // the joint's side: sheared
    b.deformed.row(v) = q.transpose();
  }
  b.grid = unitGrid({36, 36, 14});
  b.G = Volume(b.grid, ScalarType::UInt8), b.S = Volume(b.grid, ScalarType::UInt8);
  for (std::int64_t k = 2; k < 11; ++k)
    for (std::int64_t j = 2; j < 11; ++j)
      for (std::int64_t i = 2; i < 20; ++i)
        b.G.data<std::uint8_t>()[b.G.index(i, j, k)] = 5,
                                                 b.S.data<std::uint8_t>()[b.S.index(i, j, k)] = 1;
  return b;
}

}  // namespace repose::test

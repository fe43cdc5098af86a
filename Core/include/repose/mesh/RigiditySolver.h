// The seed's tetrahedral solver (eq. 1-4): tets inside the cage take their Green-coordinate
// deformation, every other tet the volume-weighted mean of its neighbours' (step 1), then vertex
// positions follow those linear maps edge by edge (step 2). Both systems are factorized once.
#pragma once

#include "repose/mesh/Embedding.h"
#include "repose/mesh/RigidHandles.h"
#include "repose/util/Progress.h"

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace repose {

class CompactGreenMatrix;

class RigiditySolver {
 public:
  // Factorizes both least-squares systems (CHOLMOD) for this mesh and these constraints.
  // Parts of the mesh with no constrained tet (step 1) or vertex (step 2) cannot be driven by the
  // cage: they keep their rest shape and position, and unconstrainedVertices() counts them.
  RigiditySolver(const TransferMesh& mesh, const std::vector<int>& constrainedVertices,
                 const std::vector<int>& constrainedTets);
  ~RigiditySolver();
  RigiditySolver(RigiditySolver&&) noexcept;
  RigiditySolver& operator=(RigiditySolver&&) noexcept;

  // targets: #constrainedVertices by 3 (the Green-coordinate positions, in the order given).
  // Returns all #V deformed positions; B (optional) receives each tet's 3x3 linear map.
  Eigen::MatrixX3d solve(const Eigen::MatrixX3d& targets,
                         std::vector<Eigen::Matrix3d>* B = nullptr) const;

  int unconstrainedVertices() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Linear part B of the affine map taking a rest tet to a deformed one (3x3).
Eigen::Matrix3d tetLinearMap(const Eigen::MatrixX3d& rest, const Eigen::MatrixX3d& deformed,
                             const Eigen::RowVector4i& tet);

// How a frame evaluates the Green coordinates. Exact: float-precise coefficients, double sums
// (exports, refinement, tests). Preview: half-precision coefficients, half the memory traffic,
// for frames during a drag; its position error is about 1e-3 of the cage's displacement from rest
// (measured in RigiditySolverTest), and an undeformed cage is reproduced exactly in both modes.
enum class GreenPrecision { Exact, Preview };

// One interaction frame: deformed cage -> Green coordinates on V_c -> rigidity solve.
// The dense coordinate matrix [phi psi] (V_c rows) is the frame's largest cost and is memory-
// bound, so it is kept once, compactly (CompactGreenMatrix: two half-float arrays), and applied
// to the cage's displacement from rest on all cores; the double coordinates are computed in
// blocks of rows and never held for the whole mesh.
//
// The coordinates can be kept between runs (saveCoordinates; docs/FORMATS.md, "Green-coordinate
// files"): constructed with such a file, V_c and the coefficients are read from it when it was
// written for this very mesh and cage, and computed otherwise, with coordinatesNote() saying why.
class CageDeformation {
 public:
  // `progress` follows the computation of the coordinates (stage "Green coordinates", the
  // longest step of a mesh or an uncached warp) and can stop it there; reading them reports none.
  CageDeformation(const TransferMesh& mesh, const TriangleMesh& cage, int threads = 0,
                  const std::string& coordinatesFile = "", const ProgressFn& progress = {});
  ~CageDeformation();
  CageDeformation(CageDeformation&&) noexcept;
  CageDeformation& operator=(CageDeformation&&) noexcept;

  const Embedding& embedding() const { return embedding_; }
  const RigiditySolver& solver() const { return *solver_; }
  // Vertices the winding number puts inside the cage whose Green coordinates do not reproduce
  // their rest position. They are left out of V_c, to the rigidity solver like the vertices
  // outside the cage. A safety net: none is expected (GreenQuasiConformalTest reproduces points
  // right above a face's edge and above an edge's line).
  int unreproducedVertices() const { return unreproduced_; }
  std::size_t coefficientBytes() const;
  // Writes V_c and the coefficients to `path` (atomically), for this mesh and cage only.
  void saveCoordinates(const std::string& path) const;
  // True when the constructor read the coordinates from its file.
  bool coordinatesRead() const { return coordinatesRead_; }
  // Why a file given to the constructor was not used ("" when it was, or none was given).
  const std::string& coordinatesNote() const { return coordinatesNote_; }
  // Positions of V_c (rows follow embedding().cageVertices) for a deformed cage.
  Eigen::MatrixX3d greenPositions(const Eigen::MatrixX3d& deformedCage,
                                  GreenPrecision precision = GreenPrecision::Exact) const;
  // deformedCage: #cage vertices by 3. Returns #V TM positions (and tet maps if B is given).
  Eigen::MatrixX3d deform(const Eigen::MatrixX3d& deformedCage,
                          std::vector<Eigen::Matrix3d>* B = nullptr,
                          GreenPrecision precision = GreenPrecision::Exact) const;

  // A frame whose handle groups moved rigidly (RigidHandles.h): the V_c vertices they dominate take
  // their motions, blended with the Green positions where the domination is partial, then the
  // rigidity solve. `influence` comes from computeHandleInfluence for this mesh, cage and list.
  Eigen::MatrixX3d deform(const Eigen::MatrixX3d& deformedCage, const HandleInfluence& influence,
                          const std::vector<RigidHandle>& handles,
                          std::vector<Eigen::Matrix3d>* B = nullptr,
                          GreenPrecision precision = GreenPrecision::Exact) const;

 private:
  // embedInCage without coordinates, then V_c's coordinates block by block.
  void computeCoordinates(const TransferMesh& mesh, int threads, const ProgressFn& progress);
  // Throws repose::Error for a wrong vertex count, a non-finite vertex, or a vertex more than
  // 1000 cage sizes from the rest cage (a handle moved too far).
  void checkPosedCage(const Eigen::MatrixX3d& deformedCage) const;
  TriangleMesh cage_;
  Embedding embedding_;
  std::unique_ptr<RigiditySolver> solver_;
  std::unique_ptr<CompactGreenMatrix> coefficients_;  // [phi psi], rows follow V_c
  Eigen::MatrixX3d restCageValues_;  // [cage vertices; stretch * normals] of the rest cage
  Eigen::MatrixX3d restPositions_;   // the exact Green image of the rest cage (double)
  Eigen::MatrixX3d restVertices_;    // the TM's own rest positions of V_c (rigid motions act on)
  int threads_ = 0;
  int unreproduced_ = 0;
  std::uint64_t key_ = 0;  // of the mesh and cage (greenCoordinatesKey)
  Eigen::Index meshVertices_ = 0;
  bool coordinatesRead_ = false;
  std::string coordinatesNote_;
};

// Where a transfer mesh's Green coordinates are kept: beside it, its name ending in .green
// instead of .vtu (a scene's tm.vtu -> tm.green).
std::string greenCoordinatesFileFor(const std::string& meshPath);

}  // namespace repose

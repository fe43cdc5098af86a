// The transfer mesh (TM): a labelled tetrahedral mesh of the body that carries the cage's
// deformation to every voxel. Built from S with CGAL Mesh_3 and a sizing field (seed §4.2).
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace repose {

struct TransferMesh {
  Eigen::MatrixX3d vertices;  // #V by 3 rest positions, RAS mm
  Eigen::MatrixX4i tets;      // #T by 4 vertex indices, positively oriented (volume > 0)
  Eigen::VectorXi labels;     // #T body-part label (subdomain of S) of each tet
  // #T piece ids of rigid tissue (bone: a label of G, or for a bone of several labels its smallest,
  // RigSettings::bonePieces), 0 for soft tissue; empty when not meshed with bones. Bones are
  // subdomains of their own (TransferMeshOptions::rigidTissue), so a bone is a union of whole tets,
  // which a pose moves as one piece (computeHandleInfluence).
  std::vector<int> rigid;
  // The largest voxel size of the grid it was meshed from (mm; 0 when unknown). Mesh_3 puts the
  // surface to within about this of the label boundary; the rasterizer's shell covers the gap.
  double sourceSpacingMm = 0;
};

// Signed volume (mm^3) of tet t: det[b-a, c-a, d-a] / 6, positive for the orientation TM uses.
double tetVolume(const Eigen::MatrixX3d& vertices, const Eigen::RowVector4i& tet);

// Desired tet size (mm) over the volume, stored on a grid (the seed's F). Refinement scales it.
struct SizingField {
  VolumeGeometry grid;        // usually S's grid or a coarser one covering it
  std::vector<float> sizeMm;  // one value per grid voxel (i fastest)
  static SizingField uniform(const VolumeGeometry& grid, double sizeMm);
  // Trilinear value at a RAS point, clamped to the grid's border values outside it.
  double at(const Eigen::Vector3d& ras) const;
};

struct TransferMeshOptions {
  double sizeMm = 0;                    // uniform size; 0: 5% of S's diagonal (the seed's default)
  const SizingField* sizing = nullptr;  // overrides sizeMm when set
  // Optional label map on S's grid: the label of rigid tissue (bone, from G and a tissue table)
  // where there is one, else 0. Its boundaries become subdomain boundaries of the mesh and
  // TransferMesh::rigid carries its labels.
  const Volume* rigidTissue = nullptr;
  ProgressFn progress;
};

struct TransferMeshReport {
  int vertices = 0, tets = 0;
  int degenerateTets = 0;                         // |volume| below 1e-9 of the mean: removed
  int invertedTets = 0;                           // negative volume after meshing: reoriented
  int collapsedEdges = 0;                         // edges merged by collapseShortEdges
  std::vector<std::pair<int, int>> tetsPerLabel;  // (label, count)
};

// Throws repose::Error for an empty S, a non-integer volume or a mesh with no tets.
TransferMesh buildTransferMesh(const Volume& parts, const TransferMeshOptions& options = {},
                               TransferMeshReport* report = nullptr);

// The builder's last pass, public so the fallback is testable: orients every tet positively in
// RAS; drops tets whose |volume| is below 1e-9 of the mean volume (report.degenerateTets; they
// carry no voxel and would make the rigidity system singular) and then the vertices no tet uses;
// counts as inverted (report.invertedTets) the tets negative beyond the grid's mirroring
// (frameSign -1 when IJK->RAS is mirrored, as for LPS grids). Fills the report's counts.
void cleanTransferMesh(TransferMesh& mesh, double frameSign, TransferMeshReport& report);

// Collapses the edges shorter than `minEdgeMm`, shortest first, each by moving one end onto the
// other where the mesh stays a manifold (boundary included) and no tet around the moved end gets
// flatter than `qualityFloor` (6 sqrt(2) V / l_max^3, 1 for a regular tet) or than the flattest
// there before. Mesh_3 leaves balls of tets with edges of hundredths of a millimetre where three
// labels meet; a pose turns them inside out (TetEdgeCollapse.cpp). Positively oriented tets in,
// positively oriented tets out; returns the number of edges collapsed.
int collapseShortEdges(TransferMesh& mesh, double minEdgeMm, double qualityFloor = 0.02);

// Inside `region`, duplicates every vertex shared by a tet of label a and a tet of label b (on a
// common face, as the seed says, but also along an edge or at a single vertex). Around each such
// vertex the copy goes to the b tets and to the tets face-connected to them without crossing an a
// tet (so b keeps its other neighbours), and the two sides can move apart. Returns the number of
// vertices added. Throws if a or b has no tet.
int separateLabels(TransferMesh& mesh, int labelA, int labelB, const Region& region);

// VTK XML unstructured grid (.vtu) with a cell array "label"; RAS mm. Atomic write.
void writeTransferMesh(const TransferMesh& mesh, const std::string& path);
TransferMesh readTransferMesh(const std::string& path);

}  // namespace repose

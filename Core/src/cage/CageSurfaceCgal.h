// The CGAL steps of cage building, kept in one translation unit because CGAL is slow to compile:
// restricted Delaunay meshing of the field's zero level set, QEM simplification, mesh checks.
#pragma once

#include "CageField.h"

namespace repose::cage {

// Boissonnat-Oudot restricted Delaunay surface (CGAL Surface_mesher) of field = 0, in RAS mm.
// facetRadiusMm bounds triangle size, approximationMm the distance to the true level set.
TriangleMesh meshZeroLevelSet(const CageField& field, double facetRadiusMm, double approximationMm);

enum class Simplification { GarlandHeckbert, LindstromTurk };
const char* simplificationName(Simplification s);

// Edge collapses down to about targetVertices with the given quadric policy, refusing collapses
// that flip a face normal. Edges touching a vertex with frozen[v] set are never collapsed (empty:
// none frozen). The mesh must be a closed triangle mesh.
TriangleMesh simplifyMesh(const TriangleMesh& mesh, int targetVertices, Simplification policy,
                          const std::vector<bool>& frozen = {});

// Centroids of the faces of `mesh` that intersect another face (empty when there are none).
std::vector<Eigen::Vector3d> selfIntersectionSites(const TriangleMesh& mesh);

struct MeshChecks {
  bool closed = false, manifold = false, outward = false, selfIntersectionFree = false;
};
// Checks the mesh and makes it outward-oriented if it was consistently inward.
MeshChecks checkAndOrient(TriangleMesh& mesh);

}  // namespace repose::cage

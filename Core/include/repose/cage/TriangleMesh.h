// A triangle surface mesh as two Eigen arrays, the form cages take in Core (libigl's V, F).
// Units are RAS millimetres; faces are counter-clockwise seen from outside (outward normals).
#pragma once

#include <Eigen/Core>

namespace repose {

struct TriangleMesh {
  Eigen::MatrixX3d vertices;  // #V by 3 positions (mm)
  Eigen::MatrixX3i faces;     // #F by 3 vertex indices, outward orientation
};

// Unit outward normal of each face of `faces` with vertex positions `vertices` (#F by 3).
Eigen::MatrixX3d faceNormals(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& faces);

}  // namespace repose

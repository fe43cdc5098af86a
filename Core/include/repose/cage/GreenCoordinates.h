// Green coordinates (Lipman, Levin, Cohen-Or 2008) of points inside a triangle cage: phi per cage
// vertex, psi per cage face. A point deforms as sum phi_i v'_i + sum psi_j s_j n'_j.
#pragma once

#include "repose/cage/TriangleMesh.h"

namespace repose {

struct GreenCoordinates {
  Eigen::MatrixXd phi;  // #points by #cage vertices
  Eigen::MatrixXd psi;  // #points by #cage faces
};

// Coordinates of each row of `points` (#P by 3, mm) with respect to `cage`, in parallel over
// points (threads 0: all cores). Valid for points inside the cage; finite everywhere off the
// cage surface (points on it get the limit of their nearby values).
GreenCoordinates computeGreenCoordinates(const TriangleMesh& cage, const Eigen::MatrixX3d& points,
                                         int threads = 0);

// Stretch factor s_j of each face between rest and deformed positions (#F): the factor that makes
// the map exact for similarities (s_j = scale for a uniform scaling).
Eigen::VectorXd greenFaceStretch(const TriangleMesh& rest, const Eigen::MatrixX3d& deformed);

// Deformed positions (#P by 3) of the points the coordinates were computed for.
Eigen::MatrixX3d applyGreenCoordinates(const GreenCoordinates& gc, const TriangleMesh& rest,
                                       const Eigen::MatrixX3d& deformed);

}  // namespace repose

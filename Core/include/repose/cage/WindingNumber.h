// Generalized winding number of a closed triangle cage (Jacobson et al. 2013): 1 inside, 0
// outside, smooth in between, robust for points near the surface. Decides where Green
// coordinates are valid.
#pragma once

#include "repose/cage/TriangleMesh.h"

namespace repose {

// Winding number of each row of `points` (#P by 3, mm) with respect to `mesh`, in parallel.
Eigen::VectorXd windingNumbers(const TriangleMesh& mesh, const Eigen::MatrixX3d& points,
                               int threads = 0);

}  // namespace repose

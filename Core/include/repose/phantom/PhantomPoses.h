// Analytic cage poses of the generated phantom, for tests and benchmarks that need the same
// motion every time (the pose files of the module describe user poses).
#pragma once

#include "repose/cage/TriangleMesh.h"
#include "repose/mesh/RigidHandles.h"
#include "repose/phantom/Phantom.h"

#include <Eigen/Core>
#include <vector>

namespace repose {

// The left forearm and hand turned `degrees` forward (towards anterior, +y) about the left elbow:
// cage vertices below the elbow and on the arm's side of the shoulder rotate about the x axis
// through the elbow joint; the rest of the cage stays.
// The same motion as rigid handle groups for CageDeformation::deform with handle influence:
// [0] the turned cage vertices with the left forearm and hand (parts of S) and the rotation,
// [1] every other cage vertex and body part, fixed.
std::vector<RigidHandle> phantomElbowFlexionHandles(const Phantom& phantom,
                                                    const TriangleMesh& cage, double degrees = 90);
Eigen::MatrixX3d phantomElbowFlexion(const Phantom& phantom, const TriangleMesh& cage,
                                     double degrees = 90);

}  // namespace repose

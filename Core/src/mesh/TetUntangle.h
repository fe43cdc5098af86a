// Creases: tets a bend turned inside out, untangled with the held volumes kept.
//
// The inner side of a bend (elbow, groin, armpit) is a contact between two sides of one body: the
// blended rigid motions fold its soft tets over each other, and the volume restoration, which
// linearises each tet's volume, cannot pull a tet far inside out back through zero. Each free
// vertex near such tets is moved, one after another (Gauss-Seidel sweeps), to lower
//
//   sum over its tets of |S|^2 / (3 sigma(det S)^(2/3))  +  kappa * sum_c (r_c / a_c)^2,
//
// S = E D^-1 the tet's deformation gradient (E posed, D rest edges), sigma(d) = (d +
// sqrt(d^2 + 4 delta^2)) / 2 the regularised determinant of Escobar et al.'s simultaneous
// untangling and smoothing (Comput. Methods Appl. Mech. Engrg. 192, 2003): finite and smooth
// through d = 0 and growing without bound as a tet turns inside out, so descent on it moves a
// vertex back across the face it crossed. r_c are the residuals of the volumes the restoration
// holds (each body part's, each tissue's), a_c their rest amounts: a vessel across the crease
// keeps its volume while the crease opens, instead of being flattened into it.
#pragma once

#include "repose/mesh/TransferMesh.h"

#include <Eigen/Core>

#include <array>
#include <atomic>
#include <utility>
#include <vector>

namespace repose {

namespace mesh_detail {
// The signed volume of the tet with corners x[0..3], and its gradient in each corner (shared
// with the restoration's rounds).
double volumeOf(const std::array<Eigen::Vector3d, 4>& x);
std::array<Eigen::Vector3d, 4> volumeGradients(const std::array<Eigen::Vector3d, 4>& x);
}  // namespace mesh_detail

// The volumes held while untangling: per tet, the constraints its volume enters and with what
// weight (constraint change per mm^3 of the tet's volume change); per constraint its rest amount
// and its residual at the positions given (the same sums as the restoration's).
struct UntangleConstraints {
  std::vector<int> offsets;                     // #tets + 1
  std::vector<std::pair<int, double>> entries;  // (constraint, weight)
  std::vector<double> amount;
  Eigen::VectorXd residual;
};

struct UntangleOptions {
  int sweeps = 120;     // at most; stops at a sweep with no tet inside out and none moved
  double delta = 0.02;  // regularisation of det S (a rest tet has det S = 1) to start with
  // When `stallSweeps` sweeps in a row turn no more tets back, delta is divided by 4, down to
  // `smallestDelta`; the sweeps stop when they stall at it.
  // On the gap phantom at 2 mm (both arms up 160 degrees, sitting) going down to 0.00125 left 14
  // and 1 tets inside out where staying at 0.02 left 48 and 6 (measured with a development build
  // whose zone also held every inverted tet; the suite now leaves 18 and 1).
  double smallestDelta = 0.00125;
  int stallSweeps = 8;
  // Weight of the held volumes' misfit (fractions squared). Under both arms raised 160 degrees
  // (gap phantom, 2 mm; 60 sweeps at delta 0.02) the body's change was -0.489 % with 1e7 and
  // -0.462 % with 1e8 (-0.438 % without untangling; the same development build): the weaker hold
  // lets the fold take tissue.
  double kappa = 1e8;
  // Weight of each tet's own volume, (det S - 1)^2, beside its shape. The shape term is scale
  // invariant and, regularised, costs nothing for a tet crushed towards a point; this term does.
  double volumeWeight = 0;
  int stepsPerVertex = 4;                     // descent steps per vertex per sweep
  const std::atomic<bool>* cancel = nullptr;  // set by another thread: stop after the sweep
};

struct UntangleReport {
  int invertedBefore = 0, invertedAfter = 0;  // among the tets given
  int sweeps = 0;
};

// Moves only `freeVertices`; counts and scores only `tets` (every tet with a free vertex must be
// among them). `held.residual` is updated as vertices move.
UntangleReport untangleTets(const TransferMesh& mesh, const std::vector<int>& freeVertices,
                            const std::vector<int>& tets, UntangleConstraints& held,
                            Eigen::MatrixX3d& deformed, const UntangleOptions& options = {});

// A knot of tiny tets the sweeps cannot open: where three parts meet, a bend can crush a few
// dozen tets of a millimetre or less onto one point, each a hair inside out, and every one-vertex
// move that turns one back turns another over (thick slices' arm raise 90 degrees, in a
// development build without this step: 27 tets, every corner free). Each knot (inverted tets
// among `tets` that share a vertex) with the ring of vertices around it is set back on the one
// affine map that best carries the rest positions of the vertices bordering it onto their posed
// ones: the knot's own tets come back right side out, and the tets between it and its border may
// turn over, but they are large enough for the sweeps, which start again from there (on that
// body none is left: the quality suite's thick-slice arm_raise90). Only free vertices (`isFree`)
// move; a knot whose map turns space over (det <= 0) is left. Returns how many knots were reset;
// the caller keeps the result only if the sweeps then leave fewer tets inside out.
int resetInvertedKnots(const TransferMesh& mesh, const std::vector<char>& isFree,
                       const std::vector<int>& tets, Eigen::MatrixX3d& deformed);

}  // namespace repose

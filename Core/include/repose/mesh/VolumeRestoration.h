// Soft tissue keeps its volume: a posed transfer mesh relaxed so that every body part has its rest
// volume again, and every tet as nearly as the mesh allows.
//
// A joint's transition is made of blended rigid motions and analytic bends (RigidHandles.h,
// JointBend.h). The bend keeps volume in the continuum, but the mesh samples it coarsely, the bend
// fades into the blend at its reach, and the soft tets between two bone ends follow two rigid
// pieces that disagree: at a 90-degree elbow the forearm's mesh lost 1.7 % of its volume, which no
// rounding of the voxels can give back to the tissue it belongs to. Flesh is nearly
// incompressible (Poisson's ratio about 0.49), so the restoration moves the soft vertices of the
// transitions (never a whole piece's: bones stay exactly rigid) by the smallest smooth correction
// that gives each body part of S its rest volume exactly and each tet its own as nearly as the
// mesh allows: the inner side of a bend bulges, as flesh does. Only the tets the correction can
// reach count: a part's volume changed elsewhere (tissue dragged along a contact no cut freed)
// is left for the report to show.
//
// Gauss-Newton on the tets' volumes: each round linearises every tet's volume in its free
// vertices and minimises sum_t (dV_t)^2 / V0_t + lambda * sum_edges |corr_a - corr_b|^2 (the
// correction kept smooth along the mesh's edges) subject to every touched part's linearised
// volume, over the tets with a free vertex, equal to its rest volume (Lagrange multipliers: one
// sparse Cholesky factorisation and a small dense system per round).
#pragma once

#include "repose/mesh/SelfContact.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>

#include <atomic>
#include <utility>
#include <vector>

namespace repose {

// Which tissue each soft tet holds at rest: per tet, the labels of G among its voxels and how
// many (whole pieces' tets hold none: they are rigid). What the per-tissue volumes of the
// restoration are counted with; the voxels' rounding sums a label's rest voxels' tet volume ratios
// over the same voxels when they come from raster/RestTissues.h (the jobs' rigs).
struct TetTissues {
  std::vector<int> offsets;  // #tets + 1: tet t's entries are [offsets[t], offsets[t+1])
  std::vector<std::pair<int, int>> entries;  // (label, voxels)
  bool empty() const { return entries.empty(); }
};
// The voxel centres inside each tet alone (a centre on a face two tets share counts in both), from
// G on its own grid (any orientation), the mesh at rest in the same RAS space. Misses the voxels
// beyond the mesh's outer faces that the rasterizer's shell carries (raster/RestTissues.h).
TetTissues tetTissues(const TransferMesh& mesh, const Volume& organs, int threads = 0);

struct VolumeRestorationOptions {
  // Rounds at most; each moves no vertex more than its shortest rest edge, the rounds stop once
  // no vertex moves more than 0.1 um, and the positions whose worst constraint is met best are
  // kept (never worse than the solve and the bends left them).
  int iterations = 12;
  // Tets whose posed volume differs from their rest volume by more than this fraction free their
  // vertices, and `rings` rings of neighbours around them, for the correction.
  double tolerance = 1e-3;
  int rings = 2;
  // Weight of the correction's smoothness against the tets' volumes (scaled by the mean rest
  // volume over the mean squared edge length of the free region, so it does not depend on the
  // mesh's size).
  double smoothness = 0.01;
  // Sweeps of the untangling (TetUntangle.h) over the free vertices when tets are left inside out
  // (a crease); 0: none.
  int untangleRounds = 120;
  // When tets are still inside out after those sweeps: up to this many sweeps again under this
  // weaker hold of the volumes (TetUntangle.h's kappa, which is 1e8 in the first sweeps; 0:
  // none). 1e6 let the tissue go more (body -0.56 % against -0.55 % at 3e6, both arms up 160
  // degrees on the 2 mm phantom); 1e7 left 2 of those 6 tets inside out.
  double relaxedKappa = 3e6;
  int relaxedSweeps = 600;
  // When tets are inside out after both: the weaker hold's sweeps again with this weight on each
  // tet's own volume (TetUntangle.h's volumeWeight; 0: none), which lifts tets crushed towards a
  // point. 10 turned back all 12 tets the first two left on the adult female's grid (both arms
  // up 160 degrees); 1 left 5 and 0.1 left 8 (before raster/RestTissues.h held the shell's
  // tissues too: with it 7 are left there).
  double crushedVolumeWeight = 10;
  // Folds (SelfContact.h; optional): surface vertices that lie inside another layer of tissue
  // are free too, and each round pulls them out to that layer's surface, `contactMarginMm`
  // beyond it, with this weight against the tets' volumes around them (1: as stiff as those);
  // 0: none. A contact found once stays as a one-sided plane for the later rounds. Up to
  // `contactIterations` rounds while contacts remain. Weights 10, 20, 40, 100 and 300 were
  // tried on arms-resting phantoms on thick slices and on the adult female's grid raising both
  // arms (docs/ARCHITECTURE.md, "Folds"): 40 lost the least of the arms' muscle.
  const SelfContactFinder* contacts = nullptr;
  double contactWeight = 40;
  double contactMarginMm = 0.5;
  int contactIterations = 40;
  // Set by another thread to stop early (a live prediction a new drag made stale): checked
  // between rounds and sweeps; the positions are then left wherever they are and `cancelled` is
  // reported.
  const std::atomic<bool>* cancel = nullptr;
};

struct VolumeRestorationReport {
  int freeVertices = 0;
  int parts = 0;               // body parts whose volume was held
  int tissues = 0;             // labels of G whose volume was held
  int iterations = 0;          // rounds taken
  double maxCorrectionMm = 0;  // the largest distance a vertex was moved
  double worstPartBefore = 0;  // the largest |volume change| of a part, percent
  double worstPartAfter = 0;
  int invertedBefore = 0, invertedAfter = 0;
  int untangled = 0;  // tets the untangling turned right side out
  // Tets were still inside out after the untangling's sweeps, and it swept again under the
  // weaker hold (kept only when that left fewer inside out).
  bool relaxedUntangle = false;
  // Tets were inside out after both, and it swept a third time with each tet's own volume
  // weighed (kept only when that left fewer inside out).
  bool crushedUntangle = false;
  // Knots of crushed tets set back on their border's affine map and swept again
  // (resetInvertedKnots; 0 when none was, or when that did not leave fewer inside out).
  int knotsReset = 0;
  // Surface vertices inside another layer of tissue (SelfContact.h) before and after, and the
  // deepest of them (mm); 0 without a contact finder.
  int contactsBefore = 0, contactsAfter = 0;
  double deepestContactBeforeMm = 0, deepestContactAfterMm = 0;
  bool cancelled = false;  // stopped by VolumeRestorationOptions::cancel: the result means nothing
};

// `movable[v]`: whether vertex v may be moved at all (the soft tissue of the joints' bends; never
// a vertex of a whole piece, which must stay rigid). Modifies `deformed` (the posed vertices, RAS
// mm) in place. Parts whose tets all keep their volume within the tolerance are left as they are.
// `held[t]` (optional, one per tet): the tets whose volumes each part's constraint sums besides
// those the correction reaches (the soft tets between two bone ends, which no free vertex can
// reach: the tissue around them makes up for them). Empty: only the reached tets.
// `tissues` (optional): each tissue of the summed tets is held at its rest volume too (the sum of
// its tets' volume ratios times its voxels there), so a vessel crossing a crease keeps its
// volume, not only the body part around it. Constraints that cannot be met together (a tissue
// only in tets no free vertex reaches) are met as nearly as they can.
VolumeRestorationReport restoreVolumes(const TransferMesh& mesh, const std::vector<char>& movable,
                                       Eigen::MatrixX3d& deformed,
                                       const VolumeRestorationOptions& options = {},
                                       const std::vector<char>& held = {},
                                       const TetTissues* tissues = nullptr);

}  // namespace repose

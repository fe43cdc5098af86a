// The rig's whole pieces (PoseRig.h): bones and the organs that lie in one body part are meshed
// as pieces of their own, with a seam where pieces of two parts touch, and every frame moves each
// piece exactly with one group; the mesh file keeps them.
#include "TestPaths.h"
#include "TestPoses.h"

#include "repose/cage/ArapDeformer.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"
#include "repose/pose/PoseRig.h"
#include "repose/volume/TissueTable.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

using namespace repose;
using namespace repose::test;

namespace {

// The 4 mm phantom and the settings `repose pose` uses for it (bones from its tissue table).
struct Rigged {
  Volume organs, parts;
  RigSettings settings;
  Rigged() {
    PhantomOptions o;
    o.voxelMm = 4;
    std::tie(organs, parts) = Phantom(o).makeVolumes();
    const TissueTable tissues =
        readTissueTable(std::string(REPOSE_SOURCE_DIR) + "/Resources/Tissues/phantom.csv");
    for (const auto& [label, tissue] : tissues)
      if (tissue.rigid) settings.rigidLabels.push_back(label);
    settings.cageVertices = 200;
  }
};

int labelNamed(const Volume& v, const std::string& name) {
  for (const Label& l : v.labels().labels())
    if (l.name == name) return l.value;
  ADD_FAILURE() << "no label " << name;
  return -1;
}

const Rigged& rigged() {
  static const Rigged r;
  return r;
}

}  // namespace

TEST(PoseRig, BonesAndOrgansOfOnePartMoveWholeButNotTheTissuesThatCrossJoints) {
  const Rigged& r = rigged();
  const std::vector<int> whole = labelsMovingWhole(r.organs, r.parts, r.settings);
  const std::set<int> set(whole.begin(), whole.end());
  for (const int bone : r.settings.rigidLabels) EXPECT_TRUE(set.count(bone)) << bone;
  // Organs clear of the parts' borders. (At 4 mm the brain's base lies on the neck's cut, the
  // head/torso plane: like a vessel running from the trunk into a limb it bends there.)
  for (const char* organ : {"urinary_bladder", "liver", "lung_left", "heart"})
    EXPECT_TRUE(set.count(labelNamed(r.organs, organ))) << organ;
  for (const char* crossing : {"skin", "subcutaneous_fat", "muscle"})
    EXPECT_FALSE(set.count(labelNamed(r.organs, crossing))) << crossing;
  RigSettings bonesOnly = r.settings;
  bonesOnly.wholeOrgans = false;
  EXPECT_EQ(labelsMovingWhole(r.organs, r.parts, bonesOnly), r.settings.rigidLabels);

  // The map: those labels where G has them, and no two pieces of different parts face to face.
  const Volume map = wholePieceMap(r.organs, r.parts, r.settings);
  ASSERT_EQ(map.dims(), r.parts.dims());
  const std::uint16_t* m = map.data<std::uint16_t>();
  const auto d = map.dims();
  std::map<int, std::int64_t> kept, total;
  int touching = 0;
  for (std::int64_t k = 0; k + 1 < d[2]; ++k)
    for (std::int64_t j = 0; j + 1 < d[1]; ++j)
      for (std::int64_t i = 0; i + 1 < d[0]; ++i) {
        const std::int64_t at = map.index(i, j, k);
        const int label = int(r.organs.valueAsDouble(at));
        if (set.count(label)) ++total[label];
        if (m[at] == 0) continue;
        EXPECT_EQ(m[at], label);
        ++kept[label];
        for (const std::int64_t n :
             {map.index(i + 1, j, k), map.index(i, j + 1, k), map.index(i, j, k + 1)})
          touching +=
              m[n] != 0 && m[n] != m[at] && r.parts.valueAsDouble(n) != r.parts.valueAsDouble(at);
      }
  EXPECT_EQ(touching, 0);
  for (const int label : whole)
    if (total[label] > 0) {
      EXPECT_GE(kept[label], 0.8 * double(total[label])) << label;
    }
  // The phantom's joints are congruent with a cartilage gap, so its bones need no seam; where
  // bones of two parts do touch (a segmentation without the gap), one is cut on each side.
  VolumeGeometry tiny =
      VolumeGeometry::make({6, 3, 3}, Eigen::Vector3d::Ones(), Eigen::Vector3d::Zero());
  Volume g(tiny, ScalarType::UInt8), s(tiny, ScalarType::UInt8);
  for (std::int64_t i = 0; i < 6; ++i)
    for (std::int64_t j = 0; j < 3; ++j)
      for (std::int64_t k = 0; k < 3; ++k) {
        g.data<std::uint8_t>()[g.index(i, j, k)] = i < 3 ? 11 : 12;  // humerus | radius_ulna
        s.data<std::uint8_t>()[s.index(i, j, k)] = i < 3 ? 3 : 4;    // upper arm | forearm
      }
  RigSettings bones;
  bones.rigidLabels = {11, 12};
  bones.wholeOrgans = false;
  const Volume seam = wholePieceMap(g, s, bones);
  for (std::int64_t i = 0; i < 6; ++i)
    EXPECT_EQ(seam.data<std::uint16_t>()[seam.index(i, 1, 1)] == 0, i == 2 || i == 3) << i;
}

TEST(PoseRig, EveryPieceMovesExactlyWithOneGroupInEveryFrame) {
  const Rigged& r = rigged();
  RigGeometry geometry = buildRigGeometry(r.parts, {}, r.settings, {}, &r.organs);
  const TransferMesh& mesh = geometry.mesh;
  ASSERT_EQ(mesh.rigid.size(), std::size_t(mesh.tets.rows()));
  // Pieces are whole tets of their label: their centres lie in that label's voxels.
  std::int64_t pieceTets = 0, agree = 0;
  std::set<int> pieceLabels;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (!mesh.rigid[t]) continue;
    ++pieceTets;
    pieceLabels.insert(mesh.rigid[t]);
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += mesh.vertices.row(mesh.tets(t, k)).transpose() / 4;
    const Eigen::Vector3d ijk = r.organs.geometry().rasToVoxel(c);
    agree += r.organs.valueAsDouble(r.organs.index(std::lround(ijk.x()), std::lround(ijk.y()),
                                                   std::lround(ijk.z()))) == mesh.rigid[t];
  }
  EXPECT_GE(agree, 0.9 * double(pieceTets));
  EXPECT_TRUE(pieceLabels.count(labelNamed(r.organs, "femur")));
  EXPECT_TRUE(pieceLabels.count(labelNamed(r.organs, "urinary_bladder")));

  // No vertex is shared by pieces of two body parts (across a joint), and demoting finds none.
  std::map<int, std::set<int>> partsAtVertex;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    if (mesh.rigid[t])
      for (int k = 0; k < 4; ++k) partsAtVertex[mesh.tets(t, k)].insert(mesh.labels[t]);
  for (const auto& [v, parts] : partsAtVertex) ASSERT_EQ(parts.size(), 1u) << "vertex " << v;
  TransferMesh copy = mesh;
  EXPECT_EQ(demotePiecesAcrossJoints(copy), 0);

  // The file keeps them.
  ScratchDir dir("rig");
  writeTransferMesh(mesh, dir.file("tm.vtu"));
  EXPECT_EQ(readTransferMesh(dir.file("tm.vtu")).rigid, mesh.rigid);

  // The leg step: each piece's vertices are exactly one group's motion of their rest positions.
  PhantomOptions po;
  po.voxelMm = 4;
  const Pose pose = suitePose("walk", Phantom(po));
  const PoseRig rig(std::move(geometry), pose, r.parts.labels());
  // Every vertex left in V_c is reproduced by its Green coordinates.
  {
    const Eigen::MatrixX3d g = rig.deformation().greenPositions(rig.cage().vertices);
    const std::vector<int>& vc = rig.deformation().embedding().cageVertices;
    for (std::size_t r = 0; r < vc.size(); ++r)
      ASSERT_LT((g.row(Eigen::Index(r)) - rig.mesh().vertices.row(vc[r])).norm(), 0.02) << vc[r];
  }
  for (std::size_t f = 0; f < rig.frameCount(); f += 3) {
    const PoseRig::Frame frame = rig.frame(f);
    ASSERT_EQ(frame.tetMaps.size(), std::size_t(rig.mesh().tets.rows()));
    // The live view's frame (no tet maps: the solver computes only the maps it reads) puts every
    // vertex where the full frame does, bit for bit, in both precisions.
    for (const GreenPrecision precision : {GreenPrecision::Exact, GreenPrecision::Preview}) {
      const PoseRig::Frame live = rig.frame(f, precision, FrameMaps::Without);
      EXPECT_TRUE(live.tetMaps.empty());
      const Eigen::MatrixX3d full =
          precision == GreenPrecision::Exact ? frame.deformed : rig.frame(f, precision).deformed;
      ASSERT_EQ((live.deformed - full).cwiseAbs().maxCoeff(), 0.0) << "frame " << f;
      ASSERT_EQ(live.cage, frame.cage);
    }
    std::map<int, std::set<int>> groupsOfLabel;
    const std::vector<char>& inCage = rig.deformation().embedding().inside;
    std::int64_t pieces = 0, checked = 0;
    for (Eigen::Index t = 0; t < rig.mesh().tets.rows(); ++t) {
      if (!rig.mesh().rigid[t]) continue;
      // Vertices outside the cage (a few at the crown and soles) are left to the solver.
      ++pieces;
      bool allInCage = true;
      for (int k = 0; k < 4; ++k) allInCage &= inCage[rig.mesh().tets(t, k)] != 0;
      if (!allInCage) continue;
      ++checked;
      int group = -1;
      for (std::size_t g = 0; g < frame.handles.size() && group < 0; ++g) {
        bool all = true;
        for (int k = 0; k < 4; ++k) {
          const int v = rig.mesh().tets(t, k);
          const Eigen::Vector3d rest = rig.mesh().vertices.row(v).transpose();
          all &= (frame.handles[g].motion * rest - frame.deformed.row(v).transpose()).norm() < 1e-6;
        }
        if (all) group = int(g);
      }
      ASSERT_GE(group, 0) << "frame " << f << ": tet " << t << " of piece label "
                          << rig.mesh().rigid[t] << " follows no group";
      groupsOfLabel[rig.mesh().labels[t]].insert(group);
    }
    EXPECT_GE(checked, 0.95 * double(pieces));
    // One group per body part: the thigh's femur goes with its leg, the pelvis with the body.
    for (const auto& [part, groups] : groupsOfLabel)
      EXPECT_EQ(groups.size(), 1u) << "frame " << f << ", body part " << part;
  }
}

TEST(PoseRig, ABoneOfSeveralLabelsIsMeshedAsOnePiece) {
  // The tissue table's bone column groups a bone's labels under its smallest one; other rigid
  // labels (no bone named) and soft tissue have no entry.
  TissueTable table;
  table[11] = {"humerus", 1908, true, "humerus"};
  table[28] = {"humerus_marrow", 1178, true, "humerus"};
  table[14] = {"femur", 1908, true, "femur"};
  table[30] = {"femur_marrow", 1178, true, "femur"};
  table[40] = {"patella", 1900, true, ""};
  table[3] = {"muscle", 1050, false, ""};
  const std::map<int, int> pieces = bonePiecesOf(table);
  EXPECT_EQ(pieces, (std::map<int, int>{{11, 11}, {28, 11}, {14, 14}, {30, 14}}));

  // The arms-resting phantom's long bones are a cortex and a marrow: one piece each, so no tet
  // carries a marrow label as its piece and the marrow lies in its bone's piece tets.
  PhantomOptions o;
  o.voxelMm = 4;
  o.armsResting = true;
  const auto [organs, parts] = Phantom(o).makeVolumes();
  const TissueTable tissues =
      readTissueTable(std::string(REPOSE_SOURCE_DIR) + "/Resources/Tissues/phantom.csv");
  RigSettings settings;
  for (const auto& [label, tissue] : tissues)
    if (tissue.rigid) settings.rigidLabels.push_back(label);
  settings.bonePieces = bonePiecesOf(tissues);
  settings.cageVertices = 200;
  const int humerus = labelNamed(organs, "humerus"), marrow = labelNamed(organs, "humerus_marrow");
  ASSERT_EQ(settings.bonePieces.at(marrow), humerus);
  const Volume map = wholePieceMap(organs, parts, settings);
  std::int64_t marrowVoxels = 0, marrowInHumerus = 0;
  for (std::int64_t i = 0; i < organs.numVoxels(); ++i)
    if (organs.valueAsDouble(i) == marrow) {
      ++marrowVoxels;
      marrowInHumerus += map.valueAsDouble(i) == humerus;
      ASSERT_NE(map.valueAsDouble(i), marrow);
    }
  EXPECT_GE(marrowInHumerus, 0.9 * double(marrowVoxels));  // all but the seam at the joints

  const RigGeometry g = buildRigGeometry(parts, {}, settings, {}, &organs);
  std::int64_t humerusTets = 0, marrowCentres = 0, marrowCentresInPiece = 0;
  for (Eigen::Index t = 0; t < g.mesh.tets.rows(); ++t) {
    ASSERT_NE(g.mesh.rigid[t], marrow);
    humerusTets += g.mesh.rigid[t] == humerus;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += g.mesh.vertices.row(g.mesh.tets(t, k)).transpose() / 4;
    const Eigen::Vector3d ijk = organs.geometry().rasToVoxel(c);
    if (organs.valueAsDouble(organs.index(std::lround(ijk.x()), std::lround(ijk.y()),
                                          std::lround(ijk.z()))) != marrow)
      continue;
    ++marrowCentres;
    marrowCentresInPiece += g.mesh.rigid[t] == humerus;
  }
  EXPECT_GT(humerusTets, 0);
  ASSERT_GT(marrowCentres, 0);
  EXPECT_GE(marrowCentresInPiece, 0.8 * double(marrowCentres));
}

TEST(PoseRig, WherePiecesOfTwoPartsShareAVertexOnlyTheSmallerSideGoesSoft) {
  // Two rigid tets of different parts meet at vertex 0: the larger (part 1) keeps it; the
  // smaller (part 2) becomes soft tissue. Before, both went soft, and a bone end beside a bent
  // joint bent with it on both sides.
  TransferMesh mesh;
  mesh.vertices.resize(7, 3);
  mesh.vertices << 0, 0, 0, 10, 0, 0, 0, 10, 0, 0, 0, 10,  // part 1's tet: 166.7 mm^3
      -2, 0, 0, 0, -2, 0, 0, 0, -2;                        // part 2's tet: 1.3 mm^3
  mesh.tets.resize(2, 4);
  mesh.tets << 0, 1, 2, 3, 0, 5, 4, 6;
  mesh.labels.resize(2);
  mesh.labels << 1, 2;
  mesh.rigid = {11, 14};
  EXPECT_EQ(demotePiecesAcrossJoints(mesh), 1);
  EXPECT_EQ(mesh.rigid, (std::vector<int>{11, 0}));
  EXPECT_EQ(demotePiecesAcrossJoints(mesh), 0);
}

TEST(PoseRig, ASoftTetPinnedBetweenPiecesOfTwoPartsGetsAFreeVertex) {
  // A joint space thinner than one tet: the soft tet (label 1) has two vertices on part 1's piece
  // and two on part 2's, so none may move, and it turns inside out when the joint bends. The
  // smaller piece (part 2) gives up its tets at those vertices; the larger keeps its own.
  TransferMesh mesh;
  mesh.vertices.resize(8, 3);
  mesh.vertices << 0, 0, 0, 10, 0, 0, 0, 10, 0, 0, 0, 10,  // part 1's piece: 166.7 mm^3
      0, 0, 12, 3, 0, 12, 0, 3, 12, 0, 0, 15;              // part 2's piece: 4.5 mm^3
  mesh.tets.resize(3, 4);
  mesh.tets << 0, 1, 2, 3, 4, 5, 6, 7, 3, 1, 4, 5;
  mesh.labels.resize(3);
  mesh.labels << 1, 2, 1;
  mesh.rigid = {11, 14, 0};
  EXPECT_EQ(demotePiecesAcrossJoints(mesh), 1);
  EXPECT_EQ(mesh.rigid, (std::vector<int>{11, 0, 0}));
  EXPECT_EQ(demotePiecesAcrossJoints(mesh), 0);
}

TEST(PoseRig, ASoftVertexSqueezedBetweenPiecesOfTwoPartsGetsASecondFreeLayer) {
  // A joint space one vertex thick (clavicle to first rib): soft vertex 8 caps a face of part 1's
  // piece and, across it, a face of part 2's. When the two faces meet it cannot get out of the
  // way, and both tets turn over. Part 1 has a second piece tet away from the joint, so it gives
  // up the smaller share of its piece: its tet at the face's corners goes soft. Once, not layer
  // after layer: a second call finds nothing.
  TransferMesh mesh;
  mesh.vertices.resize(12, 3);
  mesh.vertices << 0, 0, 0, 10, 0, 0, 0, 10, 0, 0, 0, 10,  // part 1's piece at the joint
      6, 6, 8, 8, 6, 6, 6, 8, 6, 9, 9, 9,                  // part 2's piece
      5, 5, 5,                                             // the soft vertex between them
      -10, 0, 0, 0, -10, 0, 0, 0, -10;                     // part 1's piece away from it
  mesh.tets.resize(5, 4);
  mesh.tets << 0, 1, 2, 3, 4, 5, 6, 7, 1, 2, 3, 8, 4, 5, 6, 8, 0, 9, 10, 11;
  mesh.labels.resize(5);
  mesh.labels << 1, 2, 1, 2, 1;
  mesh.rigid = {11, 14, 0, 0, 11};
  EXPECT_EQ(demotePiecesAcrossJoints(mesh), 1);
  EXPECT_EQ(mesh.rigid, (std::vector<int>{0, 14, 0, 0, 11}));
  EXPECT_EQ(demotePiecesAcrossJoints(mesh), 0);
}

TEST(PoseRig, ASoftVertexAboveTwoPiecesSideBySideIsNotSqueezed) {
  // Vertex 8 caps a face of each part's piece, but the faces lie side by side below it (the rim
  // of a joint): it can move away from both, so no piece gives up a tet.
  TransferMesh mesh;
  mesh.vertices.resize(9, 3);
  mesh.vertices << 0, 0, 0, 10, 0, 0, 0, 10, 0, 3, 3, -5,  // part 1's piece
      20, 0, 0, 30, 0, 0, 20, 10, 0, 23, 3, -5,            // part 2's piece
      15, 3, 5;                                            // the soft vertex above both
  mesh.tets.resize(4, 4);
  mesh.tets << 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 8, 4, 5, 6, 8;
  mesh.labels.resize(4);
  mesh.labels << 1, 2, 1, 2;
  mesh.rigid = {11, 14, 0, 0};
  EXPECT_EQ(demotePiecesAcrossJoints(mesh), 0);
  EXPECT_EQ(mesh.rigid, (std::vector<int>{11, 14, 0, 0}));
}

// A drag whose cage has free vertices (the left upper arm is in no group, so ARAP bends it between
// the fixed body and the turning forearm), one degree per event: each live frame takes at most
// kLiveCageIterations ARAP iterations from the last one and stays within a tenth of a millimetre
// of the cage frame() solves to convergence from rest; held still, it converges onto it; after a
// jump it is that cage exactly; and frame() does not depend on the live frames before it.
TEST(PoseRig, LiveFramesWarmStartTheCageAndEndWhereFramesFromRestEnd) {
  const Rigged& r = rigged();
  PhantomOptions po;
  po.voxelMm = 4;
  const Phantom body(po);
  Pose pose = parsePose(R"({"format": "repose-pose", "version": 1, "name": "drag",
    "groups": [
      {"name": "forearm", "select": {"parts": ["forearm_left", "hand_left"]},
       "rotation": {"axis": "elbow_left.flexion", "angle_deg": 0, "pivot": "elbow_left"}},
      {"name": "body", "fixed": true, "select": {"parts": ["head", "torso", "upper_arm_right",
        "forearm_right", "hand_right", "thigh_left", "shank_left", "foot_left", "thigh_right",
        "shank_right", "foot_right"]}}]})",
                        "drag");
  resolvePoseJoints(pose, body.skeleton());
  const PoseRig rig(buildRigGeometry(r.parts, {}, r.settings, {}, &r.organs), pose,
                    r.parts.labels());
  auto at = [&](double angle) {
    Pose edited = pose;
    edited.groups[0].transform.angleDeg = angle;
    return edited;
  };
  auto fromRest = [&](const Pose& p) {
    return rig.frame(p, 0, GreenPrecision::Preview, FrameMaps::Without).cage;
  };
  auto gap = [](const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
    return (a - b).rowwise().norm().maxCoeff();
  };
  const Eigen::MatrixX3d straight = fromRest(at(0));
  int warm = 0, cold = 0, events = 0;
  double worst = 0;
  rig.liveFrame(at(0), 0);  // the drag's first event solves from rest
  for (double angle = 1; angle <= 90; angle += 1, ++events) {
    const PoseRig::Frame live = rig.liveFrame(at(angle), 0);
    EXPECT_LE(rig.lastCageIterations(), PoseRig::kLiveCageIterations) << angle << " deg";
    warm += rig.lastCageIterations();
    const Eigen::MatrixX3d converged = fromRest(at(angle));
    cold += rig.lastCageIterations();
    worst = std::max(worst, gap(live.cage, converged));
    ASSERT_TRUE(live.deformed.allFinite());
  }
  EXPECT_GT(cold, 5 * events) << "the pose must leave cage vertices for ARAP to solve";
  EXPECT_LT(warm, cold / 3) << warm << " iterations warm, " << cold << " from rest";
  EXPECT_LT(worst, 0.1) << "mm between a live cage and the converged one";
  // Held still, the live cage converges: to an ARAP energy no higher than that of the cage
  // solved from rest (which stops at the solver's tolerance), and to within 0.02 mm of it.
  const Eigen::MatrixX3d end = fromRest(at(90));
  Eigen::MatrixX3d held;
  for (int n = 0; n < 6; ++n) held = rig.liveFrame(at(90), 0).cage;
  const ArapDeformer arap(rig.cage());
  EXPECT_LE(arap.energy(held), arap.energy(end) * (1 + 1e-9));
  EXPECT_LT(gap(held, end), 0.02);
  // A jump (back to 30 degrees in one event) is solved on, from rest: the same cage exactly.
  EXPECT_EQ(rig.liveFrame(at(30), 0).cage, fromRest(at(30)));
  // frame() after all this is the frame() before it, bit for bit.
  EXPECT_EQ(fromRest(at(0)), straight);
}

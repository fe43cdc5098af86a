// The transfer mesh from CGAL Mesh_3: positive tets whose labels follow S, the body's volume,
// the sizing field's effect; label separation that lets a hand leave the hip; .vtu round trips.
#include "TestPaths.h"
#include "TestTetMeshes.h"

#include "repose/io/VolumeIO.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

using namespace repose;
using namespace repose::test;

namespace {

const Volume& phantomParts(bool armsTouching) {
  static std::map<bool, Volume> cache;
  if (auto it = cache.find(armsTouching); it != cache.end()) return it->second;
  PhantomOptions o;
  o.voxelMm = 4;
  o.armsTouching = armsTouching;
  return cache.emplace(armsTouching, Phantom(o).makeVolumes().second).first->second;
}

TransferMesh phantomMesh(bool armsTouching, double size, TransferMeshReport* report = nullptr) {
  TransferMeshOptions o;
  o.sizeMm = size;
  return buildTransferMesh(phantomParts(armsTouching), o, report);
}

}  // namespace

TEST(TransferMesh, PositiveTetsWhoseLabelsFollowTheSegmentation) {
  TransferMeshReport report;
  const TransferMesh mesh = phantomMesh(false, 30, &report);
  const Volume& s = phantomParts(false);
  EXPECT_EQ(report.vertices, mesh.vertices.rows());
  EXPECT_EQ(report.tets, mesh.tets.rows());
  double volume = 0;
  int agree = 0;
  std::set<int> labels;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    const double v = tetVolume(mesh.vertices, mesh.tets.row(t));
    ASSERT_GT(v, 0) << "tet " << t;
    volume += v;
    labels.insert(mesh.labels[t]);
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += mesh.vertices.row(mesh.tets(t, k)).transpose() / 4;
    const Eigen::Vector3d ijk = s.geometry().rasToVoxel(c);
    const std::int64_t i = std::lround(ijk.x()), j = std::lround(ijk.y()), k = std::lround(ijk.z());
    if (i >= 0 && j >= 0 && k >= 0 && i < s.dims()[0] && j < s.dims()[1] && k < s.dims()[2])
      agree += s.data<std::uint8_t>()[s.index(i, j, k)] == mesh.labels[t];
  }
  EXPECT_EQ(labels.size(), 14u);
  EXPECT_GE(agree, 0.95 * mesh.tets.rows());
  std::int64_t bodyVoxels = 0;
  for (std::int64_t n = 0; n < s.numVoxels(); ++n) bodyVoxels += s.data<std::uint8_t>()[n] != 0;
  EXPECT_NEAR(volume, bodyVoxels * 64.0, 0.05 * bodyVoxels * 64.0);
}

TEST(TransferMesh, SmallerSizeGivesMoreVertices) {
  // Surface vertices are set by the one-voxel facet distance, so the growth is less than cubic.
  EXPECT_GT(phantomMesh(false, 15).vertices.rows(), phantomMesh(false, 50).vertices.rows());
}

TEST(SizingField, TrilinearInsideAndClampedOutside) {
  SizingField f = SizingField::uniform(VolumeGeometry::make({2, 2, 2}, {10, 10, 10}, {0, 0, 0}), 5);
  f.sizeMm = {0, 10, 0, 10, 0, 10, 0, 10};  // grows with x
  EXPECT_DOUBLE_EQ(f.at({5, 3, 7}), 5);
  EXPECT_DOUBLE_EQ(f.at({-50, 0, 0}), 0);
  EXPECT_DOUBLE_EQ(f.at({50, 0, 0}), 10);
  EXPECT_THROW(SizingField::uniform(f.grid, -1), Error);
}

TEST(TransferMesh, RealSegmentationTouchingTheBorderMeshesCleanly) {
  const Volume seg = readVolume(dataPath("totalsegmentator/example_seg.nii.gz"));
  TransferMeshOptions o;
  o.sizeMm = 20;
  TransferMeshReport report;
  const TransferMesh mesh = buildTransferMesh(seg, o, &report);
  EXPECT_GT(report.tets, 100);
  EXPECT_EQ(report.invertedTets, 0);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    ASSERT_GT(tetVolume(mesh.vertices, mesh.tets.row(t)), 0);
}

TEST(TransferMesh, SeparationLetsTheHandLeaveTheHip) {
  TransferMesh mesh = phantomMesh(true, 20);
  Phantom phantom([] {
    PhantomOptions o;
    o.voxelMm = 4;
    o.armsTouching = true;
    return o;
  }());
  Region region;
  region.shape = Region::Shape::Sphere;
  region.a = (phantom.joint("wrist_left").ras + phantom.joint("hand_tip_left").ras) / 2;
  region.b = Eigen::Vector3d(110, 0, 0);
  const TransferMesh before = mesh;
  auto usedBy = [](const TransferMesh& m, int label) {
    std::set<int> v;
    for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
      if (m.labels[t] == label)
        for (int k = 0; k < 4; ++k) v.insert(m.tets(t, k));
    return v;
  };
  const std::set<int> handBefore = usedBy(before, kPartHandLeft),
                      thighBefore = usedBy(before, kPartThighLeft);
  int shared = 0;
  for (int v : handBefore) shared += thighBefore.count(v);
  ASSERT_GT(shared, 0) << "the arms-touching phantom's hand mesh must touch the thigh mesh";
  const int added = separateLabels(mesh, kPartThighLeft, kPartHandLeft, region);
  EXPECT_GT(added, 0);
  const std::set<int> hand = usedBy(mesh, kPartHandLeft), thigh = usedBy(mesh, kPartThighLeft);
  for (int v : hand) EXPECT_EQ(thigh.count(v), 0u) << "vertex " << v << " still shared";
  // Moving the hand's vertices leaves every thigh vertex where it was.
  Eigen::MatrixX3d moved = mesh.vertices;
  for (int v : hand) moved.row(v) += Eigen::RowVector3d(-100, 0, 0);
  for (int v : thigh) EXPECT_EQ(moved.row(v), mesh.vertices.row(v));
  // The thigh side keeps its vertices; the hand stays attached to its forearm: wherever a hand
  // tet and a forearm tet shared a vertex before, they still share one (the copy or the original).
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (mesh.labels[t] == kPartThighLeft) {
      EXPECT_EQ(mesh.tets.row(t), before.tets.row(t));
    }
  }
  const std::set<int> forearmBefore = usedBy(before, kPartForearmLeft),
                      forearm = usedBy(mesh, kPartForearmLeft);
  int attachedBefore = 0, attached = 0;
  for (int v : handBefore) attachedBefore += forearmBefore.count(v);
  for (int v : hand) attached += forearm.count(v);
  EXPECT_EQ(attached, attachedBefore);
  EXPECT_THROW(separateLabels(mesh, kPartThighLeft, 99, region), Error);
}

TEST(TransferMesh, VtuRoundTripAndBadFiles) {
  ScratchDir dir;
  const TransferMesh mesh = phantomMesh(false, 50);
  writeTransferMesh(mesh, dir.file("tm.vtu"));
  const TransferMesh back = readTransferMesh(dir.file("tm.vtu"));
  EXPECT_EQ(back.tets, mesh.tets);
  EXPECT_EQ(back.labels, mesh.labels);
  EXPECT_LT((back.vertices - mesh.vertices).cwiseAbs().maxCoeff(), 1e-9);
  std::ofstream(dir.file("bad.vtu"))
      << "<VTKFile type=\"UnstructuredGrid\"><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\">"
         "<DataArray Name=\"Points\" format=\"binary\">AAAA</DataArray>";
  EXPECT_THROW(readTransferMesh(dir.file("bad.vtu")), Error);
  EXPECT_THROW(readTransferMesh(dir.file("missing.vtu")), Error);
  EXPECT_THROW(buildTransferMesh(Volume(VolumeGeometry::make({8, 8, 8}, {1, 1, 1}, {0, 0, 0}),
                                        ScalarType::UInt8)),
               Error);
}

TEST(TransferMesh, ReportCountsAndBoundsAgreeWithTheMesh) {
  TransferMeshReport report;
  const TransferMesh mesh = phantomMesh(false, 30, &report);
  // CGAL's cells are positive and the phantom's grid is not mirrored: nothing to fix or drop.
  EXPECT_EQ(report.degenerateTets, 0);
  EXPECT_EQ(report.invertedTets, 0);
  std::map<int, int> perLabel;
  for (Eigen::Index t = 0; t < mesh.labels.size(); ++t) ++perLabel[mesh.labels[t]];
  using Counts = std::vector<std::pair<int, int>>;
  EXPECT_EQ(report.tetsPerLabel, Counts(perLabel.begin(), perLabel.end()));
  std::vector<char> used(static_cast<std::size_t>(mesh.vertices.rows()), 0);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) used[mesh.tets(t, k)] = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "unreferenced vertices";
  // Surface vertices are found by bisection, so they may pass the voxel boundary by a hair.
  const auto [lo, hi] = phantomParts(false).geometry().rasBounds();
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
    for (int c = 0; c < 3; ++c) {
      ASSERT_GE(mesh.vertices(v, c), lo[c] - 1e-3) << "vertex " << v;
      ASSERT_LE(mesh.vertices(v, c), hi[c] + 1e-3) << "vertex " << v;
    }
}

// Determinism is checked across two fresh processes (this test re-runs itself), because within
// one process CGAL's containers may hand out different addresses and so a different order.
TEST(TransferMesh, SameMeshInAFreshProcess) {
  if (const char* out = std::getenv("REPOSE_TM_DETERMINISM_OUT")) {
    writeTransferMesh(phantomMesh(false, 30), out);
    return;
  }
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  ASSERT_FALSE(ec) << "/proc/self/exe: " << ec.message();
  ScratchDir dir;
  std::string text[2];
  for (int run = 0; run < 2; ++run) {
    const std::string file = dir.file("run" + std::to_string(run) + ".vtu");
    const std::string command = "REPOSE_TM_DETERMINISM_OUT='" + file + "' '" + self.string() +
                                "' --gtest_filter=TransferMesh.SameMeshInAFreshProcess >/dev/null";
    ASSERT_EQ(std::system(command.c_str()), 0);
    std::ifstream in(file);
    std::stringstream all;
    all << in.rdbuf();
    text[run] = all.str();
  }
  EXPECT_GT(text[0].size(), 1000u);
  EXPECT_TRUE(text[0] == text[1]) << "two fresh processes built different meshes";
}

TEST(TransferMesh, RefusesFloatVolumes) {
  Volume f(VolumeGeometry::make({8, 8, 8}, {1, 1, 1}, {0, 0, 0}), ScalarType::Float32);
  EXPECT_THROW(buildTransferMesh(f), Error);
}

TEST(TransferMesh, VtuReaderRefusesMalformedFilesNamingThem) {
  ScratchDir dir;
  const std::string head =
      "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"4\" "
      "NumberOfCells=\"1\"><DataArray type=\"Float64\" Name=\"Points\" format=\"ascii\">"
      "0 0 0 1 0 0 0 1 0 0 0 1</DataArray>";
  auto cells = [](const std::string& connectivity, const std::string& type) {
    return "<DataArray Name=\"connectivity\" format=\"ascii\">" + connectivity +
           "</DataArray><DataArray Name=\"offsets\" format=\"ascii\">4</DataArray>"
           "<DataArray Name=\"types\" format=\"ascii\">" +
           type + "</DataArray>";
  };
  const std::string label = "<DataArray Name=\"label\" format=\"ascii\">3</DataArray>";
  const std::string tail = "</Piece></UnstructuredGrid></VTKFile>";
  const std::map<std::string, std::string> files = {
      {"good.vtu", head + cells("0 1 2 3", "10") + label + tail},
      {"appended.vtu",
       "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece "
       "NumberOfPoints=\"4\" NumberOfCells=\"1\"><DataArray Name=\"Points\" "
       "format=\"appended\" offset=\"0\"/>" +
           tail},
      {"index.vtu", head + cells("0 1 2 4", "10") + label + tail},
      {"triangle.vtu", head + cells("0 1 2 3", "5") + label + tail},
      {"nolabel.vtu", head + cells("0 1 2 3", "10") + tail},
      {"truncated.vtu", head + cells("0 1 2", "10") + label + tail},
      {"notvtk.vtu", "solid x\nendsolid x\n"},
  };
  for (const auto& [name, content] : files) std::ofstream(dir.file(name)) << content;
  const TransferMesh good = readTransferMesh(dir.file("good.vtu"));
  EXPECT_EQ(good.tets.rows(), 1);
  EXPECT_EQ(good.labels[0], 3);
  for (const auto& [name, content] : files) {
    if (name == "good.vtu") continue;
    try {
      readTransferMesh(dir.file(name));
      ADD_FAILURE() << name << " was accepted";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(name), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

// The builder's fallback for bad tets: a flat one is dropped with its now unused vertices, an
// inverted one is reoriented and counted, the rest is untouched.
TEST(TransferMesh, CleaningDropsFlatTetsAndReorientsInvertedOnes) {
  TransferMesh mesh = tetBox({0, 0, 0}, {20, 20, 20}, {2, 2, 2}, 7);
  const Eigen::Index nv = mesh.vertices.rows(), nt = mesh.tets.rows();
  // A flat tet on four new coplanar vertices, and an inverted copy of tet 0 with label 9.
  mesh.vertices.conservativeResize(nv + 4, 3);
  mesh.vertices.bottomRows(4) << 50, 0, 0, 60, 0, 0, 50, 10, 0, 60, 10, 0;
  mesh.tets.conservativeResize(nt + 2, 4);
  mesh.tets.row(nt) << nv, nv + 1, nv + 2, nv + 3;
  mesh.tets.row(nt + 1) << mesh.tets(0, 0), mesh.tets(0, 1), mesh.tets(0, 3), mesh.tets(0, 2);
  mesh.labels.conservativeResize(nt + 2);
  mesh.labels.tail(2) << 8, 9;
  TransferMeshReport report;
  cleanTransferMesh(mesh, 1.0, report);
  EXPECT_EQ(report.degenerateTets, 1);
  EXPECT_EQ(report.invertedTets, 1);
  EXPECT_EQ(mesh.vertices.rows(), nv);  // the flat tet's vertices are gone
  ASSERT_EQ(mesh.tets.rows(), nt + 1);
  EXPECT_EQ(mesh.labels[nt], 9);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    EXPECT_GT(tetVolume(mesh.vertices, mesh.tets.row(t)), 0);
  EXPECT_EQ(report.tets, nt + 1);
  EXPECT_EQ(report.tetsPerLabel, (std::vector<std::pair<int, int>>{{7, int(nt)}, {9, 1}}));
  // A mirrored grid flips every tet: that alone is not an inversion.
  TransferMesh mirrored = tetBox({0, 0, 0}, {20, 20, 20}, {2, 2, 2});
  for (Eigen::Index t = 0; t < mirrored.tets.rows(); ++t)
    std::swap(mirrored.tets(t, 2), mirrored.tets(t, 3));
  cleanTransferMesh(mirrored, -1.0, report);
  EXPECT_EQ(report.invertedTets, 0);
  EXPECT_EQ(report.degenerateTets, 0);
}

TEST(TransferMesh, EveryBodyPartGetsItsTetsOnThickSlices) {
  // A small part against a large one on 8 mm slices (a hand resting on a thigh): the meshing
  // starts from a point in every connected component of every part, so the small part gets tets
  // covering about its volume (rays shot from the image's centre once left a hand with none).
  VolumeGeometry g;
  g.dims = {80, 40, 30};
  g.ijkToRas.diagonal() << 2, 2, 8, 1;
  Volume s(g, ScalarType::UInt8);
  std::int64_t small = 0;
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) {
        std::uint8_t part = 0;
        if (i >= 5 && i <= 70 && j >= 5 && j <= 35 && k >= 2 && k <= 27) part = 1;
        if (i >= 71 && i <= 75 && j >= 15 && j <= 22 && k >= 2 && k <= 4) part = 2, ++small;
        s.data<std::uint8_t>()[s.index(i, j, k)] = part;
      }
  for (const double size : {0.0, 30.0}) {
    TransferMeshOptions o;
    o.sizeMm = size;  // 0: 5 % of the diagonal
    const TransferMesh mesh = buildTransferMesh(s, o);
    double volume = 0;
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
      if (mesh.labels[t] == 2) volume += std::fabs(tetVolume(mesh.vertices, mesh.tets.row(t)));
    EXPECT_NEAR(volume, double(small) * 32.0, 0.5 * double(small) * 32.0) << "size " << size;
  }
}

TEST(TransferMesh, NoBallOfTinyTetsWhereThreePartsMeetOnThickSlices) {
  // The arms-resting phantom on 1.8 x 1.8 x 4.8 mm voxels: where three parts meet (arm, trunk and
  // girdle at a shoulder, a hand on a thigh) Mesh_3 without protected features refines along the
  // line until it gives up, and left balls of tets with 0.04 mm edges, which a pose turns inside
  // out. The short edges are collapsed (TetEdgeCollapse.cpp): none under a fifth of the finest
  // voxel is left, every tet is positive and every part keeps its tets.
  PhantomOptions po;
  po.spacingMm = {1.8, 1.8, 4.8};
  po.armsResting = true;
  const Volume s = Phantom(po).makeVolumes().second;
  TransferMeshOptions o;
  o.sizeMm = 25;
  TransferMeshReport report;
  const TransferMesh mesh = buildTransferMesh(s, o, &report);
  EXPECT_GT(report.collapsedEdges, 0);
  double shortest = 1e300;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    EXPECT_GT(tetVolume(mesh.vertices, mesh.tets.row(t)), 0);
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        shortest = std::min(
            shortest,
            (mesh.vertices.row(mesh.tets(t, a)) - mesh.vertices.row(mesh.tets(t, b))).norm());
  }
  EXPECT_GE(shortest, 0.2 * 1.8);
  std::set<int> parts, meshed(mesh.labels.data(), mesh.labels.data() + mesh.labels.size());
  for (std::int64_t i = 0; i < s.numVoxels(); ++i)
    if (s.valueAsDouble(i) != 0) parts.insert(int(s.valueAsDouble(i)));
  EXPECT_EQ(meshed, parts);
  EXPECT_EQ(report.tets, int(mesh.tets.rows()));
  EXPECT_EQ(report.vertices, int(mesh.vertices.rows()));
}

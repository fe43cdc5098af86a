// Green coordinates kept on disk (CageDeformation::saveCoordinates, mesh/GreenCoordinatesFile):
// a deformation built from the file gives the very frame a recomputed one gives, bit for bit, in
// both precisions and with rigid handle groups; a file for another mesh or cage, cut short,
// damaged, or not ours is not used, the note says why, and the frame is still the recomputed one.
// The key survives the round trip of the mesh and cage through their files (tm.vtu, cage.vtk).
#include "TestMeshes.h"
#include "TestPaths.h"
#include "TestTetMeshes.h"

#include "mesh/GreenCoordinatesFile.h"
#include "repose/io/MeshIO.h"
#include "repose/mesh/RigidHandles.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <random>

using namespace repose;
using namespace repose::test;

namespace {

// The cage bent 40 degrees about z beyond x = 120, plus a random jitter of every vertex.
Eigen::MatrixX3d posedCage(const TriangleMesh& cage, unsigned seed) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(40 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d pivot(120, 0, 0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-3, 3);
  Eigen::MatrixX3d posed = cage.vertices;
  for (Eigen::Index v = 0; v < posed.rows(); ++v) {
    if (posed(v, 0) > 120)
      posed.row(v) = (R * (posed.row(v).transpose() - pivot) + pivot).transpose();
    for (int c = 0; c < 3; ++c) posed(v, c) += jitter(rng);
  }
  return posed;
}

void expectSameFrames(const CageDeformation& a, const CageDeformation& b,
                      const TriangleMesh& cage) {
  EXPECT_EQ(a.embedding().cageVertices, b.embedding().cageVertices);
  EXPECT_EQ(a.embedding().cageTets, b.embedding().cageTets);
  EXPECT_EQ(a.embedding().inside, b.embedding().inside);
  EXPECT_EQ(a.unreproducedVertices(), b.unreproducedVertices());
  EXPECT_EQ(a.coefficientBytes(), b.coefficientBytes());
  for (const unsigned seed : {1u, 2u})
    for (const GreenPrecision precision : {GreenPrecision::Exact, GreenPrecision::Preview}) {
      const Eigen::MatrixX3d posed = posedCage(cage, seed);
      std::vector<Eigen::Matrix3d> mapsA, mapsB;
      const Eigen::MatrixX3d outA = a.deform(posed, &mapsA, precision);
      const Eigen::MatrixX3d outB = b.deform(posed, &mapsB, precision);
      EXPECT_EQ((outA - outB).cwiseAbs().maxCoeff(), 0.0) << "seed " << seed;
      ASSERT_EQ(mapsA.size(), mapsB.size());
      for (std::size_t t = 0; t < mapsA.size(); ++t) ASSERT_EQ(mapsA[t], mapsB[t]) << "tet " << t;
    }
}

std::vector<char> bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeBytes(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace

TEST(GreenCoordinatesFile, ReadCoordinatesGiveTheRecomputedFrameBitForBit) {
  const ScratchDir dir;
  const TransferMesh mesh = cagedLimb();
  const TriangleMesh cage = cagedLimbCage();
  const CageDeformation computed(mesh, cage, 2);
  EXPECT_FALSE(computed.coordinatesRead());
  EXPECT_GT(computed.embedding().outliers(), 0);
  const std::string file = dir.file("tm.green");
  computed.saveCoordinates(file);
  const CageDeformation read(mesh, cage, 2, file);
  EXPECT_TRUE(read.coordinatesRead()) << read.coordinatesNote();
  EXPECT_EQ(read.coordinatesNote(), "");
  expectSameFrames(computed, read, cage);
  // With rigid handle groups (the frame of `repose pose`): the distal cage turned as one group.
  std::vector<RigidHandle> handles(1);
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v)
    if (cage.vertices(v, 0) > 150) handles[0].cageVertices.push_back(static_cast<int>(v));
  handles[0].motion = Eigen::Translation3d(120, 0, 0) *
                      Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                      Eigen::Translation3d(-120, 0, 0);
  handles.emplace_back();  // the proximal cage held in place
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v)
    if (cage.vertices(v, 0) < 60) handles[1].cageVertices.push_back(static_cast<int>(v));
  const HandleInfluence influence = computeHandleInfluence(mesh, cage, handles, 2, 1);
  const Eigen::MatrixX3d posed = moveHandles(cage.vertices, handles);
  const Eigen::MatrixX3d a = computed.deform(posed, influence, handles);
  const Eigen::MatrixX3d b = read.deform(posed, influence, handles);
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0);
}

TEST(GreenCoordinatesFile, TheKeySurvivesTheMeshAndCageFiles) {
  const ScratchDir dir;
  const TransferMesh mesh = cagedLimb();
  // Vertices that are not short decimals, as Mesh_3 makes them.
  TransferMesh jittered = mesh;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-0.3, 0.3);
  for (Eigen::Index v = 0; v < jittered.vertices.rows(); ++v)
    for (int c = 0; c < 3; ++c) jittered.vertices(v, c) += d(rng) / 3.0;
  TriangleMesh cage = cagedLimbCage();
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v)
    for (int c = 0; c < 3; ++c) cage.vertices(v, c) += d(rng) / 7.0;
  writeTransferMesh(jittered, dir.file("tm.vtu"));
  writeTriangleMesh(cage, dir.file("cage.vtk"));
  EXPECT_EQ(greenCoordinatesFileFor(dir.file("tm.vtu")), dir.file("tm.green"));
  const CageDeformation computed(jittered, cage, 2);
  computed.saveCoordinates(dir.file("tm.green"));
  const TransferMesh meshBack = readTransferMesh(dir.file("tm.vtu"));
  const TriangleMesh cageBack = readTriangleMesh(dir.file("cage.vtk"));
  EXPECT_EQ(greenCoordinatesKey(meshBack, cageBack), greenCoordinatesKey(jittered, cage));
  const CageDeformation read(meshBack, cageBack, 2, dir.file("tm.green"));
  EXPECT_TRUE(read.coordinatesRead()) << read.coordinatesNote();
  expectSameFrames(computed, read, cage);
}

TEST(GreenCoordinatesFile, AFileThatDoesNotBelongIsNotUsedAndSaysWhy) {
  const ScratchDir dir;
  const TransferMesh mesh = cagedLimb();
  const TriangleMesh cage = cagedLimbCage();
  const CageDeformation computed(mesh, cage, 2);
  const std::string file = dir.file("tm.green");
  computed.saveCoordinates(file);
  const std::vector<char> good = bytesOf(file);

  const auto expectRecomputed = [&](const TransferMesh& m, const TriangleMesh& c,
                                    const std::string& path, const std::string& why) {
    SCOPED_TRACE(why);
    const CageDeformation d(m, c, 2, path);
    EXPECT_FALSE(d.coordinatesRead());
    EXPECT_NE(d.coordinatesNote().find(why), std::string::npos) << d.coordinatesNote();
    EXPECT_EQ(d.coordinatesNote().rfind(path, 0), 0u) << "names the file";
    if (&m == &mesh && &c == &cage) expectSameFrames(computed, d, cage);
  };
  expectRecomputed(mesh, cage, dir.file("absent.green"), "no such file");
  // Another mesh: one vertex moved by a micrometre, or the same vertices in other tets.
  TransferMesh moved = mesh;
  moved.vertices(5, 1) += 1e-3;
  expectRecomputed(moved, cage, file, "another transfer mesh or cage");
  TransferMesh retet = mesh;
  retet.tets.row(0) << mesh.tets(0, 1), mesh.tets(0, 2), mesh.tets(0, 0), mesh.tets(0, 3);  // even
  expectRecomputed(retet, cage, file, "another transfer mesh or cage");
  // Another cage: the same vertices, one moved.
  TriangleMesh otherCage = cage;
  otherCage.vertices(3, 2) += 1e-6;
  expectRecomputed(mesh, otherCage, file, "another transfer mesh or cage");

  std::vector<char> bytes = good;
  bytes.resize(bytes.size() / 2);
  writeBytes(file, bytes);
  expectRecomputed(mesh, cage, file, "cut short");
  bytes = good;
  bytes.push_back('x');
  writeBytes(file, bytes);
  expectRecomputed(mesh, cage, file, "longer than its contents");
  // One bit of a coefficient (the last half of the low halves), and one of V_c's list.
  bytes = good;
  bytes[bytes.size() - 6] ^= 0x10;
  writeBytes(file, bytes);
  expectRecomputed(mesh, cage, file, "damaged (CRC)");
  bytes = good;
  bytes[80] ^= 0x01;
  writeBytes(file, bytes);
  expectRecomputed(mesh, cage, file, "damaged");
  bytes = good;
  bytes[0] = 'X';
  writeBytes(file, bytes);
  expectRecomputed(mesh, cage, file, "not a Repose Green-coordinate file");
  writeBytes(file, {});
  expectRecomputed(mesh, cage, file, "cut short");
  // A folder where the file should be.
  std::filesystem::remove(file);
  std::filesystem::create_directory(file);
  expectRecomputed(mesh, cage, file, "no such file");
}

TEST(GreenCoordinatesFile, SavingIsAtomicAndRefusesAMissingFolder) {
  const ScratchDir dir;
  const CageDeformation d(cagedLimb(), cagedLimbCage(), 2);
  EXPECT_THROW(d.saveCoordinates(dir.file("no/such/folder/tm.green")), Error);
  d.saveCoordinates(dir.file("tm.green"));
  d.saveCoordinates(dir.file("tm.green"));  // over an existing one
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1) << "no temporary left beside it";
}

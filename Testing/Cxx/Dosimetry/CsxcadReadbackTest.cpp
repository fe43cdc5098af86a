// The FDTD model read back by openEMS's own geometry library, CSXCAD, as the solver reads it:
// MODEL.csx.xml through ContinuousStructure::ReadFromXML, then permittivity, conductivity and
// density at the centre of every cell through the discrete material's lookups. Runs with
// libReposeCsxcadFix preloaded (Testing/CMakeLists.txt), without which Debian 12's CSXCAD cannot
// read any discrete material (Dosimetry/CsxcadDiscMaterialRead.cpp).
#include "TestPaths.h"

#include "repose/dosimetry/FdtdModel.h"
#include "repose/dosimetry/FdtdModelIO.h"

#include <ContinuousStructure.h>
#include <CSPropDiscMaterial.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>

using namespace repose;

namespace {

// A small body on an LPS grid whose voxel order is not RAS's, with four tissues, one of them
// twice at two densities.
Volume smallBody() {
  Volume v(VolumeGeometry::make({9, 7, 5}, {2.0, 3.0, 4.0}, {30, 20, -50},
                                (Eigen::Matrix3d() << -1, 0, 0, 0, -1, 0, 0, 0, 1).finished()),
           ScalarType::Int16);
  v.setLabelMap(true);
  std::int16_t* p = v.data<std::int16_t>();
  for (std::int64_t n = 0; n < v.numVoxels(); ++n) p[n] = std::int16_t((n * 7) % 6);
  return v;
}

}  // namespace

TEST(CsxcadReadback, EveryCellReadsBackItsTissueThroughCsxcad) {
  test::ScratchDir dir;
  const Volume v = smallBody();
  std::map<int, LabelTissue> labels;
  labels[1] = {"skin", 1109, "t", "Skin (Dry)", "t"};
  labels[2] = {"muscle", 1090, "t", "Muscle", "t"};
  labels[3] = {"cortical", 1920, "t", "Bone (Cortical)", "t"};
  labels[4] = {"spongiosa a", 1185, "t", "Bone (Cancellous)", "t"};
  labels[5] = {"spongiosa b", 1117, "t", "Bone (Cancellous)", "t"};
  FdtdModelOptions o;
  o.frequencyHz = 900e6;
  const FdtdModel model = buildFdtdModel(v, labels, o, "small");
  ASSERT_EQ(model.materials.size(), 6u);
  const std::string h5 = dir.file("model.h5");
  writeFdtdModel(model, labels, h5, {});
  const FdtdModelFiles files = fdtdModelFiles(h5);

  ContinuousStructure csx;
  const std::string error = csx.ReadFromXML(files.csx);
  ASSERT_EQ(error, "") << "CSXCAD could not read the model (is libReposeCsxcadFix preloaded?)";
  const std::vector<CSProperties*> found = csx.GetPropertiesByName("body");
  ASSERT_EQ(found.size(), 1u);
  CSPropDiscMaterial* disc = found[0]->ToDiscMaterial();
  ASSERT_NE(disc, nullptr) << "the body is not a discrete material";
  ASSERT_NEAR(csx.GetGrid()->GetDeltaUnit(), 1e-3, 1e-15);

  int checked = 0;
  for (std::int64_t z = 0; z < model.dims[2]; ++z)
    for (std::int64_t y = 0; y < model.dims[1]; ++y)
      for (std::int64_t x = 0; x < model.dims[0]; ++x) {
        const Eigen::Vector3d c =
            model.cornerMm +
            (Eigen::Vector3d(double(x), double(y), double(z)) + Eigen::Vector3d::Constant(0.5))
                .cwiseProduct(model.spacingMm);
        const double coords[3] = {c.x(), c.y(), c.z()};  // drawing units: mm
        const FdtdMaterial& m =
            model.materials[model.index[std::size_t((z * model.dims[1] + y) * model.dims[0] + x)]];
        // Also against G itself: the label of the voxel at this point, through its own matrix.
        const Eigen::Vector4d ijk = v.geometry().ijkToRas.inverse() * c.homogeneous();
        const int label = v.data<std::int16_t>()[v.index(std::lround(ijk[0]), std::lround(ijk[1]),
                                                         std::lround(ijk[2]))];
        const std::string tissue = label == 0 ? "background" : labels.at(label).tissue;
        ASSERT_EQ(m.tissue, tissue) << x << " " << y << " " << z;
        for (int n = 0; n < 3; ++n) {
          ASSERT_FLOAT_EQ(float(disc->GetEpsilonWeighted(n, coords)),
                          float(m.dielectric.relativePermittivity));
          ASSERT_FLOAT_EQ(float(disc->GetKappaWeighted(n, coords)),
                          float(m.dielectric.conductivity));
        }
        ASSERT_FLOAT_EQ(float(disc->GetDensityWeighted(coords)), float(m.densityKgM3));
        ++checked;
      }
  EXPECT_EQ(checked, 9 * 7 * 5);
  // Outside the model CSXCAD falls back to the property's own values: vacuum, no density.
  const double outside[3] = {model.cornerMm.x() - 10, model.cornerMm.y(), model.cornerMm.z()};
  EXPECT_DOUBLE_EQ(disc->GetEpsilonWeighted(0, outside), 1.0);
  EXPECT_DOUBLE_EQ(disc->GetDensityWeighted(outside), 0.0);
}

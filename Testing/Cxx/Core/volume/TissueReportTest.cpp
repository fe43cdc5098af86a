// What reports rest on: tissue tables (CSV, checked line by line) and the count of background
// voxels enclosed by the body (holes a pose must not create).
#include "TestPaths.h"

#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <gtest/gtest.h>

using namespace repose;

TEST(TissueTable, ThePhantomTableNamesEveryPhantomLabelWithBonesRigid) {
  const TissueTable t =
      readTissueTable(std::string(REPOSE_SOURCE_DIR) + "/Resources/Tissues/phantom.csv");
  EXPECT_EQ(t.size(), 36u);  // 27 labels, and 9 more of the detailed anatomy (--arms-resting)
  EXPECT_EQ(t.at(12).name, "radius_ulna");
  EXPECT_TRUE(t.at(12).rigid);
  EXPECT_FALSE(t.at(3).rigid);  // muscle
  for (const auto& [label, tissue] : t) EXPECT_GT(tissue.densityKgM3, 300) << label;
  // A bone's marrow is part of that bone; vessels are soft.
  EXPECT_TRUE(t.at(28).rigid);
  EXPECT_EQ(t.at(28).boneName(), "humerus");
  EXPECT_EQ(t.at(11).boneName(), "humerus");
  EXPECT_FALSE(t.at(33).rigid);
  // The table compiled into Core is this file.
  EXPECT_EQ(tissueTableCsv(phantomTissueTable()), tissueTableCsv(t));
}

TEST(TissueTable, TheBoneColumnIsOptionalAndRoundTrips) {
  const TissueTable four =
      parseTissueTable("label,name,density_kg_m3,rigid\n4,skull,1908,1\n", "a");
  EXPECT_EQ(four.at(4).boneName(), "skull");
  const TissueTable five = parseTissueTable(
      "label,name,density_kg_m3,rigid,bone\n13,cortex,1920,1,humerus\n"
      "14,spongiosa,1185,1,humerus\n2,fat,911,0,\n",
      "b");
  EXPECT_EQ(five.at(14).boneName(), "humerus");
  EXPECT_EQ(five.at(2).bone, "");
  const TissueTable again =
      parseTissueTable(tissueTableCsv(five, "a comment\nover two lines"), "c");
  EXPECT_EQ(tissueTableCsv(again), tissueTableCsv(five));
  EXPECT_THROW(parseTissueTable("label,name,density_kg_m3,rigid,b\n", "d"), Error);
}

TEST(TissueTable, MalformedLinesAreRefusedWithTheirLineNumber) {
  const std::string header = "label,name,density_kg_m3,rigid\n";
  EXPECT_EQ(parseTissueTable("# c\n" + header + "1,skin,1109,0\r\n", "t.csv").at(1).densityKgM3,
            1109);
  const std::pair<std::string, std::string> bad[] = {
      {"", "t.csv: empty"},
      {"label,name\n", "t.csv:1: expected the header"},
      {header + "1,skin,1109\n", "t.csv:2: expected 4 fields"},
      {header + "x,skin,1109,0\n", "t.csv:2: label must be an integer"},
      {header + "1,skin,-5,0\n", "t.csv:2: density_kg_m3 must be positive"},
      {header + "1,skin,1109,yes\n", "t.csv:2: rigid must be 0 or 1"},
      {header + "1,skin,1109,0\n1,fat,911,0\n", "t.csv:3: label 1 given twice"},
  };
  for (const auto& [text, message] : bad) {
    try {
      parseTissueTable(text, "t.csv");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0u) << e.what();
    }
  }
  EXPECT_THROW(readTissueTable("/nonexistent.csv"), Error);
}

TEST(LabelStatistics, EnclosedBackgroundCountsOnlyCavitiesNotTheOutside) {
  Volume v(VolumeGeometry::make({10, 10, 10}, {1, 1, 1}, {0, 0, 0}), ScalarType::UInt8);
  auto at = [&](int i, int j, int k) -> std::uint8_t& {
    return v.data<std::uint8_t>()[v.index(i, j, k)];
  };
  EXPECT_EQ(countEnclosedBackground(v), 0);  // all outside
  for (int k = 2; k < 8; ++k)
    for (int j = 2; j < 8; ++j)
      for (int i = 2; i < 8; ++i) at(i, j, k) = 3;  // a solid cube
  EXPECT_EQ(countEnclosedBackground(v), 0);
  at(4, 4, 4) = at(5, 4, 4) = 0;  // a two-voxel cavity
  EXPECT_EQ(countEnclosedBackground(v), 2);
  at(2, 4, 4) = at(3, 4, 4) = 0;  // a tunnel to the outside opens it (6-connected)
  EXPECT_EQ(countEnclosedBackground(v), 0);
}

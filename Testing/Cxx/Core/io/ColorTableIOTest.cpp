// Slicer colour tables (.ctbl) as vtkMRMLColorTableStorageNode.cxx reads them: '#' comment lines,
// then "index name r g b a" split on whitespace, colours on a 0-255 scale, '_' read as a space,
// indices not listed left undefined.
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/io/ColorTableIO.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace repose;
using namespace repose::test;

namespace {

struct Entry {
  std::string name;
  int rgba[4];
};

// Parsed the way Slicer's reader does; the header's value count beside.
std::map<int, Entry> readCtbl(const std::string& path, int& declared) {
  std::ifstream in(path);
  std::string line;
  std::map<int, Entry> out;
  declared = -1;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) {
      std::istringstream c(line.substr(1));
      int n;
      std::string word;
      if (c >> n >> word && word == "values") declared = n;
      continue;
    }
    std::istringstream fields(line);
    int index;
    Entry e;
    EXPECT_TRUE(fields >> index >> e.name >> e.rgba[0] >> e.rgba[1] >> e.rgba[2] >> e.rgba[3])
        << line;
    std::string extra;
    EXPECT_FALSE(fields >> extra) << "more than six fields: " << line;
    for (int c : e.rgba) {
      EXPECT_GE(c, 0);
      EXPECT_LE(c, 255);
    }
    EXPECT_EQ(out.count(index), 0u) << "index listed twice: " << index;
    out[index] = e;
  }
  return out;
}

}  // namespace

TEST(ColorTableIO, NamesColoursAndEveryValuePresentAsSlicerReadsThem) {
  ScratchDir dir;
  Volume v(obliqueGeometry({6, 5, 4}), ScalarType::UInt16);
  v.data<std::uint16_t>()[v.index(1, 1, 1)] = 3;
  v.data<std::uint16_t>()[v.index(2, 1, 1)] = 300;  // present, in no table
  v.setLabelMap(true);
  Label a;
  a.value = 3, a.name = "small intestine wall", a.color = {1.0, 0.5, 0.0};
  Label b;  // in the table, no voxel: kept (a pose may have lost it; it keeps its colour)
  b.value = 17, b.name = "", b.color = {0.2, 0.4, 0.6};
  v.labels().set(a);
  v.labels().set(b);
  writeColorTable(v, dir.file("t.ctbl"));
  int declared = 0;
  const auto t = readCtbl(dir.file("t.ctbl"), declared);
  EXPECT_EQ(declared, 301);  // highest index + 1, as Slicer writes it
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t.at(0).name, "Background");
  EXPECT_EQ(t.at(0).rgba[3], 0);  // transparent
  EXPECT_EQ(t.at(3).name, "small_intestine_wall");
  EXPECT_EQ(t.at(3).rgba[0], 255);
  EXPECT_EQ(t.at(3).rgba[1], 128);
  EXPECT_EQ(t.at(3).rgba[2], 0);
  EXPECT_EQ(t.at(3).rgba[3], 255);
  EXPECT_EQ(t.at(17).name, "label_17");
  EXPECT_EQ(t.at(17).rgba[2], 153);
  // A value the table does not name: a generated name and the colour the workbench shows it in.
  EXPECT_EQ(t.at(300).name, "label_300");
  const auto c = LabelTable::defaultColor(300);
  EXPECT_EQ(t.at(300).rgba[0], int(std::lround(c[0] * 255)));
  EXPECT_EQ(t.at(300).rgba[1], int(std::lround(c[1] * 255)));
}

TEST(ColorTableIO, NegativeLabelsAreRefusedWithTheFileNamed) {
  ScratchDir dir;
  Volume v(obliqueGeometry({2, 2, 2}), ScalarType::Int16);
  v.data<std::int16_t>()[0] = -4;
  v.setLabelMap(true);
  Label neg;
  neg.value = -4, neg.name = "x";
  v.labels().set(neg);
  try {
    writeColorTable(v, dir.file("n.ctbl"));
    FAIL() << "a negative label was written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("n.ctbl"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("n.ctbl")));
}

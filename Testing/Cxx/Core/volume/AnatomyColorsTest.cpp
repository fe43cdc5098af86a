// Label colours by structure name (volume/AnatomyColors) and the naming of a user's unnamed labels
// for display (rig/LabelConvention completeLabelNamesAndColors): class colours where a reader
// expects them, every label of the real label sets distinct on screen, names from the
// convention or the tissue table, a file's own names and colours kept.
#include "TestPaths.h"

#include <repose/io/ColorTableIO.h>
#include <repose/phantom/Phantom.h>
#include <repose/rig/LabelConvention.h>
#include <repose/util/Error.h>
#include <repose/volume/AnatomyColors.h>
#include <repose/volume/LabelStatistics.h>
#include <repose/volume/LabelTable.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace repose {
namespace {

using Rgb8 = std::array<int, 3>;

// As a slice view draws a label over black at its default opacity (0.8), in 8 bits.
Rgb8 drawn(const std::array<double, 3>& c) {
  return {int(std::lround(255 * 0.8 * c[0])), int(std::lround(255 * 0.8 * c[1])),
          int(std::lround(255 * 0.8 * c[2]))};
}

int distance(const Rgb8& a, const Rgb8& b) {
  return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}

// A label map holding one voxel of each label, named as given and coloured by no file.
Volume oneVoxelEach(const std::map<int, std::string>& names) {
  VolumeGeometry g;
  g.dims = {std::int64_t(names.size()), 1, 1};
  Volume G(g, ScalarType::UInt16);
  G.setLabelMap(true);
  std::int64_t i = 0;
  for (const auto& [v, n] : names) {
    G.data<std::uint16_t>()[i++] = std::uint16_t(v);
    Label l;
    l.value = v;
    l.name = n;
    l.color = LabelTable::defaultColor(v, n);
    l.colorGenerated = true;  // as a reader marks a colour it made up
    G.labels().set(l);
  }
  return G;
}

// The closest two labels of a table as drawn (L-infinity in 8 bits), and which they are.
std::pair<int, std::string> closestPair(const LabelTable& table) {
  std::map<int, std::string> names;
  std::vector<std::pair<int, Rgb8>> colours;
  for (const Label& l : table.labels()) {
    names[l.value] = l.name;
    colours.push_back({l.value, drawn(l.color)});
  }
  int best = 1 << 20;
  std::string which;
  for (std::size_t i = 0; i < colours.size(); ++i)
    for (std::size_t j = i + 1; j < colours.size(); ++j)
      if (const int d = distance(colours[i].second, colours[j].second); d < best) {
        best = d;
        which = names.at(colours[i].first) + " / " + names.at(colours[j].first);
      }
  return {best, which};
}

std::map<int, std::string> icrpNames() {
  // The structure names of ICRP 110, as the shared label README gives them (quoted CSV).
  std::ifstream in(test::dataPath("../labels/icrp110_organs.csv"));
  std::map<int, std::string> out;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    const std::size_t q1 = line.find('"'), q2 = line.find('"', q1 + 1);
    const std::size_t comma = line.find(',');
    if (q1 != std::string::npos && q2 != std::string::npos)
      out[std::stoi(line.substr(0, comma))] = line.substr(q1 + 1, q2 - q1 - 1);
    else
      out[std::stoi(line.substr(0, comma))] =
          line.substr(comma + 1, line.find(',', comma + 1) - comma - 1);
  }
  return out;
}

std::map<int, std::string> totalSegmentatorNames() {
  std::ifstream in(test::dataPath("totalsegmentator/example_seg_labels.tsv"));
  std::map<int, std::string> out;
  std::string line;
  std::getline(in, line);  // value name r g b
  while (std::getline(in, line)) {
    std::istringstream f(line);
    int v;
    std::string n;
    if (f >> v >> n) out[v] = n;
  }
  return out;
}

bool reddish(const std::array<double, 3>& c) {
  return c[0] > c[1] + 0.2 && c[0] > c[2] + 0.2;
}

TEST(AnatomyColors, StructuresGetTheirClassColour) {
  // Bone ivory (light, red >= green >= blue), muscle and arteries red, veins blue, fat yellow.
  for (const char* bone : {"Humeri, upper half, cortical", "femur_left", "vertebrae_L3", "skull"}) {
    const auto c = anatomyColor(bone, 13);
    ASSERT_TRUE(c) << bone;
    EXPECT_GT((*c)[0] + (*c)[1] + (*c)[2], 1.7) << bone;
    EXPECT_GE((*c)[0] + 0.02, (*c)[2]) << bone;
  }
  for (const char* red : {"Muscle, trunk", "aorta", "iliac_artery_left", "muscle"})
    EXPECT_TRUE(reddish(*anatomyColor(red, 7))) << red;
  for (const char* vein : {"inferior_vena_cava", "portal_vein_and_splenic_vein"}) {
    const auto c = *anatomyColor(vein, 7);
    EXPECT_GT(c[2], c[0] + 0.2) << vein;
  }
  const auto fat = *anatomyColor("subcutaneous_fat", 2);
  EXPECT_GT(fat[0] + fat[1], 2 * fat[2] + 0.6);
  // The marrow of a bone is not the bone's colour: specific rules come first.
  EXPECT_EQ(anatomyColorRule("humerus_marrow"), "*marrow*");
  EXPECT_EQ(anatomyColorRule("Humeri, upper half, spongiosa"), "*spongiosa*");
  EXPECT_EQ(anatomyColorRule("spinal_cord"), "spinal cord");
  EXPECT_EQ(anatomyColorRule("pulmonary_vein"), "*pulmonary vein*");
  // No rule: nothing here, and the label falls back to its own hue.
  EXPECT_FALSE(anatomyColor("tumour 3", 3));
  EXPECT_FALSE(anatomyColor("", 3));
  EXPECT_EQ(LabelTable::defaultColor(3, "tumour 3"), LabelTable::defaultColor(3));
  // Stable: the same label gets the same colour.
  EXPECT_EQ(*anatomyColor("liver", 20), *anatomyColor("Liver", 20));
}

TEST(AnatomyColors, EveryLabelOfTheRealLabelSetsIsDistinctOnScreen) {
  // ICRP 110's 140 structures (dozens of bones in a few classes), TotalSegmentator's example
  // labels and the phantom's, named by their files with no colours: once completed for display,
  // no two labels of one set draw within 4 levels of each other, and the class colours stay.
  const std::map<int, std::string> icrp = icrpNames();
  ASSERT_GE(icrp.size(), 136u);
  int known = 0;
  for (const auto& [v, n] : icrp) known += anatomyColor(n, v).has_value();
  EXPECT_GE(known, 125) << "ICRP 110 structures with a class colour";
  const std::map<int, std::string> ts = totalSegmentatorNames();
  ASSERT_GE(ts.size(), 40u);
  std::map<int, std::string> phantom;
  for (const auto& [v, t] : phantomTissueTable()) phantom[v] = t.name;
  using Names = std::map<int, std::string>;
  for (const Names* set : std::array<const Names*, 3>{&icrp, &ts, &phantom}) {
    Volume G = oneVoxelEach(*set);
    EXPECT_EQ(completeLabelNamesAndColors(G, nullptr, "G"), "");  // every label was named
    const auto [d, which] = closestPair(G.labels());
    EXPECT_GE(d, 4) << which;
    // Moved apart within the class: a bone stays light and a muscle red.
    for (const Label& l : G.labels().labels()) {
      const std::string rule = anatomyColorRule(l.name);
      if (rule == "*cortical*" || rule == "vertebra*" || rule == "rib *") {
        EXPECT_GT(l.color[0] + l.color[1] + l.color[2], 1.5) << l.name;
      }
      if (rule == "*muscle*") {
        EXPECT_TRUE(reddish(l.color)) << l.name;
      }
    }
  }
}

TEST(AnatomyColors, UnnamedIcrpLabelsAreNamedByTheConventionAndColouredByName) {
  PhantomOptions po;
  po.voxelMm = 8;
  po.armsResting = true;
  po.labels = PhantomLabelling::Icrp110;
  Volume G = Phantom(po).makeVolumes().first;
  ASSERT_TRUE(G.labels().empty());  // as a converted ICRP array arrives
  const std::string note = completeLabelNamesAndColors(G, nullptr, "G.nii.gz");
  EXPECT_NE(note.find("G.nii.gz: "), std::string::npos) << note;
  EXPECT_NE(note.find("icrp110"), std::string::npos) << note;
  const std::map<int, std::string> icrp = icrpNames();
  std::map<int, std::string> shown;
  for (const LabelCount& c : countLabels(G)) {
    const Label* l = G.labels().find(c.value);
    ASSERT_TRUE(l) << c.value;
    shown[c.value] = l->name;
    EXPECT_EQ(l->name, icrp.at(c.value));
    EXPECT_TRUE(l->colorGenerated);
    if (anatomyColorRule(l->name) == "*cortical*") {
      EXPECT_GT(l->color[0] + l->color[1] + l->color[2], 1.5) << l->name;
    }
  }
  EXPECT_GE(shown.size(), 20u);
  // Done twice: nothing changes (a scene reopened, a volume shown again).
  const LabelTable once = G.labels();
  EXPECT_EQ(completeLabelNamesAndColors(G, nullptr, "G.nii.gz"), "");
  ASSERT_EQ(G.labels().size(), once.size());
  for (std::size_t i = 0; i < once.size(); ++i) {
    EXPECT_EQ(G.labels().labels()[i].name, once.labels()[i].name);
    EXPECT_EQ(G.labels().labels()[i].color, once.labels()[i].color);
  }
}

// A viewer that has counted the labels already hands its counts over: the names, colours and
// note are those of a count of its own, and only the labels in the counts are named (the map is
// not read again: one pass on open instead of three at a gigavoxel).
TEST(AnatomyColors, LabelCountsHandedOverGiveTheSameNamesWithoutReadingTheMapAgain) {
  PhantomOptions po;
  po.voxelMm = 8;
  po.armsResting = true;
  po.labels = PhantomLabelling::Icrp110;
  const Volume plain = Phantom(po).makeVolumes().first;
  Volume own = plain, handed = plain, partial = plain;
  const std::vector<LabelCount> counts = countLabels(plain);
  const std::string note = completeLabelNamesAndColors(own, nullptr, "G.nii.gz");
  EXPECT_EQ(completeLabelNamesAndColors(handed, nullptr, "G.nii.gz", &counts), note);
  ASSERT_EQ(handed.labels().size(), own.labels().size());
  for (std::size_t i = 0; i < own.labels().size(); ++i) {
    EXPECT_EQ(handed.labels().labels()[i].value, own.labels().labels()[i].value);
    EXPECT_EQ(handed.labels().labels()[i].name, own.labels().labels()[i].name);
    EXPECT_EQ(handed.labels().labels()[i].color, own.labels().labels()[i].color);
  }
  // Counts without one label: that label is left as the file had it (unnamed), so the counts
  // handed over are what was used.
  std::vector<LabelCount> fewer = counts;
  const int dropped = fewer.back().value;
  fewer.pop_back();
  completeLabelNamesAndColors(partial, nullptr, "G.nii.gz", &fewer);
  EXPECT_EQ(partial.labels().find(dropped), nullptr);
  EXPECT_EQ(partial.labels().size(), own.labels().size() - 1);
}

TEST(AnatomyColors, NamesComeFromATissueTableOrStayNumbers) {
  VolumeGeometry g;
  g.dims = {4, 4, 4};
  Volume G(g, ScalarType::UInt16);
  G.setLabelMap(true);
  auto* v = G.data<std::uint16_t>();
  for (int i = 0; i < 64; ++i) v[i] = std::uint16_t(i < 20 ? 1000 : i < 40 ? 2000 : 0);
  // No convention knows labels 1000 and 2000: they keep their numbers and their own hues.
  Volume plain = G;
  const std::string note = completeLabelNamesAndColors(plain, nullptr, "x.nii");
  EXPECT_NE(note.find("no label convention or tissue table names them"), std::string::npos) << note;
  ASSERT_TRUE(plain.labels().find(1000));
  EXPECT_EQ(plain.labels().find(1000)->name, "1000");
  EXPECT_EQ(plain.labels().find(1000)->color, LabelTable::defaultColor(1000));
  // A tissue table names them, and the names colour them; a colour the file gave stays.
  Label given;
  given.value = 1000;
  given.color = {0.1, 0.2, 0.3};
  G.labels().set(given);
  TissueTable tissues;
  tissues[1000] = Tissue{"liver", 1079, false, ""};
  tissues[2000] = Tissue{"femur", 1908, true, ""};
  const std::string named = completeLabelNamesAndColors(G, &tissues, "x.nii");
  EXPECT_NE(named.find("2 named from the tissue table"), std::string::npos) << named;
  EXPECT_EQ(G.labels().find(1000)->name, "liver");
  EXPECT_EQ(G.labels().find(1000)->color, given.color);
  EXPECT_FALSE(G.labels().find(1000)->colorGenerated);
  EXPECT_EQ(G.labels().find(2000)->color, *anatomyColor("femur", 2000));
}

}  // namespace
}  // namespace repose

// A reference colour table, as a user with 3D Slicer has its GenericAnatomyColors.txt: the names
// it lists take its colours exactly (case and '_' aside), other names the rules' shaded class
// colour; the file is what writeColorTable writes and Slicer reads; a malformed line is refused
// naming the file and the line; $REPOSE_COLOR_TABLE names the table when none is set, and an
// unreadable one is an error, not other colours.
TEST(AnatomyColors, AReferenceColorTableGivesItsColoursByName) {
  repose::test::ScratchDir dir;
  const std::string path = (dir.path() / "reference.txt").string();
  {
    std::ofstream out(path);
    out << "# Color table file reference.txt\n# 4 values\n0 background 0 0 0 0\n"
           "1 liver 10 20 30 255\n2 skeletal_muscle 200 100 50 255\n3 left_kidney 1 2 3 255\n";
  }
  const repose::LabelTable table = repose::readColorTable(path);
  ASSERT_EQ(table.labels().size(), 4u);
  EXPECT_EQ(table.find(2)->name, "skeletal muscle");
  EXPECT_DOUBLE_EQ(table.find(1)->color[2], 30 / 255.0);
  const auto rulesLiver = repose::anatomyColor("liver", 5);  // before the table
  repose::setReferenceColors(table);
  const auto liver = repose::LabelTable::defaultColor(5, "Liver");
  EXPECT_DOUBLE_EQ(liver[0], 10 / 255.0);
  EXPECT_DOUBLE_EQ(liver[2], 30 / 255.0);
  EXPECT_EQ(repose::LabelTable::defaultColor(77, "skeletal muscle"),
            repose::LabelTable::defaultColor(9, "Skeletal_Muscle"));  // one colour, any value
  // Not listed: the rules, as before.
  EXPECT_EQ(repose::anatomyColor("spleen", 4), [] {
    repose::setReferenceColors({});
    return repose::anatomyColor("spleen", 4);
  }());
  repose::setReferenceColors(table);
  EXPECT_FALSE(repose::referenceColor("spleen"));
  // A second shade of a listed name (completeLabelNamesAndColors' variants) comes from the rules.
  EXPECT_EQ(repose::anatomyColor("liver", 5, 1), [&] {
    repose::setReferenceColors({});
    return repose::anatomyColor("liver", 5, 1);
  }());

  // Written by writeColorTable and read back: the same names and colours.
  repose::VolumeGeometry grid;
  grid.dims = {2, 2, 2};
  repose::Volume labels(grid, repose::ScalarType::UInt8);
  labels.labels() = table;
  const std::string written = (dir.path() / "written.ctbl").string();
  repose::writeColorTable(labels, written);
  const repose::LabelTable back = repose::readColorTable(written);
  for (const repose::Label& l : table.labels()) {
    if (l.value == 0) continue;
    ASSERT_TRUE(back.find(l.value)) << l.value;
    EXPECT_EQ(back.find(l.value)->name, l.name);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(back.find(l.value)->color[std::size_t(k)], l.color[std::size_t(k)], 0.5 / 255);
  }

  // Bad files: one line naming the file and what is wrong.
  auto refused = [&](const std::string& text) {
    const std::string bad = (dir.path() / "bad.txt").string();
    std::ofstream(bad) << text;
    try {
      repose::readColorTable(bad);
    } catch (const repose::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refused("# c\n1 liver 10 20\n").rfind(dir.path().string() + "/bad.txt: line 2:", 0),
            0u);
  EXPECT_NE(refused("1 liver 10 20 300 255\n").find("line 1: a colour is 0 to 255"),
            std::string::npos);
  EXPECT_NE(refused("1 a 1 2 3 255\n1 b 1 2 3 255\n").find("value 1 listed twice"),
            std::string::npos);
  EXPECT_TRUE(repose::parseColorTable("# only a comment\n\n", "empty").empty());
  EXPECT_THROW(repose::readColorTable((dir.path() / "missing.txt").string()), repose::Error);

  // The environment names the table.
  ::setenv("REPOSE_COLOR_TABLE", path.c_str(), 1);
  repose::useReferenceColorsFromEnvironment();
  EXPECT_DOUBLE_EQ(repose::LabelTable::defaultColor(5, "liver")[1], 20 / 255.0);
  ::setenv("REPOSE_COLOR_TABLE", (dir.path() / "missing.txt").c_str(), 1);
  repose::useReferenceColorsFromEnvironment();
  try {
    repose::LabelTable::defaultColor(5, "liver");
    ADD_FAILURE() << "an unreadable REPOSE_COLOR_TABLE was ignored";
  } catch (const repose::Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.txt: cannot open (REPOSE_COLOR_TABLE)"),
              std::string::npos)
        << e.what();
  }
  // Set but empty: no table, whatever Slicer this machine has.
  ::setenv("REPOSE_COLOR_TABLE", "", 1);
  repose::useReferenceColorsFromEnvironment();
  EXPECT_EQ(repose::anatomyColor("liver", 5), rulesLiver);
  ::unsetenv("REPOSE_COLOR_TABLE");
  repose::useReferenceColorsFromEnvironment();
}

namespace {

// Sets an environment variable for a scope, then puts it back as it was.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value)
      ::setenv(name, value->c_str(), 1);
    else
      ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void writeTable(const std::filesystem::path& file, int green) {
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file) << "# a Slicer colour table (made up for the test)\n0 Background 0 0 0 0\n"
                      << "1 liver 10 " << green << " 30 255\n";
}

}  // namespace

// With no REPOSE_COLOR_TABLE, a Slicer installation's own GenericAnatomyColors.txt gives the
// colours: the installation that launched us (SLICER_HOME), else the Slicer on the PATH, else one
// in the usual places; its newest share/Slicer-X.Y (5.10 after 5.9, as numbers); a macOS bundle's
// Contents too. No Slicer found: the rules.
TEST(AnatomyColors, SlicersOwnTableIsFoundInItsInstallation) {
  namespace fs = std::filesystem;
  repose::test::ScratchDir dir;
  const fs::path home = dir.path() / "Slicer-5.10.0-linux-amd64";
  writeTable(home / "share/Slicer-5.9/ColorFiles/GenericAnatomyColors.txt", 59);
  writeTable(home / "share/Slicer-5.10/ColorFiles/GenericAnatomyColors.txt", 60);
  const std::string homeText = home.string(), empty;
  const ScopedEnv noTable("REPOSE_COLOR_TABLE", nullptr), slicer("SLICER_HOME", &homeText);
  // Nothing of this machine's: no Slicer on the PATH, a home without one.
  const std::string nowhere = (dir.path() / "nowhere").string();
  const ScopedEnv path("PATH", &nowhere), user("HOME", &nowhere);
  EXPECT_EQ(repose::findSlicerColorTable(),
            (home / "share/Slicer-5.10/ColorFiles/GenericAnatomyColors.txt").string());
  repose::useReferenceColorsFromEnvironment();
  EXPECT_DOUBLE_EQ(repose::LabelTable::defaultColor(5, "Liver")[1], 60 / 255.0);

  // A macOS bundle on the PATH through a link to its launcher.
  const fs::path bundle = dir.path() / "Slicer.app";
  writeTable(bundle / "Contents/share/Slicer-5.8/ColorFiles/GenericAnatomyColors.txt", 58);
  fs::create_directories(bundle / "Contents/MacOS");
  std::ofstream(bundle / "Contents/MacOS/Slicer") << "";
  fs::create_directories(dir.path() / "bin");
  fs::create_symlink(bundle / "Contents/MacOS/Slicer", dir.path() / "bin/Slicer");
  const std::string bin = (dir.path() / "bin").string();
  {
    const ScopedEnv noHome("SLICER_HOME", nullptr), onPath("PATH", &bin);
    EXPECT_EQ(repose::findSlicerColorTable(),
              (bundle / "Contents/share/Slicer-5.8/ColorFiles/GenericAnatomyColors.txt").string());
  }
  // In the home folder, where the Linux tarball is often unpacked.
  {
    const std::string userHome = dir.path().string();
    const ScopedEnv noHome("SLICER_HOME", nullptr), inHome("HOME", &userHome);
    const std::string found = repose::findSlicerColorTable();
    // /opt or /usr/local may hold a newer Slicer on a developer's machine; here, ours.
    if (found.rfind("/opt", 0) != 0 && found.rfind("/usr/local", 0) != 0) {
      EXPECT_EQ(found, (home / "share/Slicer-5.10/ColorFiles/GenericAnatomyColors.txt").string());
    }
  }
  // A table that does not exist in the installation: nothing found.
  EXPECT_EQ(repose::findSlicerColorTable("NoSuchTable.txt"), "");
  repose::setReferenceColors({});
  repose::useReferenceColorsFromEnvironment();
}

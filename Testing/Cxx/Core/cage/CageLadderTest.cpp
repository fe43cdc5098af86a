// The cage ladder: the settings tried in their documented order, a body whose asked cage fails
// its checks rigged with the next setting that passes (and the choice recorded), one line naming
// every setting tried when none passes, and other errors said at once.
#include "repose/cage/CageLadder.h"
#include "repose/phantom/Phantom.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace repose;

TEST(CageLadder, MoreVerticesFirstThenASmallerThenALargerDilation) {
  const std::vector<CageSetting> ladder = cageLadder({300, 10});
  const std::vector<CageSetting> expected = {{300, 10}, {600, 10}, {1000, 10}, {2000, 10},
                                             {300, 6},  {600, 6},  {300, 15},  {600, 15}};
  ASSERT_EQ(ladder.size(), expected.size());
  for (std::size_t i = 0; i < ladder.size(); ++i) {
    EXPECT_EQ(ladder[i].vertices, expected[i].vertices) << i;
    EXPECT_DOUBLE_EQ(ladder[i].dilateMm, expected[i].dilateMm) << i;
  }
  // Any asked setting: first itself, no setting twice, every one within buildCage's bounds.
  for (const CageSetting asked :
       {CageSetting{50, 4}, CageSetting{1200, 10}, CageSetting{2000, 3}, CageSetting{700, 12.5}}) {
    const std::vector<CageSetting> l = cageLadder(asked);
    ASSERT_FALSE(l.empty());
    EXPECT_TRUE(l.front() == asked);
    for (std::size_t i = 0; i < l.size(); ++i) {
      EXPECT_GE(l[i].vertices, 50);
      EXPECT_LE(l[i].vertices, 2000);
      EXPECT_GT(l[i].dilateMm, 0);
      for (std::size_t j = 0; j < i; ++j) EXPECT_FALSE(l[i] == l[j]);
    }
  }
}

TEST(CageLadder, TheChoiceSurvivesItsJson) {
  CageChoice c;
  c.asked = {300, 10};
  c.used = {1000, 10};
  c.tried = {{{300, 10}, "self-intersecting"},
             {{600, 10}, "not manifold, self-intersecting"},
             {{1000, 10}, ""}};
  const CageChoice back = CageChoice::fromJson(c.json());
  EXPECT_TRUE(back.asked == c.asked);
  EXPECT_TRUE(back.used == c.used);
  EXPECT_TRUE(back.fallback());
  ASSERT_EQ(back.tried.size(), 3u);
  EXPECT_EQ(back.tried[1].failure, "not manifold, self-intersecting");
  EXPECT_EQ(back.tried[2].failure, "");
  EXPECT_THROW(CageChoice::fromJson("{\"asked\": 3}"), Error);
  // A cage of a known setting, nothing else tried.
  const CageChoice given = CageChoice::given({450, 8});
  EXPECT_FALSE(given.fallback());
  EXPECT_TRUE(given.used == (CageSetting{450, 8}));
  ASSERT_EQ(given.tried.size(), 1u);
  EXPECT_EQ(given.tried[0].failure, "");
}

namespace {

const Volume& phantomParts() {
  static const Volume parts = [] {
    PhantomOptions o;
    o.voxelMm = 6;
    return Phantom(o).makeVolumes().second;
  }();
  return parts;
}

}  // namespace

// A cage that fails its checks at the first settings (here on cue, as a real body's thin contact
// on thick slices fails: the automatic cage of 300 vertices self-intersecting) is built at the
// next setting of the ladder that passes, and the choice says what was asked, used and tried.
TEST(CageLadder, AFailedCageIsBuiltAgainWithTheNextSettingThatPasses) {
  std::vector<CageSetting> seen;
  const CageBuildFn failingTwice = [&](const Volume& parts, const CageOptions& o) {
    seen.push_back({o.targetVertices, o.dilateMm});
    if (seen.size() <= 2) throw CageCheckError("the cage failed its checks", "self-intersecting");
    return buildCage(parts, o);
  };
  CageOptions asked;
  asked.targetVertices = 120;
  CageChoice choice;
  const Cage cage = buildCageTrying(phantomParts(), asked, &choice, failingTwice);
  EXPECT_TRUE(cage.report.valid());
  ASSERT_EQ(seen.size(), 3u);
  const std::vector<CageSetting> ladder = cageLadder({120, 10});
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_TRUE(seen[i] == ladder[i]) << i;
  EXPECT_TRUE(choice.asked == (CageSetting{120, 10}));
  EXPECT_TRUE(choice.used == ladder[2]);
  EXPECT_TRUE(choice.fallback());
  ASSERT_EQ(choice.tried.size(), 3u);
  EXPECT_EQ(choice.tried[0].failure, "self-intersecting");
  EXPECT_EQ(choice.tried[2].failure, "");
  EXPECT_NEAR(cage.report.vertices, ladder[2].vertices, 0.15 * ladder[2].vertices);

  // The asked setting that passes is kept, with nothing else tried.
  CageChoice plain;
  buildCageTrying(phantomParts(), asked, &plain);
  EXPECT_FALSE(plain.fallback());
  EXPECT_EQ(plain.tried.size(), 1u);
}

TEST(CageLadder, NoSettingPassingIsOneLineListingEveryTryAndOtherErrorsComeAtOnce) {
  int calls = 0;
  const CageBuildFn neverPasses = [&](const Volume&, const CageOptions&) -> Cage {
    ++calls;
    throw CageCheckError("the cage failed its checks", "self-intersecting");
  };
  try {
    buildCageTrying(phantomParts(), {}, nullptr, neverPasses);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    for (const CageSetting& s : cageLadder({300, 10}))
      EXPECT_NE(m.find(describeCageSetting(s.vertices, s.dilateMm)), std::string::npos)
          << describeCageSetting(s.vertices, s.dilateMm) << " not in: " << m;
  }
  EXPECT_EQ(calls, int(cageLadder({300, 10}).size()));
  // An empty map is no matter of settings: said at once, by buildCage itself.
  Volume empty(VolumeGeometry::make({20, 20, 20}, {2, 2, 2}, {0, 0, 0}), ScalarType::UInt8);
  try {
    buildCageTrying(empty, {});
    FAIL() << "no error";
  } catch (const CageCheckError&) {
    FAIL() << "an empty map is not a failed check";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("every setting"), std::string::npos) << e.what();
  }
}

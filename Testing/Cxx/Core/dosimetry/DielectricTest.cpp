// The tissues' dielectric model and which tissue each label is: the Cole-Cole values against
// figures others computed from Gabriel's parameters (the IT'IS Foundation's database v5 at 450,
// 835 and 2450 MHz; an IFAC-derived table from 10 kHz to 1 MHz), and the name rules against every
// name of the three built-in label conventions.
#include "TestPaths.h"

#include "repose/dosimetry/ColeCole.h"
#include "repose/dosimetry/LabelTissues.h"
#include "repose/util/Error.h"
#include "repose/volume/TissueTable.h"
#include "rig/Icrp110Organs.h"

#include <gtest/gtest.h>

#include <fstream>
#include <set>

using namespace repose;

namespace {

struct Reference {
  const char* tissue;
  double hz, epsR, sigma;
};

const ColeColeTissue& tissue(const char* name) {
  const ColeColeTissue* t = findGabrielTissue(name);
  if (!t) throw std::runtime_error(std::string("no tissue ") + name);
  return *t;
}

}  // namespace

// Values of the IT'IS Foundation tissue database v5 (which stores Gabriel's parameters), as
// computed and published in github.com/rwydaegh/goliat data/material_properties_cache.json;
// printed to 4-6 significant digits, so compared to 5e-5 relative.
TEST(ColeCole, MatchesTheItisDatabaseAtThreeFrequencies) {
  const Reference refs[] = {
      {"Muscle", 450e6, 56.7544, 0.80928},
      {"Muscle", 835e6, 55.1924, 0.92122},
      {"Muscle", 2450e6, 52.7295, 1.73879},
      {"Fat (Not Infiltrated)", 450e6, 5.5606, 0.04194},
      {"Fat (Not Infiltrated)", 2450e6, 5.2801, 0.10452},
      {"Fat (Average Infiltrated)", 835e6, 11.3612, 0.10475},
      {"Blood", 450e6, 63.6749, 1.36638},
      {"Blood", 2450e6, 58.2636, 2.54485},
      {"Bone (Cortical)", 835e6, 12.5166, 0.13564},
      {"Bone (Cortical)", 2450e6, 11.3809, 0.39432},
      {"Skin (Dry)", 450e6, 45.7528, 0.70882},
      {"Skin (Dry)", 2450e6, 38.0066, 1.46404},
      {"Brain (Grey Matter)", 835e6, 53.0564, 0.91497},
      {"Brain (White Matter)", 2450e6, 36.1666, 1.21499},
      {"Cerebro Spinal Fluid", 450e6, 70.4812, 2.26426},
  };
  for (const Reference& r : refs) {
    const DielectricValues v = dielectricAt(tissue(r.tissue), r.hz);
    EXPECT_NEAR(v.relativePermittivity, r.epsR, 5e-5 * r.epsR) << r.tissue << " " << r.hz;
    EXPECT_NEAR(v.conductivity, r.sigma, 5e-5 * r.sigma + 5e-6) << r.tissue << " " << r.hz;
  }
}

// The low-frequency dispersions (alpha, beta) that the microwave figures barely see: IFAC-style
// values of BioMedical Engineering OnLine (2018), doi:10.1186/s12938-018-0473-9, Table 3, which
// agree with Gabriel's parameters; conductivities printed to 1e-4 S/m.
TEST(ColeCole, MatchesIfacValuesAtKilohertzFrequencies) {
  const Reference refs[] = {
      {"Skin (Dry)", 10e3, 1133.6, 0.00020},
      {"Skin (Dry)", 1e6, 990.76, 0.0132},
      {"Skin (Wet)", 10e3, 29010, 0.0029},
      {"Skin (Wet)", 1e6, 1832.8, 0.2214},
      {"Fat (Not Infiltrated)", 100e3, 92.885, 0.0244},
      {"Muscle", 10e3, 25909, 0.3408},
      {"Muscle", 1e6, 1836.4, 0.5027},
      {"Bone (Cortical)", 100e3, 227.64, 0.0208},
  };
  for (const Reference& r : refs) {
    const DielectricValues v = dielectricAt(tissue(r.tissue), r.hz);
    EXPECT_NEAR(v.relativePermittivity, r.epsR, 2e-4 * r.epsR) << r.tissue << " " << r.hz;
    EXPECT_NEAR(v.conductivity, r.sigma, 3e-3 * r.sigma + 5e-5) << r.tissue << " " << r.hz;
  }
}

TEST(ColeCole, TheTableHasGabrielsFortyFourTissuesAndAir) {
  EXPECT_EQ(gabrielTissues().size(), 45u);
  const DielectricValues air = dielectricAt(tissue("Air"), 1e9);
  EXPECT_DOUBLE_EQ(air.relativePermittivity, 1.0);
  EXPECT_DOUBLE_EQ(air.conductivity, 0.0);
  // Physical properties at every tissue and decade: permittivity falls and conductivity rises
  // with frequency (Kramers-Kronig for passive media), and both stay positive.
  for (const ColeColeTissue& t : gabrielTissues()) {
    double lastEps = 1e300, lastSigma = -1;
    for (double hz = 10; hz <= 20e9; hz *= 10) {
      const DielectricValues v = dielectricAt(t, hz);
      EXPECT_GE(v.relativePermittivity, 1.0) << t.name << " " << hz;
      EXPECT_LE(v.relativePermittivity, lastEps * (1 + 1e-12)) << t.name << " " << hz;
      EXPECT_GE(v.conductivity, lastSigma - 1e-12) << t.name << " " << hz;
      lastEps = v.relativePermittivity;
      lastSigma = v.conductivity;
    }
  }
  EXPECT_EQ(findGabrielTissue("muscle"), findGabrielTissue("Muscle"));
  EXPECT_EQ(findGabrielTissue("Bone"), nullptr);
}

TEST(ColeCole, FrequenciesAreReadWithTheirUnitsAndBounded) {
  EXPECT_DOUBLE_EQ(parseFrequencyHz("900MHz"), 900e6);
  EXPECT_DOUBLE_EQ(parseFrequencyHz("2.45 GHz"), 2.45e9);
  EXPECT_DOUBLE_EQ(parseFrequencyHz("10kHz"), 10e3);
  EXPECT_DOUBLE_EQ(parseFrequencyHz("64e6"), 64e6);
  EXPECT_DOUBLE_EQ(parseFrequencyHz("10Hz"), 10.0);
  for (const char* bad : {"", "fast", "-900MHz", "900 MHz extra", "30GHz", "1Hz", "nanHz"})
    EXPECT_THROW(parseFrequencyHz(bad), Error) << bad;
}

TEST(ColeCole, AMalformedTableNamesItsLine) {
  const std::string header =
      "tissue,ef,sigma_S_m,del1,tau1_ps,alf1,del2,tau2_ns,alf2,del3,tau3_us,alf3,del4,tau4_ms,"
      "alf4\n";
  try {
    parseColeColeTable(header + "# c\nX,4,0.2,50,7,0.1,7000,353,0.1,1e6,318,0.1,2e7,2,1.5\n",
                       "t.csv");
    FAIL() << "an alpha of 1.5 was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("t.csv:3:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parseColeColeTable(header + "X,4,0.2\n", "t.csv"), Error);
  EXPECT_THROW(parseColeColeTable("tissue,ef\n", "t.csv"), Error);
}

TEST(LabelTissues, GlobsMatchWholeNames) {
  EXPECT_TRUE(globMatches("*cortical*", "humeri, upper half, cortical"));
  EXPECT_TRUE(globMatches("rib *", "rib left 3"));
  EXPECT_FALSE(globMatches("rib *", "ribs"));
  EXPECT_TRUE(globMatches("a?c", "abc"));
  EXPECT_FALSE(globMatches("liver", "liver tumour"));
  EXPECT_TRUE(globMatches("*", ""));
}

// Every name of the three conventions gets a tissue, and the ones that matter for dosimetry
// get the right one.
TEST(LabelTissues, EveryNameOfTheBuiltInConventionsHasATissue) {
  std::set<std::string> names;
  for (const auto& organ : rig::kIcrp110Organs) names.insert(organ.name);
  for (const auto& [label, t] : phantomTissueTable()) names.insert(t.name);
  for (const char* tsv :
       {"totalsegmentator/example_seg_labels.tsv", "totalsegmentator/example_seg_mr_labels.tsv"}) {
    std::ifstream in(test::dataPath(tsv));
    ASSERT_TRUE(in) << tsv;
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      const auto a = line.find('\t'), b = line.find('\t', a + 1);
      names.insert(line.substr(a + 1, b - a - 1));
    }
  }
  // TotalSegmentator v2's classes beyond the example's (appendicular bones, muscles of the limbs).
  for (const char* n : {"radius_left",
                        "ulna_right",
                        "carpal_left",
                        "metacarpal_right",
                        "phalanges_hand_left",
                        "tibia_left",
                        "fibula_right",
                        "patella_left",
                        "tarsal_right",
                        "metatarsal_left",
                        "phalanges_feet_right",
                        "skull",
                        "sternum",
                        "costal_cartilages",
                        "kidney_cyst_left",
                        "quadriceps_femoris_left",
                        "sartorius_right",
                        "thigh_medial_compartment_left",
                        "subcutaneous_fat",
                        "skeletal_muscle",
                        "torso_fat"})
    names.insert(n);
  EXPECT_GE(names.size(), 290u);  // 141 ICRP + 36 phantom + the TotalSegmentator classes
  std::vector<std::string> unknown;
  for (const std::string& n : names)
    if (tissueForName(n).empty()) unknown.push_back(n);
  EXPECT_TRUE(unknown.empty()) << unknown.size() << " names without a tissue, first: "
                               << (unknown.empty() ? "" : unknown.front());

  const std::pair<const char*, const char*> expected[] = {
      {"Humeri, upper half, cortical", "Bone (Cortical)"},
      {"Femora, lower half, spongiosa", "Bone (Cancellous)"},
      {"Femora, upper half, medullary cavity", "Bone Marrow (Not Infiltrated)"},
      {"Lung, left, blood", "Blood"},
      {"Lung, right, tissue", "Lung (Inflated)"},
      {"Heart contents (blood)", "Blood"},
      {"Heart wall", "Heart"},
      {"Residual tissue, arms", "Fat (Average Infiltrated)"},
      {"Skin, trunk", "Skin (Dry)"},
      {"Oral mucosa, tongue", "Skin (Wet)"},
      {"Eye lense, left", "Lens Cortex"},
      {"Eye bulb, right", "Vitreous Humor"},
      {"Gall bladder contents", "Gall Bladder Bile"},
      {"Air inside body", "Air"},
      {"Spinal cord", "Nerve"},
      {"Breast, left, adipose tissue", "Breast fat"},
      {"Cartilage, legs", "Cartilage"},
      {"humerus_left", "Bone (Cortical)"},
      {"vertebrae_L3", "Bone (Cortical)"},
      {"rib_right_11", "Bone (Cortical)"},
      {"gluteus_maximus_left", "Muscle"},
      {"aorta", "Blood"},
      {"portal_vein_and_splenic_vein", "Blood"},
      {"lung_upper_lobe_left", "Lung (Inflated)"},
      {"brain", "Brain (Grey Matter)"},
      {"subcutaneous_fat", "Fat (Average Infiltrated)"},
      {"humerus_marrow", "Bone (Cancellous)"},
      {"radius_ulna", "Bone (Cortical)"},
      {"blood_vessels_arms", "Blood"},
      {"eye", "Vitreous Humor"},
      {"urinary_bladder", "Bladder"},
      {"small_bowel", "Small Intestine"},
      {"kidney_left", "Kidney"},
  };
  for (const auto& [name, tissueName] : expected)
    EXPECT_EQ(tissueForName(name), tissueName) << name;
  EXPECT_EQ(tissueForName("Humeri; upper half; cortical"), "Bone (Cortical)");  // tissues.csv form
  EXPECT_EQ(tissueForName("tumour"), "");
}

TEST(LabelTissues, AUserMapComesFirstAndUnknownLabelsAreListed) {
  test::ScratchDir dir;
  std::map<int, LabelTissue> labels;
  labels[1].name = "liver";
  labels[2].name = "tumour";
  labels[3].name = "";
  try {
    assignTissues(labels, {});
    FAIL() << "labels without a tissue were accepted";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("2 label(s): 2 (tumour), 3"), std::string::npos) << m;
    EXPECT_NE(m.find("--default-tissue"), std::string::npos) << m;
  }
  const std::string csv = dir.file("map.csv");
  std::ofstream(csv) << "# my labels\nlabel,tissue\n2,Muscle\n1,spleen\n";
  assignTissues(labels, {csv, "Fat (Not Infiltrated)"});
  EXPECT_EQ(labels[1].tissue, "Spleen");  // the user's map wins over the name rule, any case
  EXPECT_EQ(labels[1].rule, csv);
  EXPECT_EQ(labels[2].tissue, "Muscle");
  EXPECT_EQ(labels[3].tissue, "Fat (Not Infiltrated)");
  EXPECT_EQ(labels[3].rule, "--default-tissue");

  std::ofstream(csv) << "label,tissue\n2,Tumour tissue\n";
  try {
    assignTissues(labels, {csv, ""});
    FAIL() << "an unknown tissue was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(csv + ":2: unknown tissue \"Tumour tissue\""),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(assignTissues(labels, {"", "Granite"}), Error);
}

// The gyro writer (io/gyro_toml.h): load(save(g)) is g, field by field and bit for bit, for the
// bundled and test gyro files, for every catalog effect applied in memory, and for any double;
// the saved file saves again to the same bytes and simulates the same trace for a seed. No
// tolerance anywhere: the contract is exact.

#include <gtest/gtest.h>

#include <algorithm>
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/uniform_int_distribution.hpp>
#include <boost/random/uniform_real_distribution.hpp>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "io/gyro_file.h"
#include "io/gyro_toml.h"
#include "sim/gyro_compare.h"
#include "sim/simulator.h"
#include "tests/sim/test_helpers.h"

namespace rlg::io {

using sim::ApplyEffect;
using sim::BiasParams;
using sim::EffectNames;
using sim::EffectSpec;
using sim::GyroConfig;
using sim::GyroDifference;
using sim::GyroNoiseParams;
using sim::Profile;
using sim::Run;
using sim::RunSpec;
using sim::SimulateRun;
using sim::kAmbient;

namespace {

std::string Saved(const GyroConfig& g) {
  std::ostringstream out;
  WriteGyroToml(g, out);
  return out.str();
}

/// Four hours at 10 s: soaked at 20 °C, up to 60 °C and back, with stepped power on every
/// source driven by data. It heats and cools every node (rates, hysteresis, lag, drift) and
/// moves the block by 40 °C (mode hops).
RunSpec RiseFall(const GyroConfig& g) {
  RunSpec r;
  r.id = "rise-fall";
  r.duration_s = 14400;
  r.sample_period_s = 10;
  r.ambient = Profile::Table({{0, 20}, {1800, 20}, {4200, 60}, {7200, 60}, {9600, 20}});
  for (const auto& s : g.network.sources)
    if (s.driven_by_data) r.power.emplace(s.name, Profile::Steps(0.5, {{3600, 1.0}, {9000, 0.0}}));
  return r;
}

/// EXPECT the two runs hold the same columns with the same bits.
void ExpectSameRun(const Run& a, const Run& b) {
  ASSERT_EQ(a.names, b.names);
  ASSERT_EQ(a.t_s, b.t_s);
  for (size_t c = 0; c < a.columns.size(); ++c) {
    ASSERT_EQ(a.columns[c].size(), b.columns[c].size());
    EXPECT_EQ(std::memcmp(a.columns[c].data(), b.columns[c].data(), a.columns[c].size() * sizeof(double)), 0)
        << "column " << a.names[c] << " differs";
  }
}

/// Saves into a fresh directory per test (removed after it) and reads back.
class GyroTomlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("rlg_gyro_toml_") + info->test_suite_name() + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');  // parametrized tests are named Suite/Test/Param
    dir_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  GyroConfig Reloaded(const GyroConfig& g) {
    const std::string path = (dir_ / "gyro.toml").string();
    SaveGyro(g, path);
    return LoadGyro(path);
  }
  void ExpectReadsBack(const GyroConfig& g) { EXPECT_EQ(GyroDifference(Reloaded(g), g), ""); }
  void ExpectResavesByteForByte(const GyroConfig& g) { EXPECT_EQ(Saved(Reloaded(g)), Saved(g)); }
  void ExpectSameTrace(const GyroConfig& g) {
    const GyroConfig back = Reloaded(g);
    ExpectSameRun(SimulateRun(back, RiseFall(g), 7, 0), SimulateRun(g, RiseFall(g), 7, 0));
  }
  std::filesystem::path dir_;
};

// ---- gyro files ------------------------------------------------------------------------------

std::vector<std::string> GyroFiles() {
  std::vector<std::string> files = {"scenarios/gyros/default.toml", "scenarios/gyros/tclab-nominal.toml"};
  std::vector<std::string> test_files;
  for (const auto& entry : std::filesystem::directory_iterator(test::SourcePath("tests/data/gyros")))
    if (entry.path().extension() == ".toml") test_files.push_back("tests/data/gyros/" + entry.path().filename().string());
  std::sort(test_files.begin(), test_files.end());
  files.insert(files.end(), test_files.begin(), test_files.end());
  return files;
}

class GyroFile : public GyroTomlTest, public ::testing::WithParamInterface<std::string> {
 protected:
  GyroConfig Loaded() const { return LoadGyro(test::SourcePath(GetParam())); }
};

TEST_P(GyroFile, ReadsBackFieldByField) { ExpectReadsBack(Loaded()); }
TEST_P(GyroFile, ResavesByteForByte) { ExpectResavesByteForByte(Loaded()); }
TEST_P(GyroFile, SimulatesTheSameTraceBitForBit) { ExpectSameTrace(Loaded()); }

std::string FileTestName(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = std::filesystem::path(info.param).stem().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}
INSTANTIATE_TEST_SUITE_P(Bundled, GyroFile, ::testing::ValuesIn(GyroFiles()), FileTestName);

TEST(GyroFiles, TheListHoldsTheBundledGyrosAndEveryTestGyro) {
  // Guards the directory listing above: the two bundled files plus at least the two test gyros.
  EXPECT_GE(GyroFiles().size(), 4u);
}

// ---- catalog effects applied in memory --------------------------------------------------------

/// A valid target and parameters on the default gyro for each catalog effect, every optional
/// parameter given a value other than its default so that writing it is tested.
EffectSpec CaseFor(const std::string& name) {
  static const std::vector<EffectSpec> cases = {
      {"thermal.missing_mass", "block-cabinet", {{"heat_capacity_J_per_K", 300.0}, {"conductance_W_per_K", 0.5}}},
      {"thermal.missing_link", "anode-ambient", {{"conductance_W_per_K", 0.01}}},
      {"thermal.power_drift", "cathode", {{"g_per_C", 0.01}, {"reference_C", 0.0}}},
      {"thermal.radiation", "block-ambient", {{"emissivity_area_m2", 0.02}}},
      {"sensor.lag", "T1", {{"time_constant_s", 120.0}}},
      {"sensor.offset", "T3", {{"offset_C", 0.05}}},
      {"bias.temperature_rate", "T1", {{"k_dph_per_C_per_min", 0.04}}},
      {"bias.gradient", "anode-cabinet", {{"k_dph_per_C", 0.02}}},
      {"bias.hysteresis", "block", {{"k_heating_dph_per_C", 0.01}, {"k_cooling_dph_per_C", 0.005}}},
      {"bias.play", "block", {{"k_dph_per_C", 0.02}, {"width_C", 1.5}, {"reference_C", 25.0}}},
      {"bias.mode_hop", "block", {{"step_dph", 0.05}, {"mode_spacing_C", 10.0}, {"range_modes", 0.7}}},
  };
  for (const auto& c : cases)
    if (c.name == name) return c;
  return {name, "", {}};  // no case: CatalogEffect.EveryNameHasACase fails
}

GyroConfig DefaultWith(const std::vector<EffectSpec>& effects) {
  GyroConfig g = LoadGyro(test::SourcePath("scenarios/gyros/default.toml"));
  for (const auto& e : effects) ApplyEffect(e, g);
  return g;
}

class CatalogEffect : public GyroTomlTest, public ::testing::WithParamInterface<std::string> {
 protected:
  GyroConfig Gyro() const { return DefaultWith({CaseFor(GetParam())}); }
};

TEST_P(CatalogEffect, HasACase) { EXPECT_FALSE(CaseFor(GetParam()).target.empty()) << GetParam(); }
TEST_P(CatalogEffect, ReadsBackFieldByField) { ExpectReadsBack(Gyro()); }
TEST_P(CatalogEffect, ResavesByteForByte) { ExpectResavesByteForByte(Gyro()); }
TEST_P(CatalogEffect, SavedGyroSimulatesTheSameTraceAsTheGyroInMemoryBitForBit) { ExpectSameTrace(Gyro()); }
TEST_P(CatalogEffect, IsWrittenAsAnEffectEntryOnTheGyroWithoutIt) {
  // The plain keys are the default gyro's; the effect follows by name.
  const std::string with = Saved(Gyro()), without = Saved(DefaultWith({}));
  const std::string entry = "\n[[effects]]\nname = \"" + GetParam() + "\"";
  ASSERT_NE(with.find(entry), std::string::npos) << with;
  const auto body = [](const std::string& text) { return text.substr(text.find("\nname = ")); };
  EXPECT_EQ(body(with).substr(0, body(with).find("\n[[effects]]")), body(without)) << with;
}

std::string EffectTestName(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& c : name)
    if (c == '.') c = '_';
  return name;
}
INSTANTIATE_TEST_SUITE_P(Catalog, CatalogEffect, ::testing::ValuesIn(EffectNames()), EffectTestName);

/// Every effect at once, with what stacking does: a second offset on the same channel (they add
/// up), a second lag on T1 (a stage in series after the first), and effects on a node a
/// missing_mass added.
GyroConfig Stacked() {
  std::vector<EffectSpec> effects;
  for (const auto& name : EffectNames()) effects.push_back(CaseFor(name));
  effects.push_back({"sensor.offset", "T3", {{"offset_C", -0.0125}}});
  effects.push_back({"sensor.lag", "T1", {{"time_constant_s", 30.0}}});
  effects.push_back({"bias.temperature_rate", "block_cabinet_mass", {{"k_dph_per_C_per_min", -0.02}}});
  effects.push_back({"thermal.radiation", "block_cabinet_mass-ambient", {{"emissivity_area_m2", 0.01}}});
  return DefaultWith(effects);
}

TEST_F(GyroTomlTest, EveryEffectStackedReadsBackFieldByField) { ExpectReadsBack(Stacked()); }
TEST_F(GyroTomlTest, EveryEffectStackedResavesByteForByte) { ExpectResavesByteForByte(Stacked()); }
TEST_F(GyroTomlTest, EveryEffectStackedSimulatesTheSameTraceBitForBit) { ExpectSameTrace(Stacked()); }

TEST_F(GyroTomlTest, EffectsOnAGyroFromAFileWithEffectsReadBack) {
  // Another network: effects on the seven-node gyro's named channel T_mirror, its mirror node
  // and one of its two anodes.
  GyroConfig g = LoadGyro(test::SourcePath("tests/data/gyros/seven-node.toml"));
  ApplyEffect({"sensor.lag", "T_mirror", {{"time_constant_s", 5.0}}}, g);
  ApplyEffect({"thermal.missing_mass", "mirror-block", {{"heat_capacity_J_per_K", 2.0}, {"conductance_W_per_K", 0.1}}}, g);
  ApplyEffect({"thermal.power_drift", "anode2", {{"g_per_C", -0.002}}}, g);
  ExpectReadsBack(g);
  ExpectSameTrace(g);
}

// ---- plain fields and numbers -----------------------------------------------------------------

TEST_F(GyroTomlTest, EveryPlainFieldWithAValueOtherThanItsDefaultReadsBack) {
  GyroConfig g = DefaultWith({});
  g.name = "every field";
  g.network.radiation.push_back({2, kAmbient, 0.015});
  g.network.radiation.push_back({0, 3, 0.001});
  g.network.sources[1].driven_by_data = true;
  g.sensors[1].noise = {0.0, 0.0};
  BiasParams& b = g.bias;
  b.reference_C = 25.5;
  b.langmuir_gradients.push_back({1, 3, -0.05});
  b.path_length_m = 0.28;
  b.cte_per_C = 3e-8;
  b.wavelength_m = 543.5e-9;
  GyroNoiseParams& n = g.noise;
  n.instability_model = GyroNoiseParams::InstabilityModel::kGaussMarkov;
  n.gauss_markov_time_s = 1800.0;
  n.rrw_deg_per_h_per_sqrt_h = 0.0002;
  n.quantization_arcsec = 0.0015;
  n.turn_on_sigma_dph = 0.003;
  g.calibration_uncertainty = 0.2;
  ExpectReadsBack(g);
  ExpectResavesByteForByte(g);
  ExpectSameTrace(g);
}

TEST_F(GyroTomlTest, NamesWithQuotesBackslashesControlCharactersAndUnicodeReadBack) {
  GyroConfig g = DefaultWith({});
  g.name = "gyro \"A\" \\ \t\n\x7f fünf";
  g.network.nodes[0].name = "an ode\"\\";  // sorted before "block": the shares stay in the loader's order
  g.network.nodes[2].name = "blöck";
  ExpectReadsBack(g);
}

/// `count` doubles spread over every binade of [-limit, limit] down to the subnormals, with
/// random mantissas, after the awkward ones: both zeros, whole numbers, 0.1, 1/3, 1e-9, the
/// smallest double, values beyond the limit (clamped to it).
std::vector<double> AwkwardDoubles(size_t count, double limit, uint64_t seed) {
  std::vector<double> v = {0.0, -0.0, 1.0, -3.0, 0.1, 0.2 + 0.1, 1.0 / 3.0, 1e-9, 632.8e-9, 5e-8, 1e7 / 3.0, 4.9e-324,
                           DBL_MIN, std::nextafter(DBL_MIN, 0.0), std::nextafter(1.0, 2.0), 9007199254740993.0};
  boost::random::mt19937_64 rng(seed);
  boost::random::uniform_int_distribution<int> exponent(-1074, static_cast<int>(std::ilogb(limit)));
  boost::random::uniform_real_distribution<double> mantissa(1.0, 2.0);
  while (v.size() < count) {
    const double x = std::ldexp(mantissa(rng), exponent(rng)) * (v.size() % 2 ? -1.0 : 1.0);
    v.push_back(std::abs(x) <= limit ? x : std::round(x / limit));  // a whole number now and then
  }
  for (double& x : v) x = std::clamp(x, -limit, limit);
  return v;
}

TEST_F(GyroTomlTest, EveryDoubleReadsBackBitForBit) {
  // Effect parameters take any double in their range: 2,000 offsets in +-50 °C, each in its own
  // sensor.offset entry on one channel. The bias coefficients take the same, scaled into their
  // ranges.
  const std::vector<double> offsets = AwkwardDoubles(2000, 50.0, 1);
  GyroConfig g = DefaultWith({});
  for (const double x : offsets) ApplyEffect({"sensor.offset", "T2", {{"offset_C", x}}}, g);
  const std::vector<double> coefficients = AwkwardDoubles(20, 1e7 / 230.0 / 230.0, 2);  // b2's range, the narrowest
  g.bias.b0_dph = coefficients[16];  // past the fixed awkward ones: random
  g.bias.b1_dph_per_C = coefficients[17];
  g.bias.b2_dph_per_C2 = coefficients[18];
  ExpectReadsBack(g);
}

TEST_F(GyroTomlTest, NumbersAreTheShortestDecimalThatReadsBack) {
  GyroConfig g = DefaultWith({});
  g.bias.b0_dph = 1e-9;
  g.bias.cte_per_C = 5e-8;
  g.network.nodes[0].heat_capacity_J_per_K = 250.0;
  const std::string text = Saved(g);
  EXPECT_NE(text.find("\nb0_dph = 1e-09\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\ncte_per_C = 5e-08\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nwavelength_m = 6.328e-07\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nheat_capacity_J_per_K = 250.0\n"), std::string::npos) << text;  // a float, not an integer
}

TEST_F(GyroTomlTest, FileStartsWithACommentSayingRlgthermWroteIt) {
  const std::string text = Saved(DefaultWith({}));
  EXPECT_EQ(text.rfind("# Gyro file written by rlgtherm: the gyro \"default\"", 0), 0u) << text;
}

// ---- the comparison ---------------------------------------------------------------------------

TEST(GyroDifference, NamesTheFirstDifferingFieldWithBothValues) {
  const GyroConfig a = DefaultWith({});
  GyroConfig b = a;
  EXPECT_EQ(GyroDifference(a, b), "");
  b.bias.b1_dph_per_C = std::nextafter(a.bias.b1_dph_per_C, 1.0);  // one ulp
  b.noise.arw_deg_per_sqrt_h = 0.5;
  EXPECT_EQ(GyroDifference(a, b), "bias.b1_dph_per_C: 0.006 != 0.006000000000000001");
}

TEST(GyroDifference, ComparesEffectsAndNegativeZeroBitForBit) {
  GyroConfig a = DefaultWith({{"sensor.offset", "T1", {{"offset_C", 0.0}}}});
  GyroConfig b = DefaultWith({{"sensor.offset", "T1", {{"offset_C", -0.0}}}});
  // 0 + -0 is +0: the sensors agree, the effects' parameters do not.
  EXPECT_EQ(GyroDifference(a, b), "effects[0] (sensor.offset).offset_C: 0 != -0");
}

// ---- what the format cannot say ---------------------------------------------------------------

/// The message of the std::invalid_argument WriteGyroToml throws; nothing may be written.
std::string Refusal(const GyroConfig& g) {
  std::ostringstream out;
  try {
    WriteGyroToml(g, out);
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(out.str(), "");
    return e.what();
  }
  ADD_FAILURE() << "expected std::invalid_argument";
  return "";
}

TEST(GyroTomlRefusal, SensorLagSetWithoutAnEffectIsRefused) {
  GyroConfig g = DefaultWith({});
  g.sensors[0].lag_time_constants_s = {5.0};
  EXPECT_NE(Refusal(g).find("sensors[0] (T1).lag_time_constants_s: 0 entries != 1"), std::string::npos) << Refusal(g);
}

TEST(GyroTomlRefusal, ANodeAnEffectAddedChangedAfterwardsIsRefused) {
  GyroConfig g = DefaultWith({CaseFor("thermal.missing_mass")});
  g.network.nodes.back().heat_capacity_J_per_K *= 1.01;
  EXPECT_NE(Refusal(g).find("network.nodes[4].heat_capacity_J_per_K"), std::string::npos) << Refusal(g);
}

TEST(GyroTomlRefusal, SensorsOutOfTheLoadersOrderAreRefused) {
  GyroConfig g = DefaultWith({});
  std::swap(g.sensors[0], g.sensors[1]);
  EXPECT_NE(Refusal(g).find("sensors 'T2' before 'T1'"), std::string::npos) << Refusal(g);
}

TEST(GyroTomlRefusal, SharesOutOfTheLoadersOrderAreRefused) {
  GyroConfig g = DefaultWith({});
  auto& shares = g.network.sources[0].shares;
  std::swap(shares[0], shares[1]);
  EXPECT_NE(Refusal(g).find("shares: 'anode' after 'block'"), std::string::npos) << Refusal(g);
}

TEST(GyroTomlRefusal, ALinkFromAmbientIsRefused) {
  GyroConfig g = DefaultWith({});
  g.network.links.push_back({kAmbient, 0, 0.01});
  EXPECT_NE(Refusal(g).find("links[6] starts at ambient"), std::string::npos) << Refusal(g);
}

TEST(GyroTomlRefusal, SensorLagFollowersInTheNetworkAreRefused) {
  GyroConfig g = DefaultWith({});
  g.network.followers.push_back({0, 10.0});
  EXPECT_NE(Refusal(g).find("followers"), std::string::npos) << Refusal(g);
}

TEST(GyroTomlRefusal, ANumberThatIsNotFiniteIsRefused) {
  GyroConfig g = DefaultWith({});
  g.bias.b1_dph_per_C = NAN;
  EXPECT_NE(Refusal(g).find("bias.b1_dph_per_C is nan"), std::string::npos) << Refusal(g);
}

TEST_F(GyroTomlTest, ARefusedGyroLeavesNoFile) {
  GyroConfig g = DefaultWith({});
  g.sensors[0].offset_C = 0.1;
  const std::string path = (dir_ / "gyro.toml").string();
  EXPECT_THROW(SaveGyro(g, path), std::invalid_argument);
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

}  // namespace
}  // namespace rlg::io

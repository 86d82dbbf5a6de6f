// Part-to-part spread (sim/population.h, sim/gyro_parameters.h): parameter names, the draws'
// distributions against their closed forms, correlation, reproducibility, refusals.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <toml++/toml.h>

#include "io/gyro_file.h"
#include "io/scenario_file.h"
#include "io/toml_reader.h"
#include "sim/errors.h"
#include "sim/effect_registry.h"
#include "sim/gyro.h"
#include "sim/gyro_compare.h"
#include "sim/population.h"
#include "tools/source_dir.h"

namespace rlg::sim {

using io::LoadGyro;
using io::ReadPopulation;
using io::TomlReader;

namespace {

GyroConfig Default() { return LoadGyro(rlg::tools::SourcePath("scenarios/gyros/default.toml")); }

/// The default gyro with a rate term on T1 and a play on the block, as a scenario's
/// [[effects]] would add them.
GyroConfig WithEffects() {
  GyroConfig g = Default();
  ApplyEffect({"bias.temperature_rate", "T1", {{"k_dph_per_C_per_min", 0.05}}}, g);
  ApplyEffect({"bias.play", "block", {{"k_dph_per_C", 0.02}, {"width_C", 2.0}, {"reference_C", 20.0}}}, g);
  return g;
}

PopulationSpec Spec(const std::string& toml_text) {
  const toml::table doc = toml::parse(toml_text);
  const TomlReader root(doc, "pop.toml", "");
  return ReadPopulation(root.Table("population"));
}

// Draws enough gyros that a sample moment's standard error is small against its tolerance.
constexpr int kGyros = 4000;

std::vector<double> Column(const Population& p, size_t k, int n = kGyros) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(p.Draw(7, static_cast<uint64_t>(i)).values[k]);
  return v;
}

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double Sd(const std::vector<double>& v) {
  const double m = Mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

TEST(GyroParameters, NamesFollowTheGyroFileAndPatternsCoverOneNamePart) {
  const GyroConfig g = Default();
  const auto caps = MatchParameters(g, "nodes.*.heat_capacity_J_per_K");
  ASSERT_EQ(caps.size(), 4u);
  EXPECT_EQ(caps[0].name, "nodes.anode.heat_capacity_J_per_K");
  EXPECT_EQ(caps[3].name, "nodes.cabinet.heat_capacity_J_per_K");
  EXPECT_DOUBLE_EQ(caps[2].get(g), 350.0);  // the block, as default.toml writes it
  EXPECT_EQ(MatchParameters(g, "links.cabinet-ambient.conductance_W_per_K").size(), 1u);
  EXPECT_EQ(MatchParameters(g, "bias.langmuir_gradient.anode-block.k_dph_per_C").size(), 1u);
  EXPECT_EQ(MatchParameters(g, "sensors.*.offset_C").size(), 4u);
  EXPECT_TRUE(MatchParameters(g, "nodes.*").empty());  // `*` is one name part, not the rest
  EXPECT_TRUE(MatchParameters(g, "nodes.mirror.heat_capacity_J_per_K").empty());
}

TEST(GyroParameters, EverySetterChangesWhatItsGetterReadsAndNothingElse) {
  // The default gyro, and with bias effects, whose parameters are listed too.
  for (const GyroConfig& g : {Default(), WithEffects()}) {
    const auto params = GyroParameters(g);
    for (size_t k = 0; k < params.size(); ++k) {
      GyroConfig c = g;
      const double v = params[k].get(c) * 1.5 + 0.25;
      params[k].set(c, v);
      for (size_t j = 0; j < params.size(); ++j) {
        EXPECT_EQ(params[j].get(c), j == k ? v : params[j].get(g)) << params[k].name << " moved " << params[j].name;
      }
    }
  }
}

TEST(GyroParameters, ABiasEffectsParametersAreNamedByEffectTargetAndKeyAndSetBothTermAndRecord) {
  const GyroConfig g = WithEffects();
  const auto rate = MatchParameters(g, "bias.temperature_rate.T1.k_dph_per_C_per_min");
  ASSERT_EQ(rate.size(), 1u);
  EXPECT_EQ(rate[0].get(g), 0.05);
  // Every parameter of the play but the held reference temperature; its width must be > 0.
  const auto play = MatchParameters(g, "bias.play.*.width_C");
  ASSERT_EQ(play.size(), 1u);
  EXPECT_EQ(play[0].name, "bias.play.block.width_C");
  EXPECT_EQ(play[0].lower, 0.0);
  EXPECT_TRUE(play[0].lower_open);
  EXPECT_EQ(play[0].upper, RequireEffect("bias.play").FindParameter("width_C")->file_hi);
  EXPECT_EQ(MatchParameters(g, "bias.play.block.k_dph_per_C").size(), 1u);
  EXPECT_TRUE(MatchParameters(g, "bias.play.block.reference_C").empty());
  GyroConfig c = g;
  play[0].set(c, 3.5);
  EXPECT_EQ(c.bias.play.at(0).width_C, 3.5);
  EXPECT_EQ(c.effects.at(1).parameters.at("width_C"), 3.5);  // the record a gyro file is written from
  // The gyro's other parameters are untouched (as for every parameter: the test below).
  EXPECT_EQ(c.bias.play.at(0).k_dph_per_C, 0.02);
  EXPECT_EQ(c.bias.rate_terms.at(0).k_dph_per_C_per_min, 0.05);
}

TEST(Population, EffectParametersAreDrawnWithTheirStatedSpreadAndTheSameGyroEachTime) {
  const GyroConfig g = WithEffects();
  const Population p(Spec(R"([population]
count = 4000
[[population.spread]]
parameter = "bias.temperature_rate.T1.k_dph_per_C_per_min"
distribution = "normal"
relative_sigma = 0.2
[[population.spread]]
parameter = "bias.play.block.k_dph_per_C"
distribution = "normal"
sigma = 0.005
[[population.spread]]
parameter = "bias.play.block.width_C"
distribution = "lognormal"
relative_sigma = 0.1
)"),
                     g);
  ASSERT_EQ(p.parameters(), (std::vector<std::string>{"bias.temperature_rate.T1.k_dph_per_C_per_min",
                                                      "bias.play.block.k_dph_per_C", "bias.play.block.width_C"}));
  const double n = kGyros;
  // 4 standard errors of each sample statistic, as for the gyro's own parameters above (a 6e-5
  // chance each for a correct draw; the seeds are fixed, so the test is deterministic): the
  // mean's is sd / sqrt(n), a normal sample sd's sd / sqrt(2 n).
  const auto rate = Column(p, 0);
  EXPECT_NEAR(Mean(rate), 0.05, 4 * 0.01 / std::sqrt(n));
  EXPECT_NEAR(Sd(rate), 0.01, 4 * 0.01 / std::sqrt(2 * n));
  const auto k = Column(p, 1);
  EXPECT_NEAR(Mean(k), 0.02, 4 * 0.005 / std::sqrt(n));
  EXPECT_NEAR(Sd(k), 0.005, 4 * 0.005 / std::sqrt(2 * n));
  std::vector<double> log_w;
  for (double w : Column(p, 2)) log_w.push_back(std::log(w / 2.0));
  EXPECT_NEAR(Mean(log_w), 0.0, 4 * 0.1 / std::sqrt(n));
  EXPECT_NEAR(Sd(log_w), 0.1, 4 * 0.1 / std::sqrt(2 * n));
  // Gyro i's draw is its seed's: the same alone or after others, in the simulated terms and in
  // the [[effects]] record alike.
  const auto alone = p.Draw(3, 17);
  for (uint64_t i = 0; i < 17; ++i) (void)p.Draw(3, i);
  const auto again = p.Draw(3, 17);
  EXPECT_EQ(alone.values, again.values);
  EXPECT_EQ(GyroDifference(alone.config, again.config), "");
  EXPECT_EQ(alone.config.bias.rate_terms.at(0).k_dph_per_C_per_min, alone.values[0]);
  EXPECT_EQ(alone.config.bias.play.at(0).k_dph_per_C, alone.values[1]);
  EXPECT_EQ(alone.config.bias.play.at(0).width_C, alone.values[2]);
  EXPECT_EQ(alone.config.effects.at(1).parameters.at("width_C"), alone.values[2]);
}

void ExpectRefused(const std::string& toml_text, const std::string& fragment, const GyroConfig& gyro = Default());

TEST(Population, AnEffectParameterDrawnOutsideItsRangeIsRefused) {
  // A normal width of 2 °C with a relative sd of 0.6 draws w <= 0 for z < -1.67 (5 % of the
  // gyros): among 200 some do.
  ExpectRefused("[population]\ncount = 200\n[[population.spread]]\nparameter = \"bias.play.block.width_C\"\n"
                "distribution = \"normal\"\nrelative_sigma = 0.6\n",
                "pop.toml:3: gyro ", WithEffects());
  ExpectRefused("[population]\ncount = 200\n[[population.spread]]\nparameter = \"bias.play.block.width_C\"\n"
                "distribution = \"normal\"\nrelative_sigma = 0.6\n",
                "draws bias.play.block.width_C = -", WithEffects());
  // Above what a gyro file may give (sim/limits.h): a width beyond the temperature span.
  ExpectRefused("[population]\ncount = 20\n[[population.spread]]\nparameter = \"bias.play.block.width_C\"\n"
                "distribution = \"uniform\"\nrange = [300, 400]\n",
                "outside its physical range (<= 230)", WithEffects());
  // An effect the gyro does not have has no parameter to spread.
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"bias.play.block.width_C\"\n"
                "distribution = \"lognormal\"\nrelative_sigma = 0.1\n",
                "pop.toml:3: [[population.spread]] parameter 'bias.play.block.width_C' names no parameter");
}

TEST(Population, GyroIIsTheSameGyroAloneOrAfterOthers) {
  const Population p(Spec(R"([population]
count = 100
[[population.spread]]
parameter = "nodes.*.heat_capacity_J_per_K"
distribution = "lognormal"
relative_sigma = 0.05
)"),
                     Default());
  const auto alone = p.Draw(1, 42);
  for (uint64_t i = 0; i < 42; ++i) (void)p.Draw(1, i);
  const auto after = p.Draw(1, 42);
  EXPECT_EQ(alone.values, after.values);
  EXPECT_EQ(alone.seed, Population::GyroSeed(1, 42));
  EXPECT_NE(p.Draw(1, 43).values, alone.values);
  EXPECT_NE(p.Draw(2, 42).values, alone.values);  // another suite seed, another gyro
  EXPECT_NE(Population::GyroSeed(1, 42), Population::GyroSeed(1, 43));
  EXPECT_THROW(p.Draw(1, 100), InputError);
}

TEST(Population, DrawsFollowTheirDistributions) {
  const GyroConfig g = Default();
  const Population p(Spec(R"([population]
count = 4000
[[population.spread]]
parameter = "nodes.block.heat_capacity_J_per_K"
distribution = "lognormal"
relative_sigma = 0.05
[[population.spread]]
parameter = "bias.b0_dph"
distribution = "normal"
sigma = 0.3
[[population.spread]]
parameter = "links.block-cabinet.conductance_W_per_K"
distribution = "normal"
relative_sigma = 0.1
[[population.spread]]
parameter = "sensors.T1.offset_C"
distribution = "uniform"
range = [-0.1, 0.3]
)"),
                     g);
  ASSERT_EQ(p.parameters().size(), 4u);
  const double n = kGyros;
  // Tolerances are 4 standard errors of the sample statistic (a 6e-5 chance each for a correct
  // draw; the seeds are fixed, so the test is deterministic).
  std::vector<double> log_ratio;
  for (double x : Column(p, 0)) log_ratio.push_back(std::log(x / 350.0));
  EXPECT_NEAR(Mean(log_ratio), 0.0, 4 * 0.05 / std::sqrt(n));
  EXPECT_NEAR(Sd(log_ratio), 0.05, 4 * 0.05 / std::sqrt(2 * n));

  const auto b0 = Column(p, 1);
  EXPECT_NEAR(Mean(b0), g.bias.b0_dph, 4 * 0.3 / std::sqrt(n));
  EXPECT_NEAR(Sd(b0), 0.3, 4 * 0.3 / std::sqrt(2 * n));

  const auto G = Column(p, 2);
  EXPECT_NEAR(Mean(G), 0.42, 4 * 0.042 / std::sqrt(n));
  EXPECT_NEAR(Sd(G), 0.042, 4 * 0.042 / std::sqrt(2 * n));

  const auto off = Column(p, 3);
  for (double x : off) {
    EXPECT_GE(x, -0.1);
    EXPECT_LE(x, 0.3);
  }
  const double width = 0.4;  // uniform: mean at the middle, sd width / sqrt(12)
  EXPECT_NEAR(Mean(off), 0.1, 4 * width / std::sqrt(12 * n));
  EXPECT_NEAR(Sd(off), width / std::sqrt(12.0), 4 * width / std::sqrt(12.0) / std::sqrt(2 * n) * 1.2);  // a uniform's
  // sample sd has a smaller spread than a normal's (kurtosis 1.8 < 3); 1.2 is a margin on the normal's formula
}

TEST(Population, CorrelatedScoresHaveTheCoefficientWritten) {
  const Population p(Spec(R"([population]
count = 4000
[[population.spread]]
parameter = "nodes.anode.heat_capacity_J_per_K"
distribution = "lognormal"
relative_sigma = 0.05
[[population.spread]]
parameter = "nodes.block.heat_capacity_J_per_K"
distribution = "lognormal"
relative_sigma = 0.1
[[population.correlation]]
parameters = ["nodes.block.heat_capacity_J_per_K", "nodes.anode.heat_capacity_J_per_K"]
coefficient = 0.8
)"),
                     Default());
  std::vector<double> a, b;
  for (double x : Column(p, 0)) a.push_back(std::log(x / 250.0) / 0.05);
  for (double x : Column(p, 1)) b.push_back(std::log(x / 350.0) / 0.1);
  const double ma = Mean(a), mb = Mean(b);
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  // The sample correlation's standard error is (1 - rho²) / sqrt(n); 4 of them.
  EXPECT_NEAR(sab / std::sqrt(saa * sbb), 0.8, 4 * (1 - 0.64) / std::sqrt(static_cast<double>(kGyros)));
  EXPECT_NEAR(Sd(b), 1.0, 4 / std::sqrt(2.0 * kGyros));  // each score keeps its own unit variance
}

void ExpectRefused(const std::string& toml_text, const std::string& fragment, const GyroConfig& gyro) {
  try {
    const Population p(Spec(toml_text), gyro);
    for (uint64_t i = 0; i < p.count(); ++i) (void)p.Draw(1, i);
    ADD_FAILURE() << "accepted: " << toml_text;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(Population, RefusesWhatIsNotASpreadNamingFileAndLine) {
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"nodes.mirror.heat_capacity_J_per_K\"\n"
                "distribution = \"lognormal\"\nrelative_sigma = 0.05\n",
                "pop.toml:3: [[population.spread]] parameter 'nodes.mirror.heat_capacity_J_per_K' names no parameter");
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"nodes.*.heat_capacity_J_per_K\"\n"
                "distribution = \"lognormal\"\nrelative_sigma = 0.05\n[[population.spread]]\n"
                "parameter = \"nodes.block.heat_capacity_J_per_K\"\ndistribution = \"normal\"\nsigma = 3.0\n",
                "pop.toml:7: parameter 'nodes.block.heat_capacity_J_per_K' is spread by two");
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"bias.b0_dph\"\ndistribution = "
                "\"normal\"\nsigma = 0.1\n[[population.correlation]]\nparameters = [\"bias.b0_dph\", "
                "\"bias.b1_dph_per_C\"]\ncoefficient = 0.5\n",
                "pop.toml:7: [[population.correlation]] names 'bias.b1_dph_per_C', which no [[population.spread]]");
  // a-b and b-c strongly positive with a-c strongly negative: no correlation matrix.
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"nodes.*.heat_capacity_J_per_K\"\n"
                "distribution = \"lognormal\"\nrelative_sigma = 0.05\n"
                "[[population.correlation]]\nparameters = [\"nodes.anode.heat_capacity_J_per_K\", "
                "\"nodes.block.heat_capacity_J_per_K\"]\ncoefficient = 0.9\n"
                "[[population.correlation]]\nparameters = [\"nodes.block.heat_capacity_J_per_K\", "
                "\"nodes.cathode.heat_capacity_J_per_K\"]\ncoefficient = 0.9\n"
                "[[population.correlation]]\nparameters = [\"nodes.anode.heat_capacity_J_per_K\", "
                "\"nodes.cathode.heat_capacity_J_per_K\"]\ncoefficient = -0.9\n",
                "not positive definite");
  // The default gyro's RRW is 0: a relative spread would leave it 0 on every gyro.
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"noise.rrw_deg_per_h_per_sqrt_h\"\n"
                "distribution = \"lognormal\"\nrelative_sigma = 0.1\n",
                "is 0 in gyro 'default', so a relative spread leaves it 0");
  ExpectRefused("[population]\ncount = 200\n[[population.spread]]\nparameter = \"nodes.*.heat_capacity_J_per_K\"\n"
                "distribution = \"normal\"\nrelative_sigma = 0.9\n",
                "outside its physical range (> 0)");
  ExpectRefused("[population]\ncount = 0\n", "pop.toml:2: key 'count' in [population]: expected a gyro count");
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"bias.b0_dph\"\n"
                "distribution = \"normal\"\nsigma = 0.1\nrelative_sigma = 0.1\n",
                "one of sigma");
  ExpectRefused("[population]\ncount = 5\n[[population.spread]]\nparameter = \"bias.b0_dph\"\n"
                "distribution = \"uniform\"\nrange = [0.2, -0.2]\n",
                "lo <= hi");
}

}  // namespace
}  // namespace rlg::sim

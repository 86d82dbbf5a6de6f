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
#include "sim/gyro.h"
#include "sim/population.h"
#include "tools/source_dir.h"

namespace rlg::sim {

using io::LoadGyro;
using io::ReadPopulation;
using io::TomlReader;

namespace {

GyroConfig Default() { return LoadGyro(rlg::tools::SourcePath("scenarios/gyros/default.toml")); }

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
  const GyroConfig g = Default();
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

void ExpectRefused(const std::string& toml_text, const std::string& fragment) {
  try {
    const Population p(Spec(toml_text), Default());
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

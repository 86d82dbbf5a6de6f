// Every catalog effect (scenarios/README.md, Effects), switched on in a noiseless default gyro, moves the
// output in its physical direction relative to the same run without it.

#include <gtest/gtest.h>

#include <algorithm>

#include "sim/effects/play.h"
#include "sim/errors.h"
#include "sim/simulator.h"
#include "tests/sim/test_helpers.h"

namespace rlg::sim {
namespace {

RunSpec WarmUp() {
  RunSpec r;
  r.id = "warmup";
  r.duration_s = 3600;
  r.sample_period_s = 10;
  r.ambient = Profile::Constant(20.0);
  return r;
}

struct Pair {
  Run base, with;
};

Pair Compare(const RunSpec& spec, const EffectSpec& effect) {
  const GyroConfig base = test::NoiselessDefaultGyro();
  GyroConfig with = base;
  ApplyEffect(effect, with);
  return {SimulateRun(base, spec, 1, 0), SimulateRun(with, spec, 1, 0)};
}

TEST(Effects, CatalogHasTheElevenFixedNames) {
  EXPECT_EQ(EffectNames(), (std::vector<std::string>{"thermal.missing_mass", "thermal.missing_link",
                                                     "thermal.power_drift", "thermal.radiation", "sensor.lag",
                                                     "sensor.offset", "bias.temperature_rate", "bias.gradient",
                                                     "bias.hysteresis", "bias.play", "bias.mode_hop"}));
}

TEST(Effects, MissingMassSlowsTheBlockWarmUp) {
  const auto [b, w] = Compare(WarmUp(), {"thermal.missing_mass", "block-cabinet",
                                         {{"heat_capacity_J_per_K", 300.0}, {"conductance_W_per_K", 0.5}}});
  // A heat capacity on a path out of the block soaks heat: the block warms less.
  EXPECT_LT(w.Column("T1")[180], b.Column("T1")[180] - 0.05);
}

TEST(Effects, MissingLinkToCabinetCoolsTheAnode) {
  const auto [b, w] = Compare(WarmUp(), {"thermal.missing_link", "anode-cabinet", {{"conductance_W_per_K", 0.1}}});
  EXPECT_LT(w.Column("T2").back(), b.Column("T2").back() - 0.1);
}

TEST(Effects, PositivePowerDriftHeatsMoreAboveItsReference) {
  const auto [b, w] = Compare(WarmUp(), {"thermal.power_drift", "cathode", {{"g_per_C", 0.01}, {"reference_C", 0.0}}});
  // At ~21 °C the discharge dissipates ~21 % more: every node ends warmer.
  EXPECT_GT(w.Column("T1").back(), b.Column("T1").back() + 0.1);
  EXPECT_GT(w.Column("T4").back(), b.Column("T4").back() + 0.1);
}

TEST(Effects, RadiationToAmbientCoolsAWarmBlock) {
  const auto [b, w] = Compare(WarmUp(), {"thermal.radiation", "block-ambient", {{"emissivity_area_m2", 0.02}}});
  EXPECT_LT(w.Column("T1").back(), b.Column("T1").back() - 0.05);
}

TEST(Effects, SensorLagMakesTheReadingTrailARisingTemperature) {
  const auto [b, w] = Compare(test::RiseFall(), {"sensor.lag", "T1", {{"time_constant_s", 120.0}}});
  const size_t rising = 3000 / 10;  // mid ramp: block rising at ~0.5 °C/min
  EXPECT_LT(w.Column("T1")[rising], b.Column("T1")[rising] - 0.2);
  // Other channels are untouched up to the integrator's error control, which now also
  // watches the lag state: rtol 1e-6 on ~60 °C allows 6e-5 °C; 2e-4 leaves margin.
  for (size_t k = 0; k < b.size(); ++k) EXPECT_NEAR(w.Column("T2")[k], b.Column("T2")[k], 2e-4);
}

TEST(Effects, ASecondSensorLagOnALaggedChannelIsAStageInSeries) {
  // sensor.lag on a channel that already lags adds a stage after the first (a sensor in a
  // housing glued on), it does not replace it: the reading trails by about the sum of the two.
  GyroConfig g = test::NoiselessDefaultGyro();
  ApplyEffect({"sensor.lag", "T1", {{"time_constant_s", 60.0}}}, g);
  GyroConfig two = g;
  ApplyEffect({"sensor.lag", "T1", {{"time_constant_s", 60.0}}}, two);
  EXPECT_EQ(two.sensors[0].lag_time_constants_s, (std::vector<double>{60.0, 60.0}));
  GyroConfig sum = test::NoiselessDefaultGyro();
  ApplyEffect({"sensor.lag", "T1", {{"time_constant_s", 120.0}}}, sum);
  const RunSpec spec = test::RiseFall();
  const sim::Run one = SimulateRun(g, spec, 1, 0), series = SimulateRun(two, spec, 1, 0), single = SimulateRun(sum, spec, 1, 0);
  const size_t rising = 3000 / 10;  // mid ramp, ~0.5 °C/min: a lag of tau trails by ~tau x rate
  EXPECT_LT(series.Column("T1")[rising], one.Column("T1")[rising] - 0.2);
  // Two 60 s stages trail a ramp as one 120 s stage does, up to the ramp's curvature: the
  // transfer functions differ by -tau1 tau2 s^2 at second order (-3600 s^2 x d2T/dt2, 0.023 °C
  // here), against the second stage's own trail of ~60 s x 0.5 °C/min = 0.5 °C; a tenth of it
  // separates "in series" from "replaced" (which would read as `one`) with a wide margin.
  const double second_stage = one.Column("T1")[rising] - series.Column("T1")[rising];
  EXPECT_LT(std::abs(series.Column("T1")[rising] - single.Column("T1")[rising]), 0.1 * second_stage);
}

TEST(Effects, SensorOffsetShiftsOnlyItsChannel) {
  const auto [b, w] = Compare(WarmUp(), {"sensor.offset", "T3", {{"offset_C", 0.5}}});
  for (size_t k = 0; k < b.size(); ++k) EXPECT_NEAR(w.Column("T3")[k] - b.Column("T3")[k], 0.5, 1e-12);
  EXPECT_EQ(w.Column("T1"), b.Column("T1"));
  EXPECT_EQ(w.Column("bias_dph"), b.Column("bias_dph"));
}

TEST(Effects, TemperatureRateRaisesBiasWhileHeatingAndLowersItWhileCooling) {
  const auto [b, w] = Compare(test::RiseFall(), {"bias.temperature_rate", "T1", {{"k_dph_per_C_per_min", 0.1}}});
  const size_t heating = 3000 / 10, cooling = 9000 / 10;
  EXPECT_GT(w.Column("bias_dph")[heating] - b.Column("bias_dph")[heating], 0.02);
  EXPECT_LT(w.Column("bias_dph")[cooling] - b.Column("bias_dph")[cooling], -0.02);
}

TEST(Effects, GradientTermFollowsTheNodeDifference) {
  const auto [b, w] = Compare(WarmUp(), {"bias.gradient", "anode-cabinet", {{"k_dph_per_C", 0.2}}});
  for (size_t k = 0; k < b.size(); k += 60) {
    const double expected = 0.2 * (b.Column("T2")[k] - b.Column("T3")[k]);  // noiseless sensors = nodes
    EXPECT_NEAR(w.Column("bias_dph")[k] - b.Column("bias_dph")[k], expected, 1e-9);
  }
  EXPECT_GT(w.Column("bias_dph").back(), b.Column("bias_dph").back());
}

TEST(Effects, HysteresisLeavesABiasOffsetAfterHeatingAndCoolingBack) {
  const auto [b, w] = Compare(test::RiseFall(), {"bias.hysteresis", "block",
                                           {{"k_heating_dph_per_C", 0.01}, {"k_cooling_dph_per_C", 0.005}}});
  // Block goes up and back down by ~40 °C: the loop leaves (0.01 - 0.005) x net travel, and at
  // the top the offset is ~0.01 x 40 = 0.4 °/h.
  const size_t top = 7200 / 10;
  EXPECT_GT(w.Column("bias_dph")[top] - b.Column("bias_dph")[top], 0.3);
  const double end_offset = w.Column("bias_dph").back() - b.Column("bias_dph").back();
  const double travel_left = b.Column("T1").back() - b.Column("T1").front();
  EXPECT_GT(end_offset, 0.005 * 30.0);  // heating counted at 0.01, cooling at 0.005
  EXPECT_LT(end_offset, 0.01 * 41.0 + 0.01 * travel_left);
}

TEST(Effects, PlayBranchesOnATriangleWaveSitKTimesWidthApart) {
  // T runs 0 -> 40 -> 0 -> 40 °C in steps of 0.25 °C (exact in binary, so every sum below is
  // exact): after the first w/2 of heating p = T - w/2, after each reversal and w of travel
  // p = T + w/2 (cooling) or T - w/2 (heating). At the same T the cooling branch's bias less the
  // heating branch's is k w, to round-off (the values are multiples of 2^-k: exactly).
  const double k = 0.02, w = 3.0, T_ref = 20.0;
  std::vector<double> T;
  for (int i = 0; i <= 160; ++i) T.push_back(0.25 * i);
  for (int i = 159; i >= 0; --i) T.push_back(0.25 * i);
  for (int i = 1; i <= 160; ++i) T.push_back(0.25 * i);
  double p = T.front();
  std::vector<double> b;
  for (double t : T) b.push_back(PlayEffect::Bias_dph(k, w, T_ref, t, p));
  // The first rise, from power-on (p_0 = T_0 = 0): held until T reaches w/2, then T - w/2.
  for (int i = 0; i <= 160; ++i) {
    const double expected = T[i] < 0.5 * w ? k * (0.0 - T_ref) : k * (T[i] - 0.5 * w - T_ref);
    EXPECT_NEAR(b[i], expected, 1e-15) << "rise, T = " << T[i];
  }
  // The fall (samples 161 ... 320) and the second rise (321 ... 480) at the same T, both more
  // than w from their reversal: the branch offset is k w.
  for (int i = 0; i <= 160; ++i) {
    const double t = 0.25 * i;
    if (t > 40.0 - w || t < w) continue;  // within w of a reversal the play is crossing over
    const double cooling = b[static_cast<size_t>(320 - i)], heating = b[static_cast<size_t>(320 + i)];
    EXPECT_NEAR(cooling - heating, k * w, 1e-15) << "T = " << t;
    EXPECT_NEAR(cooling, k * (t + 0.5 * w - T_ref), 1e-15) << "T = " << t;
  }
  // Across a reversal p holds still for w: the bias is flat while T returns w.
  EXPECT_EQ(b[160], b[160 + 12]);  // 12 steps of 0.25 = 3 °C = w
  EXPECT_LT(b[160 + 13], b[160 + 12]);
}

TEST(Effects, PlayInTheSimulatorLeavesTheCoolingBranchAboveTheHeatingBranch) {
  // The block rises by ~40 °C and falls back (test::RiseFall): half-way up it is on the
  // heating branch (p = T - w/2), half-way down on the cooling branch (p = T + w/2), both more
  // than w from the reversal. With k (T - T_ref) taken out, what the effect adds there is -k w/2
  // and +k w/2: the branches k w apart. Noiseless sensors read the nodes (as in the gradient
  // test above, 1e-9 for the sensor's path), and the rest of the bias is the same in both runs.
  const double k = 0.02, w = 5.0;
  const auto [b, with] = Compare(test::RiseFall(), {"bias.play", "block", {{"k_dph_per_C", k}, {"width_C", w}}});
  const auto& T1 = b.Column("T1");  // noiseless: the block
  std::vector<double> added(b.size());
  for (size_t i = 0; i < b.size(); ++i) added[i] = with.Column("bias_dph")[i] - b.Column("bias_dph")[i];
  const size_t top = static_cast<size_t>(std::max_element(T1.begin(), T1.end()) - T1.begin());
  const double mid = 0.5 * (T1.front() + T1[top]);
  size_t up = 0, down = top;
  while (T1[up] < mid) ++up;
  while (down + 1 < T1.size() && T1[down] > mid) ++down;
  // Each side: the bias referred to the same temperature, k (T - T_ref) taken out.
  const double heating = added[up] - k * (T1[up] - 20.0), cooling = added[down] - k * (T1[down] - 20.0);
  EXPECT_NEAR(heating, -0.5 * k * w, 1e-9);
  EXPECT_NEAR(cooling, 0.5 * k * w, 1e-9);
  EXPECT_NEAR(cooling - heating, k * w, 1e-9);
}

TEST(Effects, ModeHopStepsTheBiasWhenTheBlockTravelsPastThePathLengthControlRange) {
  const auto [b, w] = Compare(test::RiseFall(), {"bias.mode_hop", "block",
                                           {{"step_dph", 0.05}, {"mode_spacing_C", 10.0}, {"range_modes", 0.6}}});
  std::vector<double> diff;
  for (size_t k = 0; k < b.size(); ++k) diff.push_back(w.Column("bias_dph")[k] - b.Column("bias_dph")[k]);
  // The PLC travel term is continuous; the hop term is a multiple of step_dph. Heating by ~40 °C
  // with 10 °C per mode and a +-0.6 mode range gives 3 hops up (at +6, +16, +26 ... +36 °C).
  const double max_diff = *std::max_element(diff.begin(), diff.end());
  EXPECT_GT(max_diff, 2 * 0.05);
  EXPECT_EQ(*std::min_element(diff.begin(), diff.begin() + 150), 0.0);  // before the ramp: no hop
}

TEST(Effects, UnknownEffectNameOrTargetIsAnInputError) {
  GyroConfig g = test::NoiselessDefaultGyro();
  EXPECT_THROW(ApplyEffect({"bias.wobble", "T1", {}}, g), InputError);
  EXPECT_THROW(ApplyEffect({"sensor.offset", "T9", {{"offset_C", 1.0}}}, g), InputError);
  EXPECT_THROW(ApplyEffect({"bias.gradient", "anode-moon", {{"k_dph_per_C", 1.0}}}, g), InputError);
  EXPECT_THROW(ApplyEffect({"sensor.offset", "T1", {{"offset_degC", 1.0}}}, g), InputError);
}

}  // namespace
}  // namespace rlg::sim

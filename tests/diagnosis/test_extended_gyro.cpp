// The extended gyro of a diagnosis is a gyro file: saved and loaded again it is the same gyro,
// and simulated it reproduces the data the diagnosis calibrated it on to the noise level
// (the file on disk and the library's result are one gyro).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <unistd.h>

#include "diagnosis/diagnose.h"
#include "io/gyro_file.h"
#include "io/gyro_toml.h"
#include "sim/gyro_compare.h"
#include "tests/diagnosis/hidden_effects.h"

namespace rlg::diagnosis {
namespace {

/// RMS over runs and channels of the 100 s means of data - prediction (°C).
double Rms100(const sim::Trace& data, const sim::Trace& prediction, const std::vector<std::string>& channels) {
  double ss = 0.0;
  int n = 0;
  for (size_t r = 0; r < data.runs.size(); ++r) {
    const sim::Run& a = data.runs[r];
    const sim::Run& b = prediction.runs[r];
    for (const auto& ch : channels) {
      const auto& x = a.columns[a.Find(ch)];
      const auto& y = b.columns[b.Find(ch)];
      for (size_t k0 = 0; k0 + 100 <= a.size(); k0 += 100) {  // 1 s samples
        double m = 0.0;
        for (size_t k = k0; k < k0 + 100; ++k) m += x[k] - y[k];
        ss += (m / 100.0) * (m / 100.0);
        ++n;
      }
    }
  }
  return std::sqrt(ss / n);
}

TEST(ExtendedGyro, SavedItReadsBackAndSimulatesTheDataToTheNoiseLevel) {
  // Truth: the diagnosis suite's gyro with a missing anode-cathode link (a clear case of
  // test_diagnose_pipeline) and its block 4 % heavier than nominal (within the 5 % prior).
  sim::Scenario truth = test::DiagnosisScenario();
  truth.runs.resize(3);  // enough to calibrate and name it; keeps the test to seconds
  sim::ApplyEffect({"thermal.missing_link", "anode-cathode", {{"conductance_W_per_K", 0.01}}}, truth.gyro);
  truth.gyro.network.nodes[truth.gyro.network.FindNode("block")].heat_capacity_J_per_K *= 1.04;
  const sim::Trace data = sim::SimulateScenario(truth, truth.seed);
  const sim::GyroConfig nominal = test::DiagnosisScenario().gyro;
  DiagnoseOptions o;
  o.max_steps = 1;
  const Diagnosis d = Diagnose(data, nominal, o);
  ASSERT_FALSE(d.steps.empty()) << test::TopCandidates(d);
  ASSERT_EQ(d.steps.front().accepted.cause, "thermal.missing_link") << test::TopCandidates(d);

  char path[] = "/tmp/rlg_extended_gyro_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  io::SaveGyro(d.extended_gyro, path);
  const sim::GyroConfig loaded = io::LoadGyro(path);
  std::remove(path);
  EXPECT_EQ(sim::GyroDifference(loaded, d.extended_gyro), "");
  ASSERT_EQ(loaded.effects.size(), 1u);
  EXPECT_EQ(loaded.effects.front().name, "thermal.missing_link");

  // Noise-free simulations of the same runs with the loaded gyro and with the nominal.
  std::vector<std::string> channels;
  for (const auto& s : nominal.sensors) channels.push_back(s.channel);
  sim::Scenario with_loaded = test::Noiseless(truth), with_nominal = test::Noiseless(truth);
  with_loaded.gyro = test::Noiseless(loaded);
  with_nominal.gyro = test::Noiseless(nominal);
  const double noise = test::NoiseRms100(truth.gyro, false);
  const double rms_loaded = Rms100(data, sim::SimulateScenario(with_loaded, 1), channels);
  const double rms_nominal = Rms100(data, sim::SimulateScenario(with_nominal, 1), channels);
  std::printf("100 s RMS of data - simulation: extended gyro %.3g °C, nominal %.3g °C, noise %.3g °C\n", rms_loaded,
              rms_nominal, noise);
  // The nominal misses by far more than the noise, so the bound below can fail.
  EXPECT_GT(rms_nominal, 10.0 * noise);
  // The extended gyro: the noise of the 100 s means, plus what a calibration of ~20 knobs
  // from three runs leaves (its held-out RMS, d.extended, is of the same order): 2x.
  EXPECT_LT(rms_loaded, 2.0 * noise);
}

}  // namespace
}  // namespace rlg::diagnosis

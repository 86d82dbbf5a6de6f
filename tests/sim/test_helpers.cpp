#include "tests/sim/test_helpers.h"

#include <cmath>

namespace rlg::test {

sim::GyroConfig NoiselessDefaultGyro() {
  sim::GyroConfig g = io::LoadGyro(SourcePath("scenarios/gyros/default.toml"));
  g.noise = sim::GyroNoiseParams{};
  for (auto& s : g.sensors) s.noise = sim::SensorNoiseParams{};
  return g;
}

Track SmoothCycle(int nodes) {
  const int samples = 2000;
  const double period_s = 8000.0, dt = period_s / samples;
  Track x{Eigen::MatrixXd(nodes, samples), Eigen::MatrixXd(nodes, samples)};
  for (int i = 0; i < nodes; ++i) {
    const double amplitude = 40.0 * (1.0 + 0.15 * i), delay_s = 150.0 * i, w = 2.0 * M_PI / period_s;
    for (int k = 0; k < samples; ++k) {
      const double t = k * dt - delay_s;
      x.T(i, k) = 20.0 + amplitude * (1.0 - std::cos(w * t)) / 2.0;
      x.Tdot(i, k) = amplitude * w * std::sin(w * t) / 2.0;
    }
  }
  return x;
}

std::vector<double> BiasAlong(const sim::BiasParams& params, const Track& x) {
  const sim::BiasModel model(params);
  sim::BiasModel::State state = model.Start(x.T.col(0));
  std::vector<double> b;
  for (Eigen::Index k = 0; k < x.T.cols(); ++k) b.push_back(model.Evaluate(x.T.col(k), x.Tdot.col(k), state));
  return b;
}

sim::GyroConfig NominalForBiasTerms() {
  sim::GyroConfig g = NoiselessDefaultGyro();
  g.bias.mode_spacing_C = 30.0;
  return g;
}

sim::RunSpec RiseFall() {
  sim::RunSpec r;
  r.id = "rise-fall";
  r.duration_s = 14400;
  r.sample_period_s = 10;
  r.ambient = sim::Profile::Table({{0, 20}, {1800, 20}, {4200, 60}, {7200, 60}, {9600, 20}});
  return r;
}

void TempDir::SetUp() {
  dir_ = std::filesystem::temp_directory_path() /
         ("rlg_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name()) + "_" +
          ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::create_directories(dir_);
}

void TempDir::TearDown() { std::filesystem::remove_all(dir_); }

std::string TempDir::Write(const std::string& name, const std::string& text) {
  const auto p = dir_ / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

}  // namespace rlg::test

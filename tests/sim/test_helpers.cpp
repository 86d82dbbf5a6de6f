#include "tests/sim/test_helpers.h"

namespace rlg::test {

sim::GyroConfig NoiselessDefaultGyro() {
  sim::GyroConfig g = io::LoadGyro(SourcePath("scenarios/gyros/default.toml"));
  g.noise = sim::GyroNoiseParams{};
  for (auto& s : g.sensors) s.noise = sim::SensorNoiseParams{};
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

// What the readers accept : a byte-order mark is no error; values beyond
// sim/limits.h's physical limits are refused with file, line and the limit; nothing the
// simulator writes is refused by our own reader; no float-to-int cast is undefined.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>

#include "io/csv.h"
#include "io/gyro_file.h"
#include "io/import.h"
#include "io/scenario_file.h"
#include "sim/errors.h"
#include "sim/noise.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tests/sim/test_helpers.h"

namespace rlg::io {

using sim::CheckReadable;
using sim::GyroNoise;
using sim::GyroNoiseParams;
using sim::Rng;
using sim::RunIdProblem;
using sim::Scenario;
using sim::SensorNoise;
using sim::Trace;

namespace {

class Limits : public test::TempDir {
 protected:
  static std::string DefaultGyroText() {
    std::ifstream in(test::SourcePath("scenarios/gyros/default.toml"));
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  /// gyro.toml: the default gyro file with `from` replaced by `to` (the text must occur).
  std::string GyroWith(const std::string& from, const std::string& to) {
    std::string g = DefaultGyroText();
    const size_t at = g.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) g.replace(at, from.size(), to);
    return Write("gyro.toml", g);
  }
  /// A scenario of one run "r" (line 2) of the gyro file gyro.toml; `run` holds its other keys.
  std::string ScenarioWith(const std::string& run, const std::string& duration_s = "60") {
    return Write("s.toml", "gyro = \"gyro.toml\"\n[[runs]]\nid = \"r\"\nduration_s = " + duration_s + "\n" + run);
  }
};

constexpr char kBom[] = "\xEF\xBB\xBF";

TEST_F(Limits, ByteOrderMarkBeforeTheCsvHeaderIsSkipped) {
  for (const std::string first : {"", "# exported\n"}) {
    const auto path = Write("bom.csv", std::string(kBom) + first + "run,t_s,T1,bias_dph\na,0,20,0.5\na,1,20,0.6\n");
    const auto r = ReadTraceCsv(path);
    ASSERT_EQ(r.trace.runs.size(), 1u);
    EXPECT_EQ(r.trace.runs[0].id, "a");
    EXPECT_EQ(r.trace.runs[0].size(), 2u);
    EXPECT_TRUE(r.warnings.empty()) << r.warnings[0];
  }
}

TEST_F(Limits, ByteOrderMarkBeforeTomlFilesIsSkipped) {
  Write("gyro.toml", kBom + DefaultGyroText());
  const auto path = Write("s.toml", std::string(kBom) + "gyro = \"gyro.toml\"\n[[runs]]\nid = \"r\"\n"
                                                         "ambient = { profile = \"constant\", value_C = 20 }\n");
  EXPECT_EQ(LoadScenario(path).gyro.name, "default");
}

TEST_F(Limits, ByteOrderMarkBeforeAHeaderlessTclabLogKeepsItsFirstRow) {
  // The mark made the first row non-numeric, so it was taken for a header and dropped.
  const auto path = Write("log.txt", std::string(kBom) + "0,0,0,20.5,21\n1,10,0,20.6,21\n");
  const sim::Run run = ImportTclab(path);
  ASSERT_EQ(run.size(), 2u);
  EXPECT_EQ(run.Column("T1").front(), 20.5);
}

TEST_F(Limits, CsvValuesBeyondThePhysicalLimitsAreNamedWithTheLimit) {
  const std::string head = "run,t_s,T1,bias_dph,P_heater1_W\n";
  struct Case {
    std::string row, expect;
  };
  const std::vector<Case> cases = {
      {"a,0,20,1e303,1\n", ":2: column 4 ('bias_dph'): bias 1e+303 °/h is beyond ±1e+07 °/h"},
      {"a,0,20,-2e7,1\n", "column 4 ('bias_dph'): bias -2e+07 °/h is beyond"},
      {"a,1e150,20,0.5,1\n", ":2: column 2 ('t_s'): time 1e+150 s is beyond ±1e+09 s"},
      {"a,-2e9,20,0.5,1\n", "column 2 ('t_s'): time -2e+09 s"},
      {"a,0,20,0.5,1e300\n", "column 5 ('P_heater1_W'): power 1e+300 W is beyond ±10000 W"},
      {"#a,0,20,0.5,1\n", "no data rows"},  // a comment, not a run
  };
  for (const auto& c : cases) {
    const auto path = Write("limits.csv", head + c.row);
    const std::string m = ErrorOf([&] { ReadTraceCsv(path); });
    EXPECT_NE(m.find(c.expect), std::string::npos) << "got: " << m << "\nwanted: " << c.expect;
  }
  // At the limits the values are read.
  const auto path = Write("edge.csv", head + "a,-1e9,-80,1e7,-1e4\na,1e9,150,-1e7,1e4\n");
  EXPECT_EQ(ReadTraceCsv(path).trace.runs[0].size(), 2u);
}

TEST_F(Limits, ARunIdTheWriterCannotWriteBackIsRefused) {
  // With the run column not first, "#a" is no comment on reading, but would be one once written.
  const auto path = Write("id.csv", "t_s,run,T1,bias_dph\n0,#a,20,0.5\n");
  const std::string m = ErrorOf([&] { ReadTraceCsv(path); });
  EXPECT_NE(m.find(":2: column 2 ('run'): run id '#a' starts with '#'"), std::string::npos) << m;
  EXPECT_EQ(RunIdProblem("fixed+0"), "");
  EXPECT_NE(RunIdProblem("a b ").find("space"), std::string::npos);
  EXPECT_NE(RunIdProblem("a\rb").find("control"), std::string::npos);
}

TEST_F(Limits, WriterRefusesNonFiniteValuesInsteadOfWritingThem) {
  Trace t;
  t.runs.emplace_back();
  sim::Run& r = t.runs.back();
  r.id = "a";
  r.t_s = {0.0, 1.0};
  r.AddColumn("bias_dph") = {0.5, NAN};
  EXPECT_THROW(FormatTraceCsv(t), NumericalError);
  // A comment line break (a gyro name from a file) does not start a line of its own.
  r.columns[0][1] = 0.6;
  t.comments = {"gyro: two\nrun,t_s,T1"};
  EXPECT_EQ(FormatTraceCsv(t).rfind("# gyro: two run,t_s,T1\nrun,t_s,bias_dph\n", 0), 0u) << FormatTraceCsv(t);
  // A huge finite value is written as it is, not rounded through an overflowing product.
  r.columns[0][1] = 1e303;
  const std::string text = FormatTraceCsv(t);
  EXPECT_EQ(text.find("inf"), std::string::npos) << text;
  EXPECT_NE(FindUnreadableValue(r).find("bias 1e+303 °/h is beyond"), std::string::npos) << FindUnreadableValue(r);
}

TEST_F(Limits, GyroParametersOutsideTheirPhysicalRangeNameFileLineKeyAndRange) {
  struct Case {
    std::string from, to, expect;
  };
  const std::vector<Case> cases = {
      {"noise_C = 0.003                    #", "noise_C = 1e300 #", "gyro.toml:63: key 'noise_C' in [gyro.sensors.T1]: expected a number in 0...10, got 1e+300"},
      {"power_W = 0.6 ", "power_W = 1e300 ", "key 'power_W' in [sources[1]]: expected a number in -10000...10000"},
      {"resolution_C = 0.01                #", "resolution_C = 1e-300 #", "key 'resolution_C' in [gyro.sensors.T1]: expected a number in 1e-06...10"},
      {"b2_dph_per_C2 = -0.00008", "b2_dph_per_C2 = -1e300", "key 'b2_dph_per_C2' in [gyro.bias]: expected a number in -189.036...189.036"},
      {"quantization_arcsec = 0.001 ", "quantization_arcsec = 1e-300 ", "key 'quantization_arcsec' in [gyro.noise]: expected a number in 1e-06...3600"},
      {"heat_capacity_J_per_K = 60.0 ", "heat_capacity_J_per_K = 1e-300 ", "key 'heat_capacity_J_per_K' in [nodes[2]]"},
      {"[sensors.T4]", "[sensors.\"T4,x\"]", "sensor channels are named T1, T2, ... or T_<name>"},
      {"[sensors.T4]", "[sensors.T_amb]", "not T_amb"},
      {"[sensors.T4]", "[sensors.Tx]", "sensor channels are named"},  // the reader ignores a column "Tx"
  };
  for (const auto& c : cases) {
    const auto path = GyroWith(c.from, c.to);
    const std::string m = ErrorOf([&] { LoadGyro(path); });
    EXPECT_NE(m.find(c.expect), std::string::npos) << "got: " << m << "\nwanted: " << c.expect;
  }
}

TEST_F(Limits, EffectParametersFromAFileAreCheckedLikeTheGyros) {
  Write("gyro.toml", DefaultGyroText());
  const auto path = Write("s.toml", "gyro = \"gyro.toml\"\n[[effects]]\nname = \"sensor.lag\"\ntarget = \"T1\"\n"
                                    "time_constant_s = 1e-300\n[[runs]]\nid = \"r\"\n"
                                    "ambient = { profile = \"constant\", value_C = 20 }\n");
  const std::string m = ErrorOf([&] { LoadScenario(path); });
  EXPECT_NE(m.find("s.toml:5: key 'time_constant_s' in [effects[1]]: expected a number in 0.001...1e+06"),
            std::string::npos) << m;
}

TEST_F(Limits, ScenarioInputsOutsideWhatTheCsvHoldsAreRefused) {
  Write("gyro.toml", DefaultGyroText());
  struct Case {
    std::string runs, expect;
  };
  const std::vector<Case> cases = {
      {"ambient = { profile = \"constant\", value_C = -300 }\n", "s.toml:5: key 'value_C' in [runs[1].ambient]: expected a number in -80...150, got -300"},
      {"ambient = { profile = \"constant\", value_C = 1000 }\n", "expected a number in -80...150, got 1000"},
      {"ambient = { profile = \"table\", points = [[0, 20], [10, 200]] }\n", "key 'points' in [runs[1].ambient]: entry 2: value 200 C is outside -80...150 C"},
      {"ambient = { profile = \"steps\", initial_C = 20, steps = [[1e300, 30]] }\n", "entry 1: time 1e+300 s is beyond"},
      {"ambient = { profile = \"sine\", mean_C = 100, amplitude_C = 60, period_s = 100 }\n", "mean ± amplitude must stay within -80...150"},
      {"ambient = { profile = \"sine\", mean_C = 20, amplitude_C = 1, period_s = 1e-300 }\n", "key 'period_s'"},
      {"ambient = { profile = \"constant\", value_C = 20 }\npower = { discharge = { profile = \"constant\", value_W = 1e300 } }\n", "key 'value_W' in [runs[1].power.discharge]: expected a number in -10000...10000"},
      {"ambient = { profile = \"constant\", value_C = 20 }\nsample_period_s = 1e-9\n", "key 'sample_period_s' in [runs[1]]: expected a number in 0.001"},
      {"ambient = { profile = \"constant\", value_C = 20 }\ninitial_C = 500\n", "key 'initial_C'"},
      {"ambient = { profile = \"table\", points = [[0, 20], [10, nan]] }\n", "entry 2: expected finite numbers"},
      // Integers no double holds exactly (beyond 2^53) are numbers, checked like any other:
      // fuzz_scenario found them aborting on an empty optional (tests/fuzz/corpus/scenario).
      {"ambient = { profile = \"steps\", initial_C = -80, steps = [[-1e9, -80], [1e9, 155555555555555550]] }\n",
       "entry 2: value 1.55556e+17 C is outside -80...150 C"},
      {"ambient = { profile = \"table\", points = [[0, 20], [9007199254740993, 20]] }\n", "entry 2: time 9.0072e+15 s is beyond"},
      {"ambient = { profile = \"constant\", value_C = 9007199254740993 }\n", "expected a number in -80...150, got 9.0072e+15"},
  };
  for (const auto& c : cases) {
    const auto path = ScenarioWith(c.runs);
    const std::string m = ErrorOf([&] { LoadScenario(path); });
    EXPECT_NE(m.find(c.expect), std::string::npos) << "got: " << m << "\nwanted: " << c.expect;
  }
  const auto long_run = Write("s.toml", "gyro = \"gyro.toml\"\n[[runs]]\nid = \"r\"\nduration_s = 1e9\n"
                                        "sample_period_s = 1\nambient = { profile = \"constant\", value_C = 20 }\n");
  EXPECT_NE(ErrorOf([&] { LoadScenario(long_run); }).find("at most 1e+08 per run"), std::string::npos);
  // A path the system cannot look up (a name beyond NAME_MAX) is a file not found, with the
  // file and line that name it; std::filesystem threw filesystem_error (fuzz_scenario).
  const std::string too_long(5000, 'g');
  const auto long_gyro = Write("s.toml", "gyro = \"" + too_long + "\"\n[[runs]]\nid = \"r\"\n"
                                         "ambient = { profile = \"constant\", value_C = 20 }\n");
  EXPECT_NE(ErrorOf([&] { LoadScenario(long_gyro); }).find("s.toml:1: key 'gyro'"), std::string::npos);
  for (const auto& load : std::vector<std::function<void(const std::string&)>>{
           [](const std::string& p) { LoadScenario(p); }, [](const std::string& p) { LoadGyro(p); },
           [](const std::string& p) { ReadTraceCsv(p); }}) {
    EXPECT_NE(ErrorOf([&] { load(too_long + ".toml"); }).find(too_long), std::string::npos);
  }
  const auto hash_id = Write("s.toml", "gyro = \"gyro.toml\"\n[[runs]]\nid = \"#1\"\n"
                                       "ambient = { profile = \"constant\", value_C = 20 }\n");
  EXPECT_NE(ErrorOf([&] { LoadScenario(hash_id); }).find("s.toml:3: key 'id'"), std::string::npos);
}

TEST_F(Limits, SimulatedTemperaturesBeyondTheCsvRangeAreRefusedNotWritten) {
  // 10 kW into the default gyro's nodes heats them far past 150 °C within the hour.
  GyroWith("power_W = 0.6 ", "power_W = 1e4 ");
  const auto path = ScenarioWith("ambient = { profile = \"constant\", value_C = 20 }\n", "3600");
  const Scenario sc = LoadScenario(path);
  const Trace trace = SimulateScenario(sc, 1);
  const std::string m = ErrorOf([&] { CheckReadable(sc, trace); });
  EXPECT_NE(m.find("s.toml:2: run 'r': the simulated column 'T"), std::string::npos) << m;
  EXPECT_NE(m.find("outside the plausible range -80...150 °C"), std::string::npos) << m;
}

TEST_F(Limits, WhatSimulateWritesItsReaderReadsBack) {
  // Every input at a limit of its range at once: the written file is read back whole.
  Write("gyro.toml", DefaultGyroText());
  const auto path = ScenarioWith("sample_period_s = 0.001\n"
                                 "ambient = { profile = \"sine\", mean_C = 35, amplitude_C = 115, period_s = 0.004 }\n",
                                 "2");
  const Scenario sc = LoadScenario(path);
  const Trace trace = SimulateScenario(sc, 1);
  CheckReadable(sc, trace);
  const auto back = ReadTraceCsv(Write("out.csv", FormatTraceCsv(trace)));
  EXPECT_EQ(back.trace.runs[0].size(), trace.runs[0].size());
}

TEST(SensorNoise, AReadingBeyondInt64IsNotCastButPassedOn) {
  // noise_C or power_W of 1e300 would make T / resolution overflow an int64 cast (undefined
  // behaviour, -9.2e18 on x86-64): such a value passes through for the limits to refuse.
  const SensorNoise sensor({0.0, 0.01});
  Rng rng(1, 0);
  EXPECT_EQ(sensor.Read(1e300, rng), 1e300);
  EXPECT_TRUE(std::isnan(sensor.Read(NAN, rng)));
  EXPECT_DOUBLE_EQ(sensor.Read(20.004, rng), 20.0);   // rounded to the 0.01 °C resolution
  EXPECT_DOUBLE_EQ(sensor.Read(-20.006, rng), -20.01);  // half away from zero
}

TEST(GyroNoise, AnAngleBeyondInt64PassesThroughTheQuantizer) {
  GyroNoiseParams p;
  p.quantization_arcsec = 1.0;
  GyroNoise noise(p, 1.0, 1, 0);
  // 1e300 °/h over 1 s is 1e300 arcsec = 1e300 pulses, read back as 1e300 °/h (the int64
  // cast made it -9.2e18): finite in, the same out, for the limits to refuse.
  EXPECT_EQ(noise.Sample(1e300), 1e300);
}

}  // namespace
}  // namespace rlg::io

// Scenario/gyro files and the tidy CSV: round trips and every kind of bad input named clearly.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/csv.h"
#include "io/scenario_file.h"
#include "sim/errors.h"
#include "sim/limits.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tests/sim/test_helpers.h"

namespace rlg::io {

using sim::GyroConfig;
using sim::Profile;
using sim::RunSpec;
using sim::SimulateRun;
using sim::Trace;

namespace {

using TempDir = test::TempDir;

const char* kGyro = R"(
name = "two"
[[nodes]]
name = "a"
heat_capacity_J_per_K = 10
[[nodes]]
name = "b"
heat_capacity_J_per_K = 20
[[links]]
between = ["a", "b"]
conductance_W_per_K = 0.1
[[links]]
between = ["b", "ambient"]
conductance_W_per_K = 0.2
[[sources]]
name = "heater"
power_W = 1.0
shares = { a = 1.0 }
[sensors.T1]
node = "a"
)";

std::string Scenario(const std::string& runs) { return "gyro = \"gyro.toml\"\n" + runs; }

using ScenarioFile = TempDir;

TEST_F(ScenarioFile, LoadsEveryProfileKind) {
  Write("gyro.toml", kGyro);
  const auto path = Write("s.toml", Scenario(R"(
[[runs]]
id = "c"
duration_s = 100
ambient = { profile = "constant", value_C = 5 }
[[runs]]
id = "r"
duration_s = 100
ambient = { profile = "ramp", start_C = 0, rate_C_per_min = 6, start_s = 10, end_C = 3 }
[[runs]]
id = "t"
duration_s = 100
ambient = { profile = "table", points = [[0, 1], [50, 2]] }
[[runs]]
id = "s"
duration_s = 100
ambient = { profile = "steps", initial_C = 1, steps = [[20, 4]] }
power = { heater = { profile = "steps", initial_W = 0, steps = [[10, 2]] } }
[[runs]]
id = "w"
duration_s = 100
ambient = { profile = "sine", mean_C = 0, amplitude_C = 2, period_s = 40 }
)"));
  const auto sc = LoadScenario(path);
  ASSERT_EQ(sc.runs.size(), 5u);
  EXPECT_DOUBLE_EQ(sc.runs[0].ambient.Value(50), 5.0);
  EXPECT_DOUBLE_EQ(sc.runs[1].ambient.Value(20), 1.0);   // 6 °C/min for 10 s
  EXPECT_DOUBLE_EQ(sc.runs[1].ambient.Value(99), 3.0);   // held at end_C
  EXPECT_DOUBLE_EQ(sc.runs[2].ambient.Value(25), 1.5);
  EXPECT_DOUBLE_EQ(sc.runs[3].ambient.Value(19.9), 1.0);
  EXPECT_DOUBLE_EQ(sc.runs[3].ambient.Value(20), 4.0);
  EXPECT_DOUBLE_EQ(sc.runs[3].power.at("heater").Value(15), 2.0);
  EXPECT_NEAR(sc.runs[4].ambient.Value(10), 2.0, 1e-12);
  EXPECT_EQ(sc.gyro.name, "two");
}

TEST_F(ScenarioFile, UnknownKeyIsNamedWithItsLine) {
  Write("gyro.toml", kGyro);
  const auto path = Write("s.toml", Scenario("[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\nduraton_s = 5\n"));
  const std::string m = ErrorOf([&] { LoadScenario(path); });
  EXPECT_NE(m.find("s.toml:5: unknown key 'duraton_s' in [runs[1]]; did you mean 'duration_s'? (see scenarios/README.md "
                   "for the keys)"),
            std::string::npos)
      << m;
}

TEST_F(ScenarioFile, AMisspeltKeyIsNamedWithTheKeyItMisspellsBeforeWhatItLeavesMissing) {
  // A required key misspelt: the typo, not only the missing key.
  Write("gyro.toml", std::string(kGyro).replace(std::string(kGyro).find("name = \"a\""), 10, "nmae = \"a\""));
  const auto path = Write("s.toml", Scenario("[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\n"));
  std::string m = ErrorOf([&] { LoadScenario(path); });
  EXPECT_NE(m.find("gyro.toml:4: unknown key 'nmae' in [nodes[1]]; did you mean 'name'?"), std::string::npos) << m;
  // A table the file needs, misspelt: named instead of "needs at least one [[runs]] entry".
  Write("gyro.toml", kGyro);
  m = ErrorOf([&] { LoadScenario(Write("s.toml", Scenario("[[run]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\n"))); });
  EXPECT_NE(m.find("s.toml:2: unknown key 'run' in [scenario]; did you mean 'runs'?"), std::string::npos) << m;
  // A key that is its unit short, and one in an inline table.
  m = ErrorOf([&] { LoadScenario(Write("s.toml", Scenario("[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value = 1 }\n"))); });
  EXPECT_NE(m.find("unknown key 'value' in [runs[1].ambient]; did you mean 'value_C'?"), std::string::npos) << m;
  // A key near none: the keys the table takes.
  m = ErrorOf([&] {
    LoadScenario(Write("s.toml", Scenario("[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\nxyz = 1\n")));
  });
  EXPECT_NE(m.find("s.toml:5: unknown key 'xyz' in [runs[1]]; the keys here: ambient, duration_s, id, "), std::string::npos) << m;
}

TEST_F(ScenarioFile, UnknownKeyInGyroIsNamed) {
  Write("gyro.toml", std::string(kGyro) + "[[links]]\nbetween = [\"a\", \"ambient\"]\nconductance = 1\n");
  const auto path = Write("s.toml", Scenario("[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\n"));
  const std::string m = ErrorOf([&] { LoadScenario(path); });
  EXPECT_NE(m.find("gyro.toml:"), std::string::npos) << m;
  EXPECT_NE(m.find("'conductance_W_per_K'"), std::string::npos) << m;  // the key it expected
}

TEST_F(ScenarioFile, MissingFileIsNamed) {
  const std::string m = ErrorOf([&] { LoadScenario((dir_ / "nope.toml").string()); });
  EXPECT_NE(m.find("nope.toml: scenario file not found"), std::string::npos) << m;
}

TEST_F(ScenarioFile, NegativeHeatCapacityIsNamedWithItsLine) {
  std::string g = kGyro;
  const std::string c10 = "heat_capacity_J_per_K = 10";
  g.replace(g.find(c10), c10.size(), "heat_capacity_J_per_K = -10");
  Write("gyro.toml", g);
  const auto path = Write("s.toml", Scenario("[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\n"));
  const std::string m = ErrorOf([&] { LoadScenario(path); });
  EXPECT_NE(m.find("gyro.toml:5: key 'heat_capacity_J_per_K'"), std::string::npos) << m;
  EXPECT_NE(m.find("> 0"), std::string::npos) << m;
}

TEST_F(ScenarioFile, NodeWithoutPathToAmbientIsNamed) {
  std::string g = kGyro;
  const std::string to_ambient = "between = [\"b\", \"ambient\"]";
  g.replace(g.find(to_ambient), to_ambient.size(), "between = [\"a\", \"b\"]");
  Write("gyro.toml", g);
  const auto path = Write("s.toml", Scenario("[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\n"));
  const std::string m = ErrorOf([&] { LoadScenario(path); });
  EXPECT_NE(m.find("no conductive path to ambient"), std::string::npos) << m;
}

TEST_F(ScenarioFile, UnsortedTableIsNamedWithItsLine) {
  Write("gyro.toml", kGyro);
  const auto path = Write("s.toml", Scenario("[[runs]]\nid = \"x\"\n"
                                             "ambient = { profile = \"table\", points = [[0, 1], [50, 2], [40, 3]] }\n"));
  const std::string m = ErrorOf([&] { LoadScenario(path); });
  EXPECT_NE(m.find("s.toml:"), std::string::npos) << m;
  EXPECT_NE(m.find("strictly increasing"), std::string::npos) << m;
}

TEST_F(ScenarioFile, EffectsListedInTheScenarioAreApplied) {
  Write("gyro.toml", kGyro);
  const auto path = Write("s.toml", Scenario("[[effects]]\nname = \"sensor.offset\"\ntarget = \"T1\"\noffset_C = 0.25\n"
                                             "[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\n"));
  const auto sc = LoadScenario(path);
  EXPECT_DOUBLE_EQ(sc.gyro.sensors[0].offset_C, 0.25);
  const auto bad = Write("b.toml", Scenario("[[effects]]\nname = \"sensor.offset\"\ntarget = \"T7\"\noffset_C = 1\n"
                                            "[[runs]]\nid = \"x\"\nambient = { profile = \"constant\", value_C = 1 }\n"));
  const std::string m = ErrorOf([&] { LoadScenario(bad); });
  EXPECT_NE(m.find("b.toml:2: [effects[1]]"), std::string::npos) << m;
}

using TidyCsv = TempDir;

TEST_F(TidyCsv, SimulatedTraceRoundTripsThroughTheFile) {
  const GyroConfig gyro = test::NoiselessDefaultGyro();
  RunSpec spec;
  spec.id = "fixed+0";
  spec.duration_s = 600;
  spec.ambient = Profile::Constant(0.0);
  Trace t;
  t.comments = {"gyro: default"};
  t.runs.push_back(SimulateRun(gyro, spec, 1, 0));
  const auto path = Write("t.csv", FormatTraceCsv(t));
  const auto back = ReadTraceCsv(path);
  EXPECT_TRUE(back.warnings.empty());
  ASSERT_EQ(back.trace.runs.size(), 1u);
  const sim::Run& r = back.trace.runs[0];
  EXPECT_EQ(r.names, t.runs[0].names);
  EXPECT_EQ(r.t_s, t.runs[0].t_s);
  for (size_t c = 0; c < r.names.size(); ++c) {
    for (size_t k = 0; k < r.size(); k += 37) {
      // Written with 4 decimals for temperatures, 6 for bias: half a unit in the last place.
      EXPECT_NEAR(r.columns[c][k], t.runs[0].columns[c][k], r.names[c] == "bias_dph" ? 5e-7 : 5e-5);
    }
  }
  EXPECT_EQ(back.trace.comments, t.comments);
}

TEST_F(TidyCsv, BadInputIsNamedByFileLineAndColumn) {
  const std::string head = "run,t_s,T1,bias_dph\n";
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {"", "empty file"},
      {"run,t_s,bias_dph\na,0,1\n", "missing required column 'T1'"},
      {head + "a,0,1,x\n", ":2: column 4 ('bias_dph'): expected a number, found 'x'"},
      {head + "a,0,1,nan\n", ":2: column 4 ('bias_dph'): expected a finite number"},
      {head + "a,0,1,inf\n", "expected a finite number"},
      {head + "a,0,1,1\na,0,1,1\n", ":3: column 2 ('t_s'): time must increase strictly"},
      {head + "a,0,200,1\n", "outside the plausible range -80...150"},
      {head + "a,0,1,1\nb,0,1,1\na,1,1,1\n", ":4: rows of run 'a' are not contiguous"},
      {head + "a,0,1\n", ":2: expected 4 comma-separated fields"},
      {head, "no data rows"},
  };
  for (const auto& c : cases) {
    const auto path = Write("bad.csv", c.text);
    const std::string m = ErrorOf([&] { ReadTraceCsv(path); });
    EXPECT_NE(m.find(c.expect), std::string::npos) << "got: " << m << "\nwanted: " << c.expect;
  }
  EXPECT_NE(ErrorOf([&] { ReadTraceCsv((dir_ / "missing.csv").string()); }).find("cannot open"), std::string::npos);
}

TEST_F(TidyCsv, ExtraColumnsAreIgnoredWithOneWarning) {
  const auto path = Write("x.csv", "# gyro: SN-1\nrun,t_s,T1,humidity,bias_dph,P_heater1_W,note\na,0,1,50,0.5,1.0,3\n");
  const auto r = ReadTraceCsv(path);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("humidity, note"), std::string::npos) << r.warnings[0];
  EXPECT_EQ(r.trace.runs[0].names, (std::vector<std::string>{"T1", "bias_dph", "P_heater1_W"}));
  EXPECT_EQ(r.trace.comments, (std::vector<std::string>{"gyro: SN-1"}));
}

/// "x0,x1,...": `n` column names after `first`.
std::string Columns(const std::string& first, size_t n) {
  std::string out = first;
  for (size_t i = 0; i < n; ++i) out += ",x" + std::to_string(i);
  return out;
}

TEST_F(TidyCsv, AHeaderOfTheMostColumnsIsReadInOnePassAndAWiderOneIsRefused) {
  const size_t most = static_cast<size_t>(sim::limits::kMaxColumns);
  const std::string head = "run,t_s,T1,bias_dph";
  // At the limit: read, and the warning names the first 20 extra columns and counts the rest.
  std::string zeros;
  for (size_t i = 0; i < most - 4; ++i) zeros += ",0";
  const auto wide = Write("wide.csv", Columns(head, most - 4) + "\na,0,20,0.5" + zeros + "\n");
  const auto r = ReadTraceCsv(wide);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("ignoring extra columns: x0, x1, "), std::string::npos);
  EXPECT_NE(r.warnings[0].find(", x19 and 65512 more"), std::string::npos) << r.warnings[0].substr(0, 300);
  EXPECT_EQ(r.trace.runs.at(0).size(), 1u);
  // One column more: refused at the header, before any row.
  const std::string m = ErrorOf([&] { ReadTraceCsv(Write("wider.csv", Columns(head, most - 3) + "\n")); });
  EXPECT_NE(m.find("wider.csv:1: the header has more than the 65536 columns a data file may have"), std::string::npos) << m;
  // A name repeated at the far end of the header is found (and where it came first).
  const std::string repeated = ErrorOf([&] { ReadTraceCsv(Write("rep.csv", Columns(head, most - 5) + ",x0\na\n")); });
  EXPECT_NE(repeated.find("rep.csv:1: column 65536 ('x0'): column name repeated (column 5 has it too)"), std::string::npos)
      << repeated;
  // A comment may hold any number of commas.
  const auto commented = Write("comment.csv", "# " + std::string(most + 10, ',') + "\n" + head + "\na,0,20,0.5\n");
  EXPECT_EQ(ReadTraceCsv(commented).trace.comments.at(0), std::string(most + 10, ','));
}

TEST_F(TidyCsv, ThermalOnlyDataNeedsNoBiasWhenAllowed) {
  const auto path = Write("th.csv", "run,t_s,T1,T2,P_heater1_W\na,0,20,21,0.5\na,3,20.1,21,0.5\n");
  EXPECT_THROW(ReadTraceCsv(path), InputError);
  CsvReadOptions o;
  o.require_bias = false;
  EXPECT_EQ(ReadTraceCsv(path, o).trace.runs[0].size(), 2u);
}

}  // namespace
}  // namespace rlg::io

// `rlgtherm import columns` (io/import.h, ImportColumns): any delimited log with a header row
// to the tidy CSV's runs. Logs are written here with known values, so every expected number is
// a closed form of them.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "io/import.h"
#include "sim/errors.h"
#include "sim/limits.h"
#include "tests/sim/test_helpers.h"

namespace rlg::io {

using sim::Trace;

namespace {

class ImportColumnsTest : public test::TempDir {
 protected:
  static ColumnsOptions Options(const std::string& time, const std::string& rate, std::vector<std::string> temps) {
    ColumnsOptions o;
    o.time = ParseTimeColumn(time);
    o.rate = ParseRateColumn(rate);
    for (auto& t : temps) o.temperatures.push_back({t, "C", 1.0});
    return o;
  }
};

TEST_F(ImportColumnsTest, TabSeparatedMicrosecondsAndDegreesPerSecondBecomeSecondsFromTheFirstRowAndDegreesPerHour) {
  // Time stamps as large as the IMU log's (2.6e14 µs): the first row is subtracted before scaling.
  const auto path = Write("imu.csv",
                          "timestamp\tgyro.x\tacc\ttemp\n"
                          "256551281491968\t-0.01\t9.8\t51.5\n"
                          "256551281997598\t0.02\t9.8\t52.0\n"
                          "256551282500000\t0.5\t9.8\t52.5\n");
  const Trace trace = ImportColumns(path, Options("timestamp:us", "gyro.x:dps", {"temp"}));
  ASSERT_EQ(trace.runs.size(), 1u);
  const sim::Run& r = trace.runs[0];
  EXPECT_EQ(r.id, "imu");  // the file's stem
  EXPECT_EQ(r.names, (std::vector<std::string>{"T1", "bias_dph"}));
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r.t_s[0], 0.0);
  // 505,630 µs and 1,008,032 µs: exact differences of integers below 2^53, divided by 1e6 (one
  // correctly rounded division): the doubles nearest 0.50563 and 1.008032, written as such.
  EXPECT_EQ(r.t_s[1], 0.50563);
  EXPECT_EQ(r.t_s[2], 1.008032);
  EXPECT_DOUBLE_EQ(r.Column("bias_dph")[0], -36.0);  // -0.01 °/s x 3600 s/h
  EXPECT_DOUBLE_EQ(r.Column("bias_dph")[2], 1800.0);
  EXPECT_EQ(r.Column("T1")[1], 52.0);
}

TEST_F(ImportColumnsTest, SemicolonsWithDecimalCommasAndRadiansPerSecondAreRead) {
  const auto path = Write("log.txt", "t_ms;rate;T_a;T_b\n0;0,001;20,5;21\n100;-0,001;20,6;21,25\n");
  ColumnsOptions o = Options("t_ms:ms", "rate:radps", {"T_b", "T_a"});
  o.run = "bench";
  const sim::Run r = ImportColumns(path, o).runs.at(0);
  EXPECT_EQ(r.id, "bench");
  EXPECT_DOUBLE_EQ(r.t_s[1], 0.1);
  // The temperatures in the order given: T1 = T_b, T2 = T_a.
  EXPECT_EQ(r.Column("T1")[1], 21.25);
  EXPECT_EQ(r.Column("T2")[0], 20.5);
  EXPECT_DOUBLE_EQ(r.Column("bias_dph")[0], 0.001 * 3600.0 * 180.0 / M_PI);  // 206.26 °/h
}

TEST_F(ImportColumnsTest, ColumnsCanBeNamedByTheirOneBasedPosition) {
  const auto path = Write("log.csv", "a,b,c\n0,20,1\n1,20,2\n");
  const sim::Run r = ImportColumns(path, Options("1:s", "3:dph", {"2"})).runs.at(0);
  EXPECT_EQ(r.Column("bias_dph")[1], 2.0);
}

TEST_F(ImportColumnsTest, SplitAtCutsRunsThatKeepCountingFromTheLogsStart) {
  const auto path = Write("cycle.csv", "t,T,w\n0,20,1\n10,21,1\n20,22,1\n30,23,1\n40,24,1\n50,25,1\n");
  ColumnsOptions o = Options("t:s", "w:dph", {"T"});
  o.split_at_s = {20.0, 35.0};  // a row at exactly 20 s starts the second run
  const Trace trace = ImportColumns(path, o);
  ASSERT_EQ(trace.runs.size(), 3u);
  EXPECT_EQ(trace.runs[0].id, "cycle-1");
  EXPECT_EQ(trace.runs[1].id, "cycle-2");
  EXPECT_EQ(trace.runs[0].t_s, (std::vector<double>{0, 10}));
  EXPECT_EQ(trace.runs[1].t_s, (std::vector<double>{20, 30}));
  EXPECT_EQ(trace.runs[2].t_s, (std::vector<double>{40, 50}));
  EXPECT_EQ(trace.runs[2].Column("T1"), (std::vector<double>{24, 25}));
}

TEST_F(ImportColumnsTest, TemperaturesImplausibleForCelsiusAreWarnedOfAsFahrenheit) {
  // A chamber cycle -20 ... +60 °C logged in °F (-4 ... 140) passed silently, as does
  // a log at room temperature in °F (68-72) that never falls below 50 "°C".
  const auto chamber = Write("chamber.csv", "t,T,w\n0,-4,1\n10,70,1\n20,140,1\n");
  const auto warnings = FahrenheitWarnings(ImportColumns(chamber, Options("t:s", "w:dph", {"T"})));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "run 'chamber': T1 spans -4.0 ... 140.0 °C, above 100 °C: is the log in °F? That is -20.0 ... "
                         "60.0 °C; convert it, (°F - 32) / 1.8");
  const auto room = Write("room.csv", "t,T,w\n0,68,1\n10,72,1\n");
  const auto two = FahrenheitWarnings(ImportColumns(room, Options("t:s", "w:dph", {"T", "T"})));
  ASSERT_EQ(two.size(), 2u);  // one per column
  EXPECT_NE(two[1].find("T2 spans 68.0 ... 72.0 °C, never below 50 °C"), std::string::npos) << two[1];
  // A chamber cycle in °C, and a hot soak that starts cool, give none.
  const auto celsius = Write("celsius.csv", "t,T,w\n0,-40,1\n10,85,1\n20,20,1\n");
  EXPECT_TRUE(FahrenheitWarnings(ImportColumns(celsius, Options("t:s", "w:dph", {"T"}))).empty());
  const auto hot = Write("hot.csv", "t,T,w\n0,25,1\n10,95,1\n");
  EXPECT_TRUE(FahrenheitWarnings(ImportColumns(hot, Options("t:s", "w:dph", {"T"}))).empty());
}

TEST_F(ImportColumnsTest, BadInputNamesFileLineAndColumn) {
  const auto log = Write("log.csv", "t,T,w\n0,20,1\n1,abc,1\n");
  EXPECT_NE(ErrorOf([&] { ImportColumns(log, Options("t:s", "w:dph", {"T"})); })
                .find("log.csv:3: column 2 ('T'): expected a finite number, found 'abc'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ImportColumns(log, Options("t:s", "w:dph", {"temp"})); })
                .find("log.csv:1: --temp: no column 'temp' in the header (comma-separated: t, T, w)"),
            std::string::npos);
  const auto back = Write("back.csv", "t,T,w\n0,20,1\n1,20,1\n1,20,1\n");
  EXPECT_NE(ErrorOf([&] { ImportColumns(back, Options("t:s", "w:dph", {"T"})); })
                .find("back.csv:4: column 1 ('t'): time must increase (1 after 1)"),
            std::string::npos);
  const auto kelvin = Write("k.csv", "t,T,w\n0,293.15,1\n1,293.2,1\n");
  EXPECT_NE(ErrorOf([&] { ImportColumns(kelvin, Options("t:s", "w:dph", {"T"})); }).find("k.csv:2: column 2 ('T'): temperature"),
            std::string::npos);
  const auto ragged = Write("r.csv", "t,T,w\n0,20,1\n1,20\n");
  EXPECT_NE(ErrorOf([&] { ImportColumns(ragged, Options("t:s", "w:dph", {"T"})); })
                .find("r.csv:3: expected 3 comma-separated fields as in the header, found 2"),
            std::string::npos);
  ColumnsOptions split = Options("t:s", "w:dph", {"T"});
  split.split_at_s = {0.2, 0.5};
  const auto two = Write("two.csv", "t,T,w\n0,20,1\n1,20,1\n2,20,1\n");
  EXPECT_NE(ErrorOf([&] { ImportColumns(two, split); }).find("--split-at 0.2 s and 0.5 s hold no row between them"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseRateColumn("w:degps"); }).find("unknown unit 'degps' (expected dph, dps, radps)"),
            std::string::npos);
  // A rate without its unit is refused: °/s read as °/h would be 3600 times too small.
  EXPECT_NE(ErrorOf([] { ParseRateColumn("w"); }).find("--rate 'w': give the column's unit: w:dph, w:dps, w:radps"),
            std::string::npos);
  // Nor a time without its: milliseconds read as seconds stretch the log a thousandfold. A unit
  // the name ends in is suggested.
  EXPECT_NE(ErrorOf([] { ParseTimeColumn("time_ms"); })
                .find("--time 'time_ms': give the column's unit: time_ms:s, time_ms:ms, time_ms:us, time_ms:ns (there is "
                      "no default: milliseconds read as seconds make every time 1000 times too long); the name says ms: "
                      "--time time_ms:ms"),
            std::string::npos);
  EXPECT_EQ(ErrorOf([] { ParseTimeColumn("stamp"); }).find("the name says"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseTimeColumn("t [us]"); }).find("the name says us: --time t [us]:us"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseRateColumn("gyro_x_dps"); }).find("the name says dps: --rate gyro_x_dps:dps"),
            std::string::npos);
  // Time stamps in µs read as seconds run past the time limit: the message suggests the unit.
  const auto us = Write("us.csv", "t,T,w\n0,20,1\n2000000000,20,1\n");
  EXPECT_NE(ErrorOf([&] { ImportColumns(us, Options("t:s", "w:dph", {"T"})); })
                .find("us.csv:3: column 1 ('t'): time 2e+09 s is beyond ±1e+09 s (expected seconds since power-on); is the "
                      "time column in us? (--time t:us makes this row 2000 s)"),
            std::string::npos);
  // Spaces do not separate columns: the message says so instead of listing one long column.
  const auto spaces = Write("sp.txt", "time rate temp\n0 1 20\n");
  EXPECT_NE(ErrorOf([&] { ImportColumns(spaces, Options("time:s", "rate:dph", {"temp"})); })
                .find("sp.txt:1: --time: no column 'time': the header is one field, 'time rate temp'; expected columns "
                      "separated by commas, tabs or semicolons (spaces do not separate columns)"),
            std::string::npos);
}

TEST_F(ImportColumnsTest, AHeaderOfTheMostColumnsIsReadAndAWiderOneIsRefusedAtItsHeader) {
  const size_t most = static_cast<size_t>(sim::limits::kMaxColumns);
  std::string header = "t\tw\tT", row = "\t1\t20";
  for (size_t i = 3; i < most; ++i) header += "\tx" + std::to_string(i), row += "\t0";
  const auto wide = Write("wide.tsv", header + "\n0" + row + "\n1" + row + "\n");
  EXPECT_EQ(ImportColumns(wide, Options("t:s", "w:dph", {"T"})).runs.at(0).size(), 2u);
  // A missing column's message names the first 20 columns and counts the rest.
  EXPECT_NE(ErrorOf([&] { ImportColumns(wide, Options("t:s", "w:dph", {"nope"})); })
                .find("wide.tsv:1: --temp: no column 'nope' in the header (tab-separated: t, w, T, x3, x4, "),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ImportColumns(wide, Options("t:s", "w:dph", {"nope"})); }).find(", x19 and 65516 more)"),
            std::string::npos);
  // One column more, in any of the three delimiters: refused at the header.
  for (const char d : {',', '\t', ';'}) {
    std::string wider = "t";
    for (size_t i = 1; i <= most; ++i) wider += d + std::string("x") + std::to_string(i);
    const auto path = Write("wider.csv", wider + "\n");
    EXPECT_NE(ErrorOf([&] { ImportColumns(path, Options("t:s", "w:dph", {"T"})); })
                  .find("wider.csv:1: the header has more than the 65536 columns a data file may have"),
              std::string::npos)
        << d;
  }
}

}  // namespace
}  // namespace rlg::io

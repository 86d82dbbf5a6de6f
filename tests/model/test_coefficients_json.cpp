// The coefficient file read back by `compensate`: every malformed or implausible file is an
// InputError (exit 2) naming the file, the line, the key and what was expected; nothing that
// is accepted can make compensation produce inf or NaN.

#include <gtest/gtest.h>

#include <cmath>

#include "compensation/compensator.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::model {
namespace {

/// A valid file as `fit -o` writes it (one key per line, so each key has its own line).
std::string File(const std::string& model = "\"guo2006\"", const std::string& pair = "[\"T1\", \"T2\"]",
                 const std::string& a00 = "0.01", const std::string& range = "[-30, 60]",
                 const std::string& extra = "") {
  return "{\n"
         "  \"model\": " + model + ",\n"
         "  \"pair\": " + pair + ",\n"
         "  \"B0_window_s\": 120,\n"
         "  \"A\": [[" + a00 + ", 1e-4, 1e-6], [1e-4, 1e-6, 1e-8], [0.4, 1e-3, 1e-5]],\n"
         "  \"T10_range_C\": " + range + ",\n"
         "  \"method\": \"joint\"" + extra + "\n"
         "}\n";
}

std::string ErrorOf(const std::string& text) {
  try {
    ParseCoefficients(text, "c.json");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError for\n" << text;
  return "";
}

TEST(CoefficientsJson, AValidFileIsReadWithAndWithoutAByteOrderMark) {
  for (const std::string bom : {"", "\xEF\xBB\xBF"}) {
    const Guo2006Coefficients c = ParseCoefficients(bom + File(), "c.json");
    EXPECT_EQ(c.pair[1], "T2");
    EXPECT_EQ(c.A(2, 0), 0.4);
    EXPECT_EQ(c.t10_range_C[1], 60.0);
  }
}

TEST(CoefficientsJson, WrongTypesNameFileLineKeyAndWhatWasExpected) {
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {File("5"), "c.json:2: key 'model': expected a string, found 5"},
      {File("\"other\""), "c.json:2: key 'model': expected \"guo2006\", found \"other\""},
      {File("\"guo2006\"", "\"T1\""), "c.json:3: key 'pair': expected two temperature channels"},
      {File("\"guo2006\"", "[\"T1\", 2]"), "c.json:3: key 'pair': expected two temperature channels"},
      {File("\"guo2006\"", "[\"T1\", \"bias_dph\"]"), "key 'pair': expected two temperature channels"},
      {File("\"guo2006\"", "[\"T1\", \"T2\"]", "\"x\""), "c.json:5: key 'A': A[0][0] must be a number, found \"x\""},
      {File("\"guo2006\"", "[\"T1\", \"T2\"]", "0.01", "[-30]"), "c.json:6: key 'T10_range_C': expected [min, max] in °C"},
  };
  for (const auto& c : cases) {
    const std::string m = ErrorOf(c.text);
    EXPECT_NE(m.find(c.expect), std::string::npos) << "got: " << m << "\nwanted: " << c.expect;
  }
  const std::string runs = ErrorOf(File("\"guo2006\"", "[\"T1\", \"T2\"]", "0.01", "[-30, 60]", ",\n  \"runs\": [1, 2]"));
  EXPECT_NE(runs.find("c.json:8: key 'runs': expected an array of run ids, found [1,2]"), std::string::npos) << runs;
  const std::string missing = ErrorOf("{\"model\": \"guo2006\"}");
  EXPECT_NE(missing.find("c.json: key 'pair': missing"), std::string::npos) << missing;
  const std::string array = ErrorOf("[1, 2]");
  EXPECT_NE(array.find("c.json: expected a JSON object"), std::string::npos) << array;
}

TEST(CoefficientsJson, SyntaxErrorsAndOverflowingNumbersNameLineAndColumn) {
  const std::string overflow = ErrorOf(File("\"guo2006\"", "[\"T1\", \"T2\"]", "1e400"));
  EXPECT_NE(overflow.find("c.json:5:"), std::string::npos) << overflow;
  EXPECT_NE(overflow.find("number overflow parsing '1e400'"), std::string::npos) << overflow;
  const std::string syntax = ErrorOf("{\n  \"model\": \"guo2006\",\n  \"pair\": [\"T1\" \"T2\"]\n}\n");
  EXPECT_NE(syntax.find("c.json:3:"), std::string::npos) << syntax;
  EXPECT_NE(syntax.find("not valid JSON"), std::string::npos) << syntax;
  EXPECT_NE(ErrorOf("").find("c.json:1:0: not valid JSON"), std::string::npos) << ErrorOf("");
}

TEST(CoefficientsJson, ImplausibleValuesAreRefused) {
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {File("\"guo2006\"", "[\"T1\", \"T1\"]"), "c.json:3: key 'pair': expected two different channels"},
      {File("\"guo2006\"", "[\"T1\", \"T2\"]", "1e308"), "c.json:5: key 'A': A[0][0] = 1e+308 is outside -43478.3...43478.3"},
      {File("\"guo2006\"", "[\"T1\", \"T2\"]", "0.01", "[60, -30]"), "c.json:6: key 'T10_range_C': expected [min, max], found [60,-30]"},
      {File("\"guo2006\"", "[\"T1\", \"T2\"]", "0.01", "[-300, 60]"), "T10_range_C[0] = -300 is outside -80...150"},
      {File("\"guo2006\"", "[\"T1\", \"T2\"]", "0.01", "[-30, 60]", ",\n  \"method\": \"magic\""), "key 'method': expected \"joint\" or \"two_stage\", found \"magic\""},
  };
  for (const auto& c : cases) {
    const std::string m = ErrorOf(c.text);
    EXPECT_NE(m.find(c.expect), std::string::npos) << "got: " << m << "\nwanted: " << c.expect;
  }
}

TEST(CoefficientsJson, AcceptedCoefficientsAtTheirLimitsCompensateToFiniteValues) {
  // Every A_kl at the largest magnitude accepted, at the corners of the temperature range and
  // the bias limit: the compensated bias stays finite (the limits' purpose).
  Guo2006Coefficients c = ParseCoefficients(File(), "c.json");
  const double t_max = 150.0, span = sim::limits::kTemperatureSpan_C, f_max[3] = {span, span * span, span};
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) c.A(k, l) = sim::limits::kMaxAbsBias_dph / (f_max[k] * std::pow(t_max, l));
  for (const double Ti0 : {-80.0, 150.0}) {
    compensation::Compensator comp(c);
    comp.Update(0.0, Ti0, Ti0, sim::limits::kMaxAbsBias_dph);
    for (const double Ti : {-80.0, 150.0}) {
      for (const double Tj : {-80.0, 150.0}) {
        const double out = comp.Update(1000.0, Ti, Tj, -sim::limits::kMaxAbsBias_dph);
        EXPECT_TRUE(std::isfinite(out)) << Ti0 << " " << Ti << " " << Tj;
        EXPECT_LE(std::abs(out), 11 * sim::limits::kMaxAbsBias_dph);  // bias, B0 and nine terms at most
      }
    }
  }
}

}  // namespace
}  // namespace rlg::model

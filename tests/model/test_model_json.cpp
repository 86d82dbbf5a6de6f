// One coefficient file for every model (model/coefficients_json.h): a polynomial model survives
// writing and reading, Eq. (2) files are read as they always were, and malformed or implausible
// polynomial files are refused naming the file, the line, the key and what was expected.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "compensation/model_compensator.h"
#include "model/coefficients_json.h"
#include "model/poly_fit.h"
#include "sim/errors.h"
#include "sim/limits.h"
#include "tests/model/poly_truth.h"
#include "tools/source_dir.h"

namespace rlg::model {
namespace {

PolyModel Fitted() {
  sim::Run run = CycleRun("cycle");
  const std::vector<const sim::Run*> runs{&run};
  PolySpec spec = SpecFor(runs, 2, OffsetRule::kPowerOn, {{TermKind::kHysteresis, "", 0.0, 2.0, {}}, {TermKind::kGradient, "T2", 0.0, 0.0, {}}});
  Eigen::VectorXd beta(4);
  beta << 1.2, -0.01, 0.5, 0.2;
  boost::random::mt19937_64 rng(3);
  DrawBias(run, spec, beta, 10.0, Ar1{0.01, 0.0}, rng);
  PolyFitOptions o;
  o.order = 2;
  o.offset = OffsetRule::kPowerOn;
  o.terms = {"hysteresis", "gradient:T2", "rate", "lag"};
  return FitPoly(runs, o);
}

/// A model with products (one with a rate factor) that extrapolates beyond its range.
PolyModel FittedWithProducts() {
  sim::Run run = CycleRun("cycle");
  const std::vector<const sim::Run*> runs{&run};
  PolySpec spec = SpecFor(runs, 2, OffsetRule::kFitted, {{TermKind::kGradient, "T2", 0.0, 0.0, {}}});
  Eigen::VectorXd beta(4);
  beta << 1.0, 0.02, -1e-4, 0.3;
  boost::random::mt19937_64 rng(4);
  DrawBias(run, spec, beta, 0.0, Ar1{0.01, 0.0}, rng);
  PolyFitOptions o;
  o.order = 2;
  o.terms = {"gradient:T2", "T1*(T2-T1)", "rate(T2-T1)", "T1*rate(T1)"};
  o.extrapolate = true;
  return FitPoly(runs, o);
}

/// A valid polynomial file, one key per line (so each key has its own line).
std::string File(const std::string& order = "3", const std::string& offset = "\"fitted\"",
                 const std::string& terms = "[]", const std::string& c1 = "1.5", const std::string& extra = "") {
  return "{\n"
         "  \"model\": \"poly\",\n"
         "  \"channel\": \"T1\",\n"
         "  \"order\": " + order + ",\n"
         "  \"offset\": " + offset + ",\n"
         "  \"reference_C\": 25,\n"
         "  \"range_C\": [-10, 60],\n"
         "  \"terms\": " + terms + ",\n"
         "  \"coefficients\": [\n"
         "    {\"name\": \"c0\", \"value\": 30},\n"
         "    {\"name\": \"c1\", \"value\": " + c1 + "},\n"
         "    {\"name\": \"c2\", \"value\": -0.02},\n"
         "    {\"name\": \"c3\", \"value\": 3e-4}\n"
         "  ]" + extra + "\n"
         "}\n";
}

std::string ErrorOf(const std::string& text) {
  try {
    ParseModel(text, "c.json");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError for\n" << text;
  return "";
}

TEST(ModelJson, APolynomialModelWithEveryTermSurvivesWritingAndReading) {
  const PolyModel m = Fitted();
  const FittedModel back = ParseModel(ModelToJson(m).dump(2), "back.json");
  ASSERT_TRUE(std::holds_alternative<PolyModel>(back));
  const PolyModel& b = std::get<PolyModel>(back);
  EXPECT_EQ(ToJson(b), ToJson(m));  // every key, every double (nlohmann writes the shortest exact text)
  EXPECT_EQ(b.spec.terms.size(), 4u);
  EXPECT_EQ(b.coefficients.size(), 6u);  // c1, c2 and four terms (no constant with a power-on offset)
  EXPECT_EQ(b.spec.b0_window_s, 120.0);
  // The same compensation from the file as from the fit.
  sim::Run run = CycleRun("cycle");
  run.columns[2].assign(run.size(), 3.0);
  EXPECT_EQ(compensation::CompensateRun(FittedModel(m), run), compensation::CompensateRun(back, run));
}

TEST(ModelJson, Eq2FilesAreReadAsTheyAlwaysWereWithOrWithoutTheModelKey) {
  const std::string eq2 = "{\n  \"model\": \"guo2006\",\n  \"pair\": [\"T1\", \"T2\"],\n  \"B0_window_s\": 120,\n"
                          "  \"A\": [[0.01, 1e-4, 1e-6], [1e-4, 1e-6, 1e-8], [0.4, 1e-3, 1e-5]],\n"
                          "  \"T10_range_C\": [-30, 60]\n}\n";
  const FittedModel m = ParseModel(eq2, "c.json");
  ASSERT_TRUE(std::holds_alternative<Guo2006Coefficients>(m));
  EXPECT_EQ(ToJson(std::get<Guo2006Coefficients>(m)), ToJson(ParseCoefficients(eq2, "c.json")));
  std::string without = eq2;
  without.erase(without.find("  \"model\""), std::string("  \"model\": \"guo2006\",\n").size());
  EXPECT_EQ(ToJson(std::get<Guo2006Coefficients>(ParseModel(without, "c.json"))), ToJson(ParseCoefficients(eq2, "c.json")));
  // The repository's own Eq. (2) files, as the fuzzer's corpus keeps them.
  for (const char* name : {"fit_joint.json", "hand_made.json", "bom_minimal.json"}) {
    const std::string path = rlg::tools::SourcePath("tests/fuzz/corpus/coefficients/") + name;
    EXPECT_EQ(ToJson(std::get<Guo2006Coefficients>(ReadModelFile(path))), ToJson(ReadCoefficientsFile(path))) << name;
  }
}

TEST(ModelJson, EveryKeyTheLibraryWritesIsReadAndAnyOtherIsRefusedWithTheKeyItMisspells) {
  // Eq. (2) as fit writes it (intervals, their degrees of freedom and method included), and a
  // polynomial with products, extrapolation and an auto selection record: read back whole.
  Guo2006Coefficients eq2 = ParseCoefficients(
      "{\"pair\": [\"T1\", \"T2\"], \"B0_window_s\": 120, \"A\": [[0.01, 1e-4, 1e-6], [1e-4, 1e-6, 1e-8], "
      "[0.4, 1e-3, 1e-5]], \"T10_range_C\": [-30, 60]}", "c.json");
  eq2.stderr_dof.setConstant(7.0);
  eq2.stderr_method = "within_run_white";
  const nlohmann::json eq2_json = ToJson(eq2);
  ASSERT_TRUE(eq2_json.contains("A_ci95_halfwidth") && eq2_json.contains("A_stderr_dof"));
  EXPECT_NO_THROW(ParseModel(eq2_json.dump(2), "eq2.json"));
  PolyModel poly = FittedWithProducts();
  SelectionRecord selection;
  selection.rule = "the rule";
  selection.folds = 3;
  selection.steps = {{"order 2, fitted", 0.5, true, "start", 3}, {"order 2, fitted + rate", 0.6, false, "+ rate", 4}};
  poly.selection = selection;
  const nlohmann::json poly_json = ModelToJson(poly);
  const FittedModel back = ParseModel(poly_json.dump(2), "poly.json");
  EXPECT_EQ(ModelToJson(back), poly_json);
  // "modell": read as Eq. (2) before (the model key absent) and refused for its missing pair;
  // now the key is named, with the one it misspells, at its line.
  EXPECT_NE(ErrorOf("{\n  \"modell\": \"guo2006\",\n  \"pair\": [\"T1\", \"T2\"]\n}\n")
                .find("c.json:2: unknown key 'modell'; did you mean 'model'? (a coefficients file as 'rlgtherm fit -o' "
                      "writes it)"),
            std::string::npos);
  nlohmann::json typo = eq2_json;
  typo["T10_range"] = typo["T10_range_C"];
  typo.erase("T10_range_C");
  EXPECT_NE(ErrorOf(typo.dump(2)).find("unknown key 'T10_range'; did you mean 'T10_range_C'?"), std::string::npos);
  nlohmann::json product_typo = poly_json;
  product_typo["terms"][1]["nmae"] = product_typo["terms"][1]["name"];
  product_typo["terms"][1].erase("name");
  EXPECT_NE(ErrorOf(product_typo.dump(2)).find("unknown key 'nmae' in terms[1]; did you mean 'name'?"), std::string::npos);
  nlohmann::json beyond_typo = poly_json;
  beyond_typo["beyond"] = "extrapolate";
  EXPECT_NE(ErrorOf(beyond_typo.dump(2)).find("unknown key 'beyond'; did you mean 'beyond_range'?"), std::string::npos);
}

TEST(ModelJson, MalformedPolynomialFilesNameFileLineKeyAndWhatWasExpected) {
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {File("6"), "c.json:4: key 'order': expected an integer 1 to 5, found 6"},
      {File("2.5"), "c.json:4: key 'order': expected an integer 1 to 5, found 2.5"},
      {File("3", "\"absolute\""), "c.json:5: key 'offset': expected \"fitted\" or \"power_on\", found \"absolute\""},
      {File("3", "\"power_on\""), "c.json: key 'B0_window_s': missing"},
      {File("3", "\"fitted\"", "[{\"term\": \"wobble\"}]"), "c.json:8: key 'terms': terms[0]: expected {\"term\": \"rate\""},
      {File("3", "\"fitted\"", "[{\"term\": \"lag\", \"tau_s\": -5}]"), "terms[0]: tau_s = -5 is outside 0.001...1e+06"},
      {File("3", "\"fitted\"", "[{\"term\": \"gradient\", \"channel\": \"T1\"}]"), "terms[0]: a gradient to the model's own channel T1"},
      {File("3", "\"fitted\"", "[{\"term\": \"hysteresis\", \"width_C\": 0}]"), "terms[0]: width_C = 0 is outside 0...230"},
      {File("3", "\"fitted\"", "[{\"term\": \"rate\", \"tau_s\": 5}]"), "c.json:9: key 'coefficients': expected 5 coefficients (c0, c1, c2, c3, rate), found 4"},
      {File("3", "\"fitted\"", "[]", "\"x\""), "c.json:11: key 'coefficients': coefficients[1]: 'c1': value must be a number"},
      {File("3", "\"fitted\"", "[]", "1e300"), "c.json:11: key 'coefficients': coefficients[1]: 'c1' = 1e+300 is outside -43478.3...43478.3"},
      {File("3", "\"fitted\"", "[]", "1.5, \"dof\": 1e-300"), "c.json:11: key 'coefficients': coefficients[1]: 'c1': dof = 1e-300: expected 0 (none) or 1...1e9"},
      // A key the file does not know is refused, naming the key it misspells (the nearest in a
      // table of them first) or, when it misspells none, the keys expected there.
      {File("3", "\"fitted\"", "[]", "1.5", ",\n  \"range_C_typo\": 1,\n  \"range\": [60, -10]"),
       "c.json:16: unknown key 'range'; did you mean 'range_C'?"},
      {File("3", "\"fitted\"", "[]", "1.5", ",\n  \"note\": \"mine\""),
       "c.json:15: unknown key 'note'; expected model, preset, channel, order, offset, reference_C, range_C"},
      {File("3", "\"fitted\"", "[{\"term\": \"lag\",\n  \"tau\": 5}]"), "c.json:9: unknown key 'tau' in terms[0]; did you mean 'tau_s'?"},
      {File("3", "\"fitted\"", "[]", "1.5, \"stderror\": 0.1"), "c.json:11: unknown key 'stderror' in coefficients[1]; did you mean 'stderr'?"},
      {File("3", "\"fitted\"", "[{\"term\": \"product\", \"factors\": [{\"channel\": \"T2\", \"minsu\": \"T1\", \"range\": [0, 1]}]}]"),
       "c.json:8: unknown key 'minsu' in terms[0].factors; did you mean 'minus'?"},
      {File("3", "\"fitted\"", "[]", "1.5", ",\n  \"selection\": {\"rule\": \"r\", \"fold\": 3, \"steps\": []}"),
       "c.json:15: unknown key 'fold' in selection; did you mean 'folds'?"},
      {File("2"), "key 'coefficients': expected 3 coefficients (c0, c1, c2), found 4"},
      {"{\n  \"model\": \"polynomial\"\n}\n", "c.json:2: key 'model': expected \"guo2006\" or \"poly\", found \"polynomial\""},
  };
  for (const auto& c : cases) {
    const std::string m = ErrorOf(c.text);
    EXPECT_NE(m.find(c.expect), std::string::npos) << "got: " << m << "\nwanted: " << c.expect;
  }
  std::string swapped = File();
  swapped.replace(swapped.find("\"c2\""), 4, "\"c9\"");
  const std::string m = ErrorOf(swapped);
  EXPECT_NE(m.find("c.json:12: key 'coefficients': coefficients[2]: expected {\"name\": \"c2\""), std::string::npos) << m;
}

TEST(ModelJson, ProductTermsAndExtrapolationSurviveWritingAndReading) {
  const PolyModel m = FittedWithProducts();
  const nlohmann::json j = ModelToJson(m);
  EXPECT_EQ(j["beyond_range"], "extrapolate");
  EXPECT_EQ(j["terms"][1]["term"], "product");
  EXPECT_EQ(j["terms"][1]["name"], "T1*(T2-T1)");
  const FittedModel back = ParseModel(j.dump(2), "back.json");
  const PolyModel& b = std::get<PolyModel>(back);
  EXPECT_EQ(ToJson(b), ToJson(m));
  EXPECT_TRUE(b.spec.extrapolate);
  sim::Run run = CycleRun("cycle", 2.0, 1.0, 0.7);
  run.columns[2].assign(run.size(), 3.0);
  EXPECT_EQ(compensation::CompensateRun(FittedModel(m), run), compensation::CompensateRun(back, run));
  // A product whose factors are out of their canonical order, or a name that contradicts them,
  // is refused with the key's line.
  nlohmann::json swapped = j;
  std::swap(swapped["terms"][1]["factors"][0], swapped["terms"][1]["factors"][1]);
  swapped["terms"][1].erase("name");
  EXPECT_NE(ErrorOf(swapped.dump(2)).find("canonical order"), std::string::npos);
  nlohmann::json renamed = j;
  renamed["terms"][1]["name"] = "T1*(T3-T1)";
  EXPECT_NE(ErrorOf(renamed.dump(2)).find("does not match its factors"), std::string::npos);
  nlohmann::json beyond = j;
  beyond["beyond_range"] = "wrap";
  EXPECT_NE(ErrorOf(beyond.dump(2)).find("expected \"hold\" or \"extrapolate\""), std::string::npos);
}

TEST(ModelJson, AcceptedPolynomialsAtTheirLimitsCompensateToFiniteValues) {
  // Every coefficient at the largest magnitude accepted, at the corners of the temperature
  // range, rates far beyond 100 °C/min and the bias limit: the compensated bias stays finite.
  PolyModel m;
  m.spec.order = 5;
  m.spec.reference_C = sim::limits::kMinTemperature_C;
  m.spec.range_C = {sim::limits::kMinTemperature_C, sim::limits::kMaxTemperature_C};
  m.spec.terms = {{TermKind::kRate, "", 1e-3, 0.0, {}}, {TermKind::kHysteresis, "", 0.0, 230.0, {}}, {TermKind::kLag, "", 1e-3, 0.0, {}},
                  {TermKind::kGradient, "T2", 0.0, 0.0, {}}};
  for (const auto& name : m.spec.CoefficientNames()) {
    Coefficient c;
    c.name = name;
    c.value = name == "c0" ? 1e7 : name == "rate" ? sim::limits::kMaxBiasPerRate
                            : name.size() == 2 ? 1e7 / std::pow(230.0, name[1] - '0') : sim::limits::kMaxBiasPerC;
    m.coefficients.push_back(c);
  }
  const PolyModel back = std::get<PolyModel>(ParseModel(ToJson(m).dump(), "limits.json"));
  compensation::ModelCompensator comp{FittedModel(back)};
  double t = 0.0;
  for (const double T1 : {-80.0, 150.0, -80.0, 150.0}) {
    for (const double T2 : {-80.0, 150.0}) {
      const double T[2] = {T1, T2};
      const double out = comp.Update(t, T, sim::limits::kMaxAbsBias_dph);
      t += 1e-3;  // the shortest sample period: 230 °C in 1 ms is 1.4e7 °C/min
      EXPECT_TRUE(std::isfinite(out)) << T1 << " " << T2;
    }
  }
}

}  // namespace
}  // namespace rlg::model

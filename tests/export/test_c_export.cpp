// The C code generator (compensation/c_export.h) without a C compiler: its options, what the
// files name and promise, the constants it embeds, and that bad input never reaches a file.
// Compiling and running the code against the library: c_code.sh (tests/export/CMakeLists.txt).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "compensation/c_export.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"

namespace rlg::compensation {
namespace {

// A cubic in T1 with every term, as `rlgtherm fit` writes it (coefficients made up, within the
// reader's limits).
constexpr const char* kPolyJson = R"({"model": "poly", "channel": "T1", "order": 3, "offset": "power_on",
  "reference_C": 20.5, "range_C": [-17.6, 73.9], "B0_window_s": 120,
  "terms": [{"term": "hysteresis", "width_C": 2.25}, {"term": "rate", "tau_s": 5.05},
            {"term": "lag", "tau_s": 2122.4}, {"term": "gradient", "channel": "T2"}],
  "coefficients": [{"name": "c1", "value": -1.3044581914096518}, {"name": "c2", "value": 0.018118289819001324},
                   {"name": "c3", "value": 0.000356628320690543}, {"name": "hysteresis", "value": -3.7629366875758437},
                   {"name": "rate", "value": 0.2798817082248675}, {"name": "lag", "value": -1.702629710536593},
                   {"name": "gradient_T2", "value": 0.1}]})";
constexpr const char* kEq2Json = R"({"model": "guo2006", "pair": ["T1", "T2"], "B0_window_s": 120,
  "A": [[-0.005862900579674986, -0.0004937177518351579, 2.584222884745949e-06],
        [0.04495554495316836, -0.00042225617229852167, 1.698373244623147e-05],
        [0.3327041361226963, 0.003101977317944976, -4.5101155942615734e-05]],
  "T10_range_C": [-30, 50], "method": "joint"})";

// A quadratic with the products of the export tests (tests/export/setup.sh) and a rate term, as
// `rlgtherm fit` writes it (coefficients made up); held at the fitted ranges or extrapolating.
constexpr const char* kProductsJson = R"json({"model": "poly", "channel": "T1", "order": 2, "offset": "fitted",
  "reference_C": 10.765, "range_C": [-30.0, 51.53], "beyond_range": "BEYOND",
  "terms": [{"term": "rate", "tau_s": 10.0},
            {"term": "product", "factors": [{"channel": "T1", "range": [-30.0, 51.53]},
                                            {"channel": "T2", "minus": "T1", "range": [-0.01, 1.03]}]},
            {"term": "product", "factors": [{"channel": "T2", "minus": "T1", "range": [-0.01, 1.03]},
                                            {"channel": "T2", "minus": "T1", "range": [-0.01, 1.03]}]},
            {"term": "product", "tau_s": 10.0,
             "factors": [{"channel": "T2", "minus": "T1", "rate": true, "range": [-0.123, 0.144]}]},
            {"term": "product", "tau_s": 5.0, "factors": [{"channel": "T1", "range": [-30.0, 51.53]},
                                                           {"channel": "T1", "rate": true, "range": [-0.085, 0.133]}]}],
  "coefficients": [{"name": "c0", "value": 0.927}, {"name": "c1", "value": 0.0075}, {"name": "c2", "value": -8.3e-05},
                   {"name": "rate", "value": -0.099}, {"name": "T1*(T2-T1)", "value": 0.00167},
                   {"name": "(T2-T1)^2", "value": 0.3715}, {"name": "rate(T2-T1)", "value": -0.0248},
                   {"name": "T1*rate(T1)", "value": -0.000246}]})json";

model::FittedModel Poly() { return model::ParseModel(kPolyJson, "poly.json"); }
model::FittedModel Products(const std::string& beyond_range = "hold") {
  std::string json = kProductsJson;
  json.replace(json.find("BEYOND"), 6, beyond_range);
  return model::ParseModel(json, "products.json");
}
model::FittedModel Eq2() { return model::ParseModel(kEq2Json, "eq2.json"); }

CExportOptions Options(CPrecision precision = CPrecision::kDouble, const std::string& prefix = "rlg_comp") {
  CExportOptions o;
  o.precision = precision;
  o.prefix = prefix;
  o.source = "coeffs.json";
  return o;
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(CExportOptions, AcceptTheDefaultPrefixAndRefuseNamesThatAreNotShortCIdentifiers) {
  std::string error;
  EXPECT_TRUE(CExportOptions{}.IsValid(&error)) << error;
  EXPECT_TRUE(Options(CPrecision::kFloat, "gyro_x2").IsValid(&error)) << error;
  for (const std::string& bad : std::vector<std::string>{"", "2gyro", "_gyro", "gyro-x", "gyro x", "gyro_", "g\xc3\xa4", std::string(25, 'g')}) {
    error.clear();
    EXPECT_FALSE(Options(CPrecision::kDouble, bad).IsValid(&error)) << bad;
    EXPECT_TRUE(Contains(error, "--prefix '" + bad + "'")) << error;
  }
  EXPECT_TRUE(Options(CPrecision::kDouble, std::string(24, 'g')).IsValid(&error)) << error;  // 24 + "_update" = 31
  EXPECT_THROW(ExportC(Eq2(), Options(CPrecision::kDouble, "a-b")), InputError);
}

TEST(CExport, TheHeaderListsTheChannelsInTheCompensatorsOrderAndNamesEverythingWithThePrefix) {
  const CCode code = ExportC(Poly(), Options(CPrecision::kDouble, "imu_x"));
  EXPECT_EQ(code.header_name, "imu_x.h");
  EXPECT_EQ(code.source_name, "imu_x.c");
  for (const char* part : {"#define IMU_X_CHANNELS 2\n", "/*   T_C[0]: T1 (T, the polynomial's channel) */",
                           "/*   T_C[1]: T2 (a gradient's channel) */", "#define IMU_X_CHANNEL_NAMES { \"T1\", \"T2\" }",
                           "#define IMU_X_B0_WINDOW_S 120.0", "#ifndef IMU_X_H", "} imu_x_state;",
                           "void imu_x_init(imu_x_state *s);",
                           "double imu_x_update(imu_x_state *s, double t_s, const double *T_C, double bias_dph);",
                           "from\n *   coeffs.json\n"}) {
    EXPECT_TRUE(Contains(code.header, part)) << part << "\n" << code.header;
  }
  EXPECT_TRUE(Contains(code.source, "#include \"imu_x.h\""));
  EXPECT_FALSE(Contains(code.header + code.source, "rlg_comp"));
}

TEST(CExport, TheHeaderStatesUnitsWindowFirstSampleAndWhatHappensOutsideTheFittedRange) {
  const CCode eq2 = ExportC(Eq2(), Options()), poly = ExportC(Poly(), Options());
  for (const std::string& h : {eq2.header, poly.header}) {
    EXPECT_TRUE(Contains(h, "Units: time t_s in s, temperatures in degC, bias in deg/h.")) << h;
    EXPECT_TRUE(Contains(h, "B0 window: while t_s < t_first + RLG_COMP_B0_WINDOW_S (120 s)")) << h;
    EXPECT_TRUE(Contains(h, "captured at the first sample") || Contains(h, "Captured at the first sample")) << h;
    EXPECT_TRUE(Contains(h, "s->outside_range is 1")) << h;
    // Any gyro's: a polynomial fitted to a FOG or a MEMS IMU is no ring laser gyro.
    EXPECT_TRUE(Contains(h, "h: causal compensation of a gyro's thermal bias:\n")) << h;
    EXPECT_FALSE(Contains(h, "ring laser")) << h;
  }
  EXPECT_TRUE(Contains(eq2.header, "Ti0 = -30 ... 50 degC")) << eq2.header;
  EXPECT_TRUE(Contains(eq2.header, "nothing is\n * clamped")) << eq2.header;
  EXPECT_TRUE(Contains(poly.header, "[T_min, T_max] = [-17.6, 73.9] degC")) << poly.header;
  EXPECT_TRUE(Contains(poly.header, "the polynomial is held at the range's edge")) << poly.header;
}

TEST(CExport, OnlyRateAndLagTermsNeedLibmAndFloatCodeCallsTheFloatFunction) {
  EXPECT_FALSE(Contains(ExportC(Eq2(), Options()).source, "math.h"));
  const std::string px4 = R"({"model": "poly", "channel": "T1", "order": 3, "offset": "fitted", "reference_C": 28,
    "range_C": [-17, 73], "terms": [{"term": "hysteresis", "width_C": 2}],
    "coefficients": [{"name": "c0", "value": -251}, {"name": "c1", "value": 0.68}, {"name": "c2", "value": 0.02},
                     {"name": "c3", "value": -0.0002}, {"name": "hysteresis", "value": -3.7}]})";
  EXPECT_FALSE(Contains(ExportC(model::ParseModel(px4, "px4.json"), Options()).source, "math.h"));
  const CCode d = ExportC(Poly(), Options()), f = ExportC(Poly(), Options(CPrecision::kFloat));
  EXPECT_TRUE(Contains(d.source, "#include <math.h>") && Contains(d.source, "expm1(") && !Contains(d.source, "expm1f"));
  EXPECT_TRUE(Contains(f.source, "#include <math.h>") && Contains(f.source, "expm1f(")) << f.source;
  EXPECT_TRUE(Contains(d.header, "Needs expm1 from libm")) << d.header;
  EXPECT_TRUE(Contains(f.header, "Needs expm1f from libm")) << f.header;
}

// Every floating literal of the code (digits with a '.' or an exponent).
std::vector<std::string> Literals(const std::string& code) {
  std::vector<std::string> out;
  // Comments first: they hold numbers in words.
  const std::string bare = std::regex_replace(code, std::regex(R"(/\*[\s\S]*?\*/)"), " ");
  const std::regex number(R"((^|[^\w.])(-?[0-9]+\.[0-9]*(e[-+]?[0-9]+)?f?|-?[0-9]+e[-+]?[0-9]+f?))");
  for (auto it = std::sregex_iterator(bare.begin(), bare.end(), number); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[2]);
  return out;
}

TEST(CExport, FloatCodeHasOnlyFloatLiteralsAndNoDoubleAndDoubleCodeNoFloat) {
  for (const auto& m : std::vector<model::FittedModel>{Eq2(), Poly(), Products(), Products("extrapolate")}) {
    const CCode f = ExportC(m, Options(CPrecision::kFloat)), d = ExportC(m, Options());
    EXPECT_FALSE(std::regex_search(f.header + f.source, std::regex(R"(\bdouble\b)")));
    EXPECT_FALSE(std::regex_search(d.header + d.source, std::regex(R"(\bfloat\b)")));
    const auto fl = Literals(f.header + f.source), dl = Literals(d.header + d.source);
    ASSERT_GT(fl.size(), 5u);
    ASSERT_GT(dl.size(), 5u);
    for (const auto& l : fl) EXPECT_EQ(l.back(), 'f') << l;
    for (const auto& l : dl) EXPECT_NE(l.back(), 'f') << l;
  }
}

TEST(CExport, TheEmbeddedConstantsReadBackToTheFittedValuesOrTheirNearestFloat) {
  const model::FittedModel poly = Poly();
  const auto& p = std::get<model::PolyModel>(poly);
  for (CPrecision precision : {CPrecision::kDouble, CPrecision::kFloat}) {
    const std::string src = ExportC(Poly(), Options(precision)).source;
    const auto begin = src.find("BETA[7] = {");
    ASSERT_NE(begin, std::string::npos) << src;
    const std::vector<std::string> lits = Literals(src.substr(begin, src.find("};", begin) - begin));
    ASSERT_EQ(lits.size(), p.coefficients.size());
    for (size_t i = 0; i < lits.size(); ++i) {
      const double v = p.coefficients[i].value;
      if (precision == CPrecision::kDouble) {
        EXPECT_EQ(std::stod(lits[i]), v) << lits[i];  // exact: the shortest text that reads back
      } else {
        EXPECT_EQ(std::stof(lits[i]), static_cast<float>(v)) << lits[i];  // exact: the float nearest v
      }
    }
  }
}

TEST(CExport, ChannelNamesOfAnyBytesCannotEndAComment) {
  auto m = std::get<model::PolyModel>(Poly());
  m.spec.terms.back().channel = "T*/ \"x\"\\ \xc2\xb0?\n";
  const CCode code = ExportC(model::FittedModel(m), Options());
  for (unsigned char ch : code.header + code.source) EXPECT_LT(ch, 0x80);
  // The only "*/" are the ends of comments: each one closes a "/*" opened on or before its line.
  const std::string all = code.header + code.source;
  size_t open = 0, close = 0;
  for (size_t i = 0; i + 1 < all.size(); ++i) {
    if (all.compare(i, 2, "/*") == 0) ++open;
    if (all.compare(i, 2, "*/") == 0) {
      ++close;
      EXPECT_EQ(open, close) << all.substr(i > 60 ? i - 60 : 0, 120);
    }
  }
  EXPECT_TRUE(Contains(code.header, R"("T\052/ \"x\"\\ \302\260\?\012")")) << code.header;  // the literal, escaped
  EXPECT_FALSE(Contains(all, "??"));  // no trigraph
}

TEST(CExport, EachProductIsWrittenWithItsFormulaAndItsFactorsRangesInTheHeader) {
  const CCode code = ExportC(Products(), Options());
  for (const char* part : {" *   T1*(T2-T1)  (T1 - T_ref) (T2 - T1)\n",
                           "fitted ranges: T1 in [-30, 51.53] degC, T2 - T1 in [-0.01, 1.03] degC\n",
                           " *   (T2-T1)^2   (T2 - T1) (T2 - T1)\n", "fitted range: T2 - T1 in [-0.01, 1.03] degC\n",
                           " *   rate(T2-T1) r(T2 - T1), tau_r = 10 s\n",
                           "fitted range: r(T2 - T1) in [-0.123, 0.144] degC/min\n",
                           " *   T1*rate(T1) (T1 - T_ref) r(T1), tau_r = 5 s\n",
                           "*     r += (1 - exp(-dt / tau_r)) (60 (S - S_prev) / dt - r)\n",
                           "/*   T_C[1]: T2 (a product's channel) */"}) {
    EXPECT_TRUE(Contains(code.header, part)) << part << "\n" << code.header;
  }
  for (const std::string& text : {code.header, code.source}) {
    for (unsigned char ch : text) EXPECT_LT(ch, 0x80);
  }
}

TEST(CExport, EachRateFactorHasItsOwnLowPassAndEachTimeConstantOneExpm1) {
  const CCode code = ExportC(Products(), Options());
  // Two rate factors (rate(T2-T1), and rate(T1) of T1*rate(T1)) besides the rate term.
  EXPECT_TRUE(Contains(code.header, "double factor_prev_C[2];")) << code.header;
  EXPECT_TRUE(Contains(code.header, "double factor_rate_C_per_min[2];")) << code.header;
  for (const char* part : {"  S[0] = T_C[1] - T_C[0];\n", "  S[1] = T_C[0];\n",
                           "static const double RATE_TAU_S = 10.0;", "static const double RATE_TAU2_S = 5.0;",
                           "const double rate_gain = -expm1(-dt / RATE_TAU_S);",
                           "const double rate_gain2 = -expm1(-dt / RATE_TAU2_S);",
                           "s->rate_C_per_min += rate_gain * (difference - s->rate_C_per_min);",
                           "rate_gain * (60.0 * (S[0] - s->factor_prev_C[0]) / dt - s->factor_rate_C_per_min[0]);",
                           "rate_gain2 * (60.0 * (S[1] - s->factor_prev_C[1]) / dt - s->factor_rate_C_per_min[1]);",
                           "  g[4] = (f[0] - T_REF_C) * f[1]; /* T1*(T2-T1) */", "  g[5] = f[2] * f[3]; /* (T2-T1)^2 */",
                           "  g[6] = f[4]; /* rate(T2-T1) */", "  g[7] = (f[5] - T_REF_C) * f[6]; /* T1*rate(T1) */"}) {
    EXPECT_TRUE(Contains(code.source, part)) << part << "\n" << code.source;
  }
  // One expm1 per time constant (10 s: the rate term's and rate(T2-T1)'s; 5 s: rate(T1)'s).
  const std::regex expm1(R"(expm1\()");
  const auto calls = std::distance(std::sregex_iterator(code.source.begin(), code.source.end(), expm1),
                                   std::sregex_iterator());
  EXPECT_EQ(calls, 2);
}

TEST(CExport, HeldCodeClampsTAndTheFactorsAndExtrapolatingCodeNeitherButFlagsBoth) {
  const CCode held = ExportC(Products(), Options()), extrapolating = ExportC(Products("extrapolate"), Options());
  EXPECT_TRUE(Contains(held.header, "d = clamp(T, T_min, T_max) - T_ref")) << held.header;
  EXPECT_TRUE(Contains(held.header, "the polynomial is held at the range's edge")) << held.header;
  EXPECT_TRUE(Contains(held.header, "each product factor to its own fitted range")) << held.header;
  EXPECT_TRUE(Contains(held.source, "const double d = clipped - T_REF_C;")) << held.source;
  EXPECT_TRUE(Contains(held.source, "f[i] = f[i] < FACTOR_RANGE[i][0] ? FACTOR_RANGE[i][0]")) << held.source;
  EXPECT_TRUE(Contains(extrapolating.header, "d = T - T_ref")) << extrapolating.header;
  EXPECT_TRUE(Contains(extrapolating.header, "Beyond the fitted range the model extrapolates")) << extrapolating.header;
  EXPECT_TRUE(Contains(extrapolating.header, "is used as it is, beyond its fitted range too")) << extrapolating.header;
  EXPECT_TRUE(Contains(extrapolating.source, "const double d = T - T_REF_C;")) << extrapolating.source;
  EXPECT_FALSE(Contains(extrapolating.source, "clipped")) << extrapolating.source;
  EXPECT_FALSE(Contains(extrapolating.source, "f[i] = f[i] <")) << extrapolating.source;
  for (const CCode& code : {held, extrapolating}) {
    // The comment's words, whatever their line breaks.
    const std::string words = std::regex_replace(code.header, std::regex(R"(\n \*\s+)"), " ");
    EXPECT_TRUE(Contains(words, "s->outside_range is 1 when the last sample's T lay outside [T_min, T_max] or a product "
                                "factor's signal outside its fitted range"))
        << code.header;
    EXPECT_TRUE(Contains(code.source, "if (f[i] < FACTOR_RANGE[i][0] || f[i] > FACTOR_RANGE[i][1]) s->outside_range = 1;"))
        << code.source;
    // Counted once the factors have had their say.
    EXPECT_LT(code.source.find("s->outside_range = 1;"), code.source.find("if (s->outside_range) ++s->samples_outside;"));
  }
}

TEST(CExport, ProductsOfChannelsOfAnyBytesCannotEndAComment) {
  auto m = std::get<model::PolyModel>(Products());
  for (auto& t : m.spec.terms)
    for (auto& f : t.factors)
      if (!f.minus.empty()) f.channel = "T*/2";
  const CCode code = ExportC(model::FittedModel(m), Options());
  EXPECT_FALSE(Contains(code.header + code.source, "T*/")) << code.header;
  EXPECT_TRUE(Contains(code.header, "/*   T_C[1]: T_/2 (a product's channel) */")) << code.header;
  EXPECT_TRUE(Contains(code.header, "T_/2 - T1 in [-0.01, 1.03] degC")) << code.header;
}

TEST(CExport, TheSameModelGivesTheSameBytes) {
  const CCode a = ExportC(Poly(), Options()), b = ExportC(Poly(), Options());
  EXPECT_EQ(a.header, b.header);
  EXPECT_EQ(a.source, b.source);
}

TEST(WriteC, WritesBothFilesIntoTheDirectoryAndRefusesABadPrefixBeforeCreatingIt) {
  const auto dir = std::filesystem::temp_directory_path() / ("rlg_c_export_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  EXPECT_THROW(WriteC(Eq2(), (dir / "code").string(), Options(CPrecision::kDouble, "9")), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir));
  const auto written = WriteC(Eq2(), (dir / "code").string(), Options(CPrecision::kFloat, "gyro"));
  ASSERT_EQ(written.size(), 2u);
  const CCode code = ExportC(Eq2(), Options(CPrecision::kFloat, "gyro"));
  for (const auto& [path, text] : {std::pair{written[0], code.header}, std::pair{written[1], code.source}}) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    EXPECT_EQ(s.str(), text) << path;
  }
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "code"), std::filesystem::directory_iterator()), 2);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rlg::compensation

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

model::FittedModel Poly() { return model::ParseModel(kPolyJson, "poly.json"); }
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
  for (const auto& m : std::vector<model::FittedModel>{Eq2(), Poly()}) {
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

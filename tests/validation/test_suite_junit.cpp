// JUnit XML of validate's checks (compensation/suite_junit.h): structure and escaping. The
// document is parsed by a real XML parser in the CLI test cli.validate_junit.

#include <gtest/gtest.h>

#include <string>

#include "validation/suite.h"
#include "validation/suite_junit.h"

namespace rlg::validation {

namespace {

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

SuiteReport TwoChecks() {
  SuiteReport rep;
  Check ok;
  ok.name = "stability 100s";
  ok.run = "fixed+0";
  ok.passed = true;
  ok.detail = "at 100 s: after 0.0042 <= 0.01 °/h, the limit written (before 0.0300)";
  ok.value = 0.0042;
  ok.limit = 0.01;
  ok.unit = "°/h";
  Check failed;
  failed.name = "best pair";
  failed.detail = "M2 (SSE_ave 2.1000), expected M1";
  rep.checks = {ok, failed};
  return rep;
}

TEST(SuiteJunit, WritesOneTestcasePerCheckAndAFailureOnlyForTheFailedOne) {
  const std::string xml = SuiteJunitXml(TwoChecks(), "paper-suite");
  EXPECT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n", 0), 0u);
  EXPECT_NE(xml.find("<testsuites name=\"rlgtherm validate\" tests=\"2\" failures=\"1\">"), std::string::npos);
  EXPECT_EQ(Count(xml, "<testcase "), 2u);
  EXPECT_EQ(Count(xml, "<failure "), 1u);
  EXPECT_NE(xml.find("name=\"best pair\">\n      <failure message=\"M2 (SSE_ave 2.1000), expected M1\""), std::string::npos);
  EXPECT_NE(xml.find("classname=\"rlgtherm.paper-suite.eq2\" name=\"stability 100s fixed+0\""), std::string::npos);
}

TEST(SuiteJunit, NumericChecksCarryValueLimitAndUnitAsProperties) {
  const std::string xml = SuiteJunitXml(TwoChecks(), "s");
  EXPECT_NE(xml.find("<property name=\"value\" value=\"0.0042\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<property name=\"limit\" value=\"0.01\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<property name=\"unit\" value=\"°/h\"/>"), std::string::npos);
  EXPECT_EQ(Count(xml, "<properties>"), 1u);  // the best-pair check has no numbers
}

TEST(SuiteJunit, EscapesMarkupAndReplacesCharactersXmlForbids) {
  EXPECT_EQ(XmlEscape("a<b&c>\"d'"), "a&lt;b&amp;c&gt;&quot;d&apos;");
  EXPECT_EQ(XmlEscape("x\x01y\tz"), "x\xEF\xBF\xBDy\tz");
  EXPECT_EQ(XmlEscape("°/h"), "°/h");  // UTF-8 passes
  SuiteReport rep = TwoChecks();
  rep.checks[0].run = "a<&b";
  rep.checks[1].detail = "</failure><x>";
  const std::string xml = SuiteJunitXml(rep, "s&t");
  EXPECT_EQ(xml.find("a<&b"), std::string::npos);
  EXPECT_EQ(xml.find("</failure><x>"), std::string::npos);
  EXPECT_NE(xml.find("name=\"stability 100s a&lt;&amp;b\""), std::string::npos);
  EXPECT_NE(xml.find("<testsuite name=\"s&amp;t\""), std::string::npos);
}

}  // namespace
}  // namespace rlg::validation

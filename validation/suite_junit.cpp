#include "validation/suite_junit.h"

#include <algorithm>
#include <fmt/format.h>
#include <iterator>

namespace rlg::validation {

std::string XmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        // Bytes >= 0x80 are UTF-8 sequences, passed on; C0 controls other than tab, LF and CR
        // (and DEL, allowed but invisible) cannot appear in XML 1.0 even as references.
        if ((u < 0x20 && ch != '\t' && ch != '\n' && ch != '\r') || u == 0x7f) {
          out += "\xEF\xBF\xBD";
        } else {
          out += ch;
        }
    }
  }
  return out;
}

std::string SuiteJunitXml(const SuiteReport& report, const std::string& suite_name) {
  const auto failures = std::count_if(report.checks.begin(), report.checks.end(), [](const Check& c) { return !c.passed; });
  const std::string suite = XmlEscape(suite_name);
  fmt::memory_buffer out;
  auto w = std::back_inserter(out);
  fmt::format_to(w, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
  fmt::format_to(w, "<testsuites name=\"rlgtherm validate\" tests=\"{}\" failures=\"{}\">\n", report.checks.size(), failures);
  fmt::format_to(w, "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"0\">\n", suite,
                 report.checks.size(), failures);
  for (const auto& c : report.checks) {
    const std::string name = XmlEscape(c.run.empty() ? c.name : c.name + " " + c.run);
    const std::string detail = XmlEscape(c.detail);
    fmt::format_to(w, "    <testcase classname=\"rlgtherm.{}.{}\" name=\"{}\">\n", suite, XmlEscape(c.compensator), name);
    if (c.value || c.limit || !c.warnings.empty()) {
      fmt::format_to(w, "      <properties>\n");
      if (c.value) fmt::format_to(w, "        <property name=\"value\" value=\"{}\"/>\n", *c.value);
      if (c.limit) fmt::format_to(w, "        <property name=\"limit\" value=\"{}\"/>\n", *c.limit);
      if (!c.unit.empty()) fmt::format_to(w, "        <property name=\"unit\" value=\"{}\"/>\n", XmlEscape(c.unit));
      for (const auto& warning : c.warnings) {
        fmt::format_to(w, "        <property name=\"warning\" value=\"{}\"/>\n", XmlEscape(warning));
      }
      fmt::format_to(w, "      </properties>\n");
    }
    if (!c.passed) fmt::format_to(w, "      <failure message=\"{}\" type=\"limit\">{}</failure>\n", detail, detail);
    std::string out = detail;
    for (const auto& warning : c.warnings) out += "\nwarning: " + XmlEscape(warning);
    fmt::format_to(w, "      <system-out>{}</system-out>\n", out);
    fmt::format_to(w, "    </testcase>\n");
  }
  fmt::format_to(w, "  </testsuite>\n</testsuites>\n");
  return fmt::to_string(out);
}

std::string ErrorJunitXml(const std::string& suite_name, const std::string& type, const std::string& message) {
  const std::string suite = XmlEscape(suite_name), text = XmlEscape(message);
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<testsuites name=\"rlgtherm validate\" tests=\"1\" failures=\"0\" errors=\"1\">\n"
      "  <testsuite name=\"{0}\" tests=\"1\" failures=\"0\" errors=\"1\" skipped=\"0\">\n"
      "    <testcase classname=\"rlgtherm.{0}\" name=\"configuration\">\n"
      "      <error message=\"{1}\" type=\"{2}\">{1}</error>\n"
      "    </testcase>\n"
      "  </testsuite>\n</testsuites>\n",
      suite, text, XmlEscape(type));
}

}  // namespace rlg::validation

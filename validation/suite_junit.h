#pragma once
/// The checks of a validation suite (validation/suite.h) as JUnit XML, the report format CI
/// systems read (Jenkins, GitLab, GitHub actions' test reporters):
///
///   <testsuites name="rlgtherm validate" tests="N" failures="F">
///     <testsuite name="SUITE" tests="N" failures="F" errors="0" skipped="0">
///       <testcase classname="rlgtherm.SUITE.COMPENSATOR" name="CHECK RUN">
///         <properties>   (numeric checks only)
///           <property name="value" value="V"/> <property name="limit" value="L"/>
///           <property name="unit" value="°/h"/>
///           <property name="warning" value="W"/>   (each warning of the run: Check::warnings)
///         </properties>
///         <failure message="DETAIL" type="limit">DETAIL</failure>   (failed checks only)
///         <system-out>DETAIL (and a line "warning: W" per warning)</system-out>
///       </testcase> ..
///
/// One testcase per check, in the report's order. DETAIL is the check's text (measured value,
/// limit and where the limit comes from); V and L are shortest round-trip decimals. Markup
/// characters are escaped and characters XML 1.0 does not allow are replaced by U+FFFD, so the
/// document is well-formed whatever run ids and names it carries. No time stamps or durations:
/// the same report gives the same bytes.

#include <string>

#include "validation/suite.h"

namespace rlg::validation {

/// `suite_name` names the testsuite (the suite file's stem, e.g. "paper-suite").
std::string SuiteJunitXml(const SuiteReport& report, const std::string& suite_name);

/// The JUnit file of a validate that could not run (exit 2: bad configuration or input; exit 3:
/// a fit the data cannot identify): one testcase "configuration" with an <error> of `type`
/// ("InputError", "NumericalError") carrying `message`, so that a pipeline that reads the file
/// shows why instead of finding none (or yesterday's).
///
///   <testsuites name="rlgtherm validate" tests="1" failures="0" errors="1">
///     <testsuite name="SUITE" tests="1" failures="0" errors="1" skipped="0">
///       <testcase classname="rlgtherm.SUITE" name="configuration">
///         <error message="MESSAGE" type="TYPE">MESSAGE</error>
///       </testcase> ..
std::string ErrorJunitXml(const std::string& suite_name, const std::string& type, const std::string& message);

/// `text` with &, <, >, " and ' escaped and characters XML 1.0 forbids (control characters
/// other than tab, line feed and carriage return) replaced by U+FFFD; for text and attributes.
std::string XmlEscape(const std::string& text);

}  // namespace rlg::validation

// The GoogleTest checks of hidden_effects.h: apart from the truth side (hidden_effects.cpp), which
// dump_hidden_cases uses without GoogleTest.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "tests/diagnosis/hidden_effects.h"

namespace rlg::test {

void PrintTo(const ClearCase& c, std::ostream* os) { *os << c.effect << " on " << c.target; }

void ExpectTiesAreTheAmbiguousNote(const diagnosis::Diagnosis& d) {
  for (const auto& st : d.steps) {
    std::string listed, set_aside;
    for (const auto& t : st.ties) {
      std::string& to = t.ambiguous ? listed : set_aside;
      to += fmt::format("{}{} {} ({:+.1f}, held out {:+.1f}{})", to.empty() ? "" : ", ", t.cause, t.target,
                        t.score_difference, t.heldout_difference, t.plausible ? "" : ", stand-in");
      // Ambiguous: within the band on the fit data or on the held-out data; else a stand-in
      // the data preferred by more.
      if (t.ambiguous)
        EXPECT_TRUE(std::abs(t.score_difference) < diagnosis::kTieBand || t.heldout_difference > -diagnosis::kTieBand);
      else
        EXPECT_TRUE(!t.plausible && t.score_difference >= diagnosis::kTieBand);
    }
    const std::string head = "ambiguous: within 10 score points of " + st.accepted.cause + " " + st.accepted.target +
                             " on the fit or the held-out data: ";
    const std::string aside = "set aside: the data prefer " + set_aside + " to ";
    int notes = 0, aside_notes = 0;
    for (const auto& n : st.notes) {
      if (n.rfind("ambiguous:", 0) == 0) {
        ++notes;
        EXPECT_EQ(n.substr(0, head.size() + listed.size() + 2), head + listed + "; ") << n;
      } else if (n.rfind("set aside:", 0) == 0) {
        ++aside_notes;
        EXPECT_EQ(n.substr(0, aside.size()), aside) << n;
      }
    }
    EXPECT_EQ(notes, listed.empty() ? 0 : 1) << st.accepted.cause;
    EXPECT_EQ(aside_notes, set_aside.empty() ? 0 : 1) << st.accepted.cause;
  }
}

void ExpectClearEffectFound(const ClearCase& c) {
  sim::Scenario sc = DiagnosisScenario();
  sim::ApplyEffect({c.effect, c.target, c.parameters}, sc.gyro);
  const diagnosis::Diagnosis d =
      diagnosis::Diagnose(sim::SimulateScenario(sc, sc.seed), DiagnosisScenario().gyro, diagnosis::DiagnoseOptions{});
  ASSERT_FALSE(d.steps.empty()) << "nothing accepted" << TopCandidates(d);
  const diagnosis::Candidate& got = d.steps.front().accepted;
  ASSERT_EQ(got.cause, c.effect) << TopCandidates(d);  // the parameters below exist only for the right cause
  EXPECT_TRUE(SameTarget(DiagnosisScenario().gyro, c.effect, got.target, c.target)) << got.target;
  EXPECT_NEAR(got.parameters.at(c.checked), c.parameters.at(c.checked), 0.2 * std::abs(c.parameters.at(c.checked)));
  EXPECT_GT(got.heldout_rms_ratio, 1.2);
  ExpectTiesAreTheAmbiguousNote(d);
}

}  // namespace rlg::test

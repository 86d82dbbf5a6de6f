#include "diagnosis/statistics/identifiability.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>
#include <numeric>

namespace rlg::diagnosis {

Identifiability AnalyseIdentifiability(const Eigen::MatrixXd& cov, const std::vector<KnobLabel>& knobs,
                                       double prior_sd) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov / (prior_sd * prior_sd));
  const Eigen::Index n = cov.rows();
  Identifiability out;
  out.knobs = static_cast<int>(n);
  out.prior_sd = prior_sd;
  for (Eigen::Index j = n - 1; j >= 0; --j) {  // largest posterior variance first
    const double sd_ratio = std::sqrt(std::max(0.0, eig.eigenvalues()[j]));
    if (sd_ratio < kDeterminedSdRatio) {
      ++out.determined;
      continue;
    }
    Eigen::VectorXd v = eig.eigenvectors().col(j);
    if (v.sum() < 0.0) v = -v;
    std::vector<Eigen::Index> idx(static_cast<size_t>(n));
    std::iota(idx.begin(), idx.end(), 0);
    std::sort(idx.begin(), idx.end(), [&](Eigen::Index a, Eigen::Index b) { return std::abs(v[a]) > std::abs(v[b]); });
    IdentifiabilityDirection d;
    d.sd_ratio = sd_ratio;
    bool has_gain = false, has_ambient_link = false;
    for (Eigen::Index i : idx) {
      const KnobLabel& knob = knobs[static_cast<size_t>(i)];
      d.loadings.emplace_back(knob.name, v[i]);
      if (std::abs(v[i]) < kListedLoading) continue;
      has_gain = has_gain || knob.kind == KnobKind::kGain;
      has_ambient_link = has_ambient_link || (knob.kind == KnobKind::kConductance && knob.to_ambient);
    }
    // All heat capacities, conductances and gains moving together: C dT/dt = -G T + P is
    // unchanged when C, G and P are scaled alike, so no temperature record fixes the scale.
    const double uniform = std::abs(v.sum()) / std::sqrt(static_cast<double>(n));
    if (uniform > 0.9) {
      d.reason = "a common scale of heat capacities, conductances and powers: temperatures depend only on C/G and P/G";
    } else if (has_gain && has_ambient_link) {
      d.reason = "heating power against coupling to ambient, known to be hard to separate";
    }
    out.undetermined.push_back(std::move(d));
  }
  return out;
}

std::vector<std::string> IdentifiabilityNotes(const Identifiability& id) {
  if (id.knobs == 0) return {};  // nothing was calibrated
  std::vector<std::string> notes = {fmt::format("the data determine {} of {} combinations of the knobs (posterior sd below "
                                                "half the prior's {:.3g} in log units)",
                                                id.determined, id.knobs, id.prior_sd)};
  for (const auto& d : id.undetermined) {
    std::vector<std::string> terms;
    for (const auto& [name, loading] : d.loadings) {
      if (std::abs(loading) < kListedLoading || terms.size() == 6) break;
      terms.push_back(fmt::format("{:+.2f} {}", loading, name));
    }
    notes.push_back(fmt::format("not determined by the data (posterior/prior sd {:.2f}, kept near nominal by the prior): "
                                "{}{}",
                                d.sd_ratio, fmt::join(terms, " "), d.reason.empty() ? "" : "; " + d.reason));
  }
  return notes;
}

Eigen::MatrixXd CorrelationsGivenScale(const Eigen::MatrixXd& cov) {
  const Eigen::Index k = cov.rows();
  const Eigen::MatrixXd S = 0.5 * (cov + cov.transpose());  // pseudo-inverse round-off
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(k, 1.0 / std::sqrt(static_cast<double>(k)));
  const Eigen::VectorXd Su = S * u;
  const Eigen::MatrixXd given_scale = S - Su * Su.transpose() / u.dot(Su);
  // A knob whose variance given the scale is round-off of its variance (1e-12 of it: the
  // subtraction above keeps ~16 digits) has no correlation to report: NaN, printed as null.
  // A floor instead (1e-150) divided by nothing and printed correlations of 1e110.
  Eigen::MatrixXd corr = Eigen::MatrixXd::Constant(k, k, std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index a = 0; a < k; ++a) {
    for (Eigen::Index b = 0; b < k; ++b) {
      const double va = given_scale(a, a), vb = given_scale(b, b);
      if (va > 1e-12 * std::abs(S(a, a)) && vb > 1e-12 * std::abs(S(b, b)))
        corr(a, b) = std::clamp(given_scale(a, b) / std::sqrt(va * vb), -1.0, 1.0);
    }
  }
  return corr;
}

}  // namespace rlg::diagnosis

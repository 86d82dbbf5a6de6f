#include "diagnosis/statistics/power.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/non_central_chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>

namespace rlg::diagnosis {

namespace {

double DetectionProbability(double lambda, double critical, int dof) {
  if (!(critical > 0.0)) return 1.0;
  // Far beyond the critical value the probability is 1 to double precision: chi²_k(lambda) is
  // at least (Z + sqrt(lambda))², short of sqrt(critical) with probability below Phi(-12) =
  // 2e-33. Boost's series would also fail on such a lambda (an iround overflow above ~1e9).
  if (std::sqrt(lambda) - std::sqrt(critical) > 12.0) return 1.0;
  if (!(lambda > 0.0)) return boost::math::cdf(boost::math::complement(boost::math::chi_squared(dof), critical));
  return boost::math::cdf(boost::math::complement(boost::math::non_central_chi_squared(dof, lambda), critical));
}

/// The smallest lambda where `reaches` (rising in lambda) holds, by bisection on sqrt(lambda)
/// to a relative 1e-10; infinite when it does not hold by lambda = 1e12.
template <class F>
double SmallestLambda(F reaches) {
  if (reaches(0.0)) return 0.0;
  double lo = 0.0, hi = 8.0;  // sqrt(lambda)
  while (!reaches(hi * hi)) {
    lo = hi;
    hi *= 2.0;
    if (hi > 1e6) return std::numeric_limits<double>::infinity();
  }
  while (hi - lo > 1e-10 * hi) {
    const double mid = 0.5 * (lo + hi);
    (reaches(mid * mid) ? hi : lo) = mid;
  }
  return hi * hi;
}

}  // namespace

double DetectionNoncentrality(double critical, int dof, double power) {
  return SmallestLambda([&](double lambda) { return DetectionProbability(lambda, critical, dof) >= power; });
}

double NamingNoncentrality(double critical, int dof, const std::vector<double>& rival_cosines, double power) {
  for (double rho : rival_cosines)
    if (!(std::abs(rho) < 1.0)) return std::numeric_limits<double>::infinity();
  const boost::math::normal z;
  return SmallestLambda([&](double lambda) {
    double p = DetectionProbability(lambda, critical, dof);
    for (double rho : rival_cosines) p -= boost::math::cdf(z, -std::sqrt(lambda * (1.0 - std::abs(rho)) / 2.0));
    return p >= power;
  });
}

void NameApart(std::vector<EffectPower>& powers, const std::vector<Eigen::VectorXd>& unit,
               const std::vector<double>& critical, const std::vector<int>& dof) {
  for (size_t i = 0; i < powers.size(); ++i) {
    EffectPower& e = powers[i];
    if (!(e.lambda_at_start > 0.0)) continue;
    std::vector<double> rivals;
    for (size_t j = 0; j < powers.size(); ++j) {
      if (j == i || !(powers[j].lambda_at_start > 0.0)) continue;
      rivals.push_back(std::clamp(unit[i].dot(unit[j]), -1.0, 1.0));
      if (e.rival_cause.empty() || std::abs(rivals.back()) > std::abs(e.rival_cosine)) {
        e.rival_cosine = rivals.back();
        e.rival_cause = powers[j].cause;
        e.rival_target = powers[j].target;
      }
    }
    e.named = std::abs(e.start) * std::sqrt(NamingNoncentrality(critical[i], dof[i], rivals, kPowerLevel) / e.lambda_at_start);
  }
}

}  // namespace rlg::diagnosis

#include "diagnosis/statistics/screen.h"

#include <Eigen/QR>

namespace rlg::diagnosis {

Eigen::MatrixXd KnobBasis(const Eigen::MatrixXd& J0) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(J0);
  return qr.householderQ() * Eigen::MatrixXd::Identity(J0.rows(), J0.cols());
}

std::optional<std::vector<Screening>> ScoreTests(const Eigen::MatrixXd& Q0, const Eigen::VectorXd& j,
                                                 const Eigen::MatrixXd& r) {
  const Eigen::VectorXd p = j - Q0 * (Q0.transpose() * j);
  const double pp = p.squaredNorm();
  // Round-off of the projection leaves |p| ~ 1e-16 |j| for a column inside the knobs' span,
  // whose ratio gain would be noise: such a candidate moves nothing the knobs cannot.
  if (!(pp > 1e-20 * j.squaredNorm())) return std::nullopt;
  const Eigen::VectorXd pr = r.transpose() * p;
  std::vector<Screening> out;
  for (Eigen::Index c = 0; c < pr.size(); ++c) out.push_back({pr[c] * pr[c] / pp, -pr[c] / pp});
  return out;
}

std::optional<Screening> ScoreTest(const Eigen::MatrixXd& Q0, const Eigen::VectorXd& j, const Eigen::VectorXd& r0) {
  const auto one = ScoreTests(Q0, j, r0);
  if (!one) return std::nullopt;
  return one->front();
}

}  // namespace rlg::diagnosis

#pragma once
/// Screening of thermal candidates in stage 4: a linearised score (Lagrange-multiplier) test.
/// With r0 the calibrated baseline's weighted residuals (simulated - measured over the channel
/// noise), J0 the Jacobian of r0 in the calibrated knobs and j the change of the residuals when
/// a candidate effect is added at its start size, the candidate is credited only for what
/// recalibrating the knobs could not explain:
///     p = j - Q0 Q0^T j          (Q0 an orthonormal basis of J0's columns)
///     step = -(p . r0) / |p|²     (the multiple of the start size that best removes r0)
///     gain = (p . r0)² / |p|²     (the drop in chi² at that step, to first order)
/// Pure linear algebra: no simulation.

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace rlg::diagnosis {

/// Orthonormal basis Q0 of the columns of J0 (thin Householder QR; J0 needs as many rows as
/// columns).
Eigen::MatrixXd KnobBasis(const Eigen::MatrixXd& J0);

struct Screening {
  double gain = 0.0;  ///< chi² units
  double step = 0.0;  ///< multiple of the candidate's start size
};

/// The score test above; none when the candidate moves nothing the knobs cannot (|p|² not
/// above 0, or not finite).
std::optional<Screening> ScoreTest(const Eigen::MatrixXd& Q0, const Eigen::VectorXd& j, const Eigen::VectorXd& r0);

/// The score test of one candidate on each column of r (e.g. a null bootstrap's replicate
/// residuals), in column order; none as ScoreTest. ScoreTest is its one-column case.
std::optional<std::vector<Screening>> ScoreTests(const Eigen::MatrixXd& Q0, const Eigen::VectorXd& j,
                                                 const Eigen::MatrixXd& r);

}  // namespace rlg::diagnosis

#pragma once
/// Linearised power of the thermal search's tests (docs/diagnosis.md, "Power").
///
/// A candidate's signature p (the change of the prewhitened residuals at its start size, less
/// what the calibrated knobs take up; statistics/screen.h) carries the noncentrality
///     lambda(s) = s² |p|²        at s times the start size,
/// in units of the noise's innovations. Its score is then, to first order, a chi² of k degrees
/// (its fitted parameters) with noncentrality lambda, and the search accepts it when that less
/// k ln n reaches the threshold t: it is detected with probability
///     P_det(lambda) = P(chi²_k(lambda) >= c²),      c² = t + k ln n.
/// It is named when, detected, it also out-scores every rival j, whose signature q_j has cosine
/// rho_j = p.q_j / (|p| |q_j|) with it: |p̂.y| > |q̂_j.y| for the data y. One rival beats it with
/// probability about Phi(-sqrt(lambda (1 - |rho_j|) / 2)) (p̂.y - q̂_j.y has mean
/// (1 - rho) sqrt(lambda) and variance 2 (1 - rho)), and by the union bound
///     P_named(lambda) >= P_det(lambda) - sum_j Phi(-sqrt(lambda (1 - |rho_j|) / 2)).
/// An exact twin (|rho| = 1) is never named apart. Pure: no simulation.

#include <Eigen/Core>
#include <vector>

#include "diagnosis/diagnose.h"

namespace rlg::diagnosis {

/// The lambda at which a chi² of `dof` degrees with that noncentrality reaches `critical` with
/// probability `power` (in (0, 1)): P(chi²_dof(lambda) >= critical) = power. 0 when lambda = 0
/// already reaches it that often.
double DetectionNoncentrality(double critical, int dof, double power);

/// The smallest lambda at which the union bound above reaches `power`: detected against
/// `critical` with `dof` degrees, and ahead of every rival of cosine `rival_cosines` (their
/// magnitudes count). Infinite when a rival is a twin (|rho| = 1) or the bound never reaches it.
/// At least DetectionNoncentrality.
double NamingNoncentrality(double critical, int dof, const std::vector<double>& rival_cosines, double power);

/// The named sizes of candidates of one kind (the search's rivals are its own kind): for each
/// power with lambda_at_start > 0, the cosines of its unit signature `unit[i]` with every
/// other such one's, its nearest rival (largest |cosine|) and the size named with probability
/// kPowerLevel against `critical[i]` with `dof[i]` degrees (NamingNoncentrality, scaled from
/// `start` as the size squared); the others are left as they are.
void NameApart(std::vector<EffectPower>& powers, const std::vector<Eigen::VectorXd>& unit,
               const std::vector<double>& critical, const std::vector<int>& dof);

}  // namespace rlg::diagnosis

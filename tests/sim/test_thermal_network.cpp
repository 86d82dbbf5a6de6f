// Closed-form checks of the thermal network and its CVODE integration.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <thread>
#include <utility>
#include <vector>
#include <unsupported/Eigen/MatrixFunctions>

#include "sim/ambient.h"
#include "sim/errors.h"
#include "sim/exact_linear.h"
#include "sim/simulator.h"
#include "tests/sim/test_helpers.h"

namespace rlg::sim {
namespace {

/// CVODE at tight tolerances: these tests check the CVODE path against closed forms.
SolverOptions Tight() {
  SolverOptions o;
  o.method = ThermalMethod::kCvode;
  o.cvode.rtol = 1e-10;
  o.cvode.atol = 1e-10;
  return o;
}

std::vector<double> Times(double t_end, double dt) {
  std::vector<double> t;
  for (double x = 0.0; x <= t_end + 1e-9; x += dt) t.push_back(x);
  return t;
}

/// States at `times` by the exact path and by CVODE with `cvode`'s tolerances: (exact, cvode).
std::pair<std::vector<Eigen::VectorXd>, std::vector<Eigen::VectorXd>> ExactAndCvode(
    const ThermalSystem& sys, const std::vector<double>& times, const Eigen::VectorXd& x0, SolverOptions cvode) {
  SolverOptions exact;
  exact.method = ThermalMethod::kExactLinear;
  cvode.method = ThermalMethod::kCvode;
  std::pair<std::vector<Eigen::VectorXd>, std::vector<Eigen::VectorXd>> out;
  IntegrateThermal(sys, times, x0, exact, [&](size_t, double, const auto& x, const auto&) { out.first.push_back(x); });
  IntegrateThermal(sys, times, x0, cvode, [&](size_t, double, const auto& x, const auto&) { out.second.push_back(x); });
  return out;
}

NetworkSpec OneNode(double c, double g) {
  NetworkSpec s;
  s.nodes.push_back({"m", c});
  s.links.push_back({0, kAmbient, g});
  return s;
}

/// Max relative error of one node's step response T(t) = T_amb (1 - exp(-t G / C)).
double StepResponseError(const SolverOptions& opt) {
  const double c = 100.0, g = 0.5, t_amb = 10.0, tau = c / g;
  const ThermalNetwork net(OneNode(c, g));
  const ThermalSystem sys(net, Profile::Constant(t_amb), {});
  double worst = 0.0;
  IntegrateThermal(sys, Times(5 * tau, 7.0), Eigen::VectorXd::Zero(1), opt,
                   [&](size_t, double t, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                     const double exact = t_amb * (1.0 - std::exp(-t / tau));
                     worst = std::max(worst, std::abs(x[0] - exact) / t_amb);
                   });
  return worst;
}

TEST(ThermalNetwork, SingleNodeStepResponseIsExponential) {
  // 1e-6 relative: the accuracy asked of the integrator; with rtol = atol = 1e-10 CVODE's global error is ~1e-8.
  EXPECT_LT(StepResponseError(Tight()), 1e-6);
}

TEST(ThermalNetwork, LagsInSeriesGiveTheCascadesStepResponse) {
  // A node (tau 200 s) read through a 30 s lag and a 5 s lag after it: three first-order stages
  // in series, whose unit step response is 1 - sum_i tau_i^2 e^(-t/tau_i) / prod_(j!=i) (tau_i - tau_j).
  const double c = 100.0, g = 0.5, t_amb = 10.0;
  const double tau[3] = {c / g, 30.0, 5.0};
  NetworkSpec spec = OneNode(c, g);
  spec.followers = {{0, tau[1]}, {1, tau[2]}};
  const ThermalNetwork net(spec);
  const ThermalSystem sys(net, Profile::Constant(t_amb), {});
  double worst = 0.0;
  IntegrateThermal(sys, Times(1000.0, 5.0), Eigen::VectorXd::Zero(3), Tight(),
                   [&](size_t, double t, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                     double tail = 0.0;
                     for (int i = 0; i < 3; ++i) {
                       double den = 1.0;
                       for (int j = 0; j < 3; ++j)
                         if (j != i) den *= tau[i] - tau[j];
                       tail += tau[i] * tau[i] * std::exp(-t / tau[i]) / den;
                     }
                     worst = std::max(worst, std::abs(x[2] - t_amb * (1.0 - tail)) / t_amb);
                   });
  // As the single node's step response: CVODE at 1e-10 is far inside 1e-6.
  EXPECT_LT(worst, 1e-6);
  // A lag can follow a node or an earlier lag, not itself or a later one.
  spec.followers = {{2, 5.0}, {0, 30.0}};
  EXPECT_THROW(ThermalNetwork{spec}, InputError);
}

TEST(ThermalNetwork, ErrorShrinksAsTolerancesTighten) {
  double previous = INFINITY;
  for (double tol : {1e-4, 1e-6, 1e-8, 1e-10}) {
    SolverOptions o = Tight();
    o.cvode.rtol = tol;
    o.cvode.atol = tol;
    const double err = StepResponseError(o);
    EXPECT_LT(err, previous) << "tol " << tol;
    // BDF global error stays within ~100x the local tolerance on this smooth problem.
    EXPECT_LT(err, 100 * tol) << "tol " << tol;
    previous = err;
  }
}

TEST(ThermalNetwork, LinearNetworkMatchesMatrixExponential) {
  const GyroConfig gyro = test::NoiselessDefaultGyro();
  const ThermalNetwork net(gyro.network);
  ASSERT_TRUE(net.is_linear());
  const double t_amb = -12.0;
  Eigen::VectorXd p(net.num_sources());
  for (int s = 0; s < net.num_sources(); ++s) p[s] = gyro.network.sources[s].power_W;
  std::vector<Profile> power;
  for (int s = 0; s < net.num_sources(); ++s) power.push_back(Profile::Constant(p[s]));
  const ThermalSystem sys(net, Profile::Constant(t_amb), power);
  const Eigen::VectorXd x0 = Eigen::VectorXd::LinSpaced(net.num_states(), 5.0, 25.0);
  const Eigen::VectorXd x_ss = net.LinearSteadyState(t_amb, p);
  // Exact oracle: x(t) = x_ss + exp(A t)(x0 - x_ss).
  IntegrateThermal(sys, Times(7200, 60), x0, Tight(),
                   [&](size_t, double t, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                     const Eigen::MatrixXd At = net.A() * t;
                     const Eigen::VectorXd exact = x_ss + At.exp() * (x0 - x_ss);
                     // 1e-6 °C: 1e-10 tolerances leave ~1e-8 relative error on a ~20 °C span.
                     EXPECT_EIGEN_NEAR(x, exact, 1e-6);
                   });
}

TEST(ThermalNetwork, SteadyStateEqualsGInverseP) {
  const GyroConfig gyro = test::NoiselessDefaultGyro();
  const NetworkSpec& spec = gyro.network;
  const ThermalNetwork net(spec);
  const int n = net.num_nodes();
  // Assemble G (W/K) and the source vector independently of the network's own matrices.
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd g_amb = Eigen::VectorXd::Zero(n), P = Eigen::VectorXd::Zero(n);
  for (const auto& l : spec.links) {
    G(l.a, l.a) += l.conductance_W_per_K;
    if (l.b == kAmbient) {
      g_amb[l.a] += l.conductance_W_per_K;
    } else {
      G(l.b, l.b) += l.conductance_W_per_K;
      G(l.a, l.b) -= l.conductance_W_per_K;
      G(l.b, l.a) -= l.conductance_W_per_K;
    }
  }
  Eigen::VectorXd p(net.num_sources());
  std::vector<Profile> power;
  for (int s = 0; s < net.num_sources(); ++s) {
    p[s] = spec.sources[s].power_W;
    power.push_back(Profile::Constant(p[s]));
    for (const auto& [node, share] : spec.sources[s].shares) P[node] += share * p[s];
  }
  const double t_amb = 25.0;
  const Eigen::VectorXd expected = G.lu().solve(P + g_amb * t_amb);
  const ThermalSystem sys(net, Profile::Constant(t_amb), power);
  Eigen::VectorXd last;
  // 100 h is > 50 slowest time constants of the default gyro (~1 h), so exp(-50) ~ 0 remains.
  IntegrateThermal(sys, {0.0, 360000.0}, Eigen::VectorXd::Constant(n, t_amb), Tight(),
                   [&](size_t, double, const Eigen::VectorXd& x, const Eigen::VectorXd&) { last = x; });
  EXPECT_EIGEN_NEAR(last, expected, 1e-7);
  EXPECT_EIGEN_NEAR(net.LinearSteadyState(t_amb, p), expected, 1e-9);  // same algebra, round-off only
}

TEST(ThermalNetwork, EnergyBalanceClosesWithNonlinearTerms) {
  GyroConfig gyro = test::NoiselessDefaultGyro();
  ApplyEffect({"thermal.radiation", "block-ambient", {{"emissivity_area_m2", 0.02}}}, gyro);
  ApplyEffect({"thermal.radiation", "anode-cabinet", {{"emissivity_area_m2", 0.01}}}, gyro);
  ApplyEffect({"thermal.power_drift", "cathode", {{"g_per_C", 0.01}}}, gyro);
  const ThermalNetwork net(gyro.network);
  ASSERT_FALSE(net.is_linear());
  std::vector<Profile> power;
  for (const auto& s : gyro.network.sources) power.push_back(Profile::Constant(s.power_W));
  const Profile ambient = Profile::Sine(10.0, 15.0, 3600.0, 0.0);
  const ThermalSystem sys(net, ambient, power);
  Eigen::VectorXd pw(net.num_sources());
  sys.Power(0.0, pw);
  const int n = net.num_nodes();
  Eigen::VectorXd c(n);
  for (int i = 0; i < n; ++i) c[i] = gyro.network.nodes[i].heat_capacity_J_per_K;
  std::vector<double> q;  // net heat input (W) at 1 s
  double e0 = 0.0, e1 = 0.0;
  const std::vector<double> times = Times(7200, 1.0);
  IntegrateThermal(sys, times, Eigen::VectorXd::Constant(n, 10.0), Tight(),
                   [&](size_t k, double t, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                     q.push_back(net.NetHeatInput_W(x, ambient.Value(t), pw));
                     const double e = c.dot(x.head(n));
                     if (k == 0) e0 = e;
                     e1 = e;
                   });
  // Simpson's rule over 7200 intervals of 1 s; the integrand varies on the 1 h sine and
  // ~2 min node constants, so the quadrature error is < 1e-6 of the stored energy change.
  double integral = q.front() + q.back();
  for (size_t k = 1; k + 1 < q.size(); ++k) integral += (k % 2 ? 4.0 : 2.0) * q[k];
  integral /= 3.0;
  EXPECT_NEAR(e1 - e0, integral, 1e-6 * std::abs(e1 - e0) + 1e-6);
}

class BothMethods : public ::testing::TestWithParam<ThermalMethod> {
 protected:
  SolverOptions Options() const {
    SolverOptions o = Tight();
    o.method = GetParam();
    return o;
  }
};

TEST_P(BothMethods, RampBreakpointsAreHonoured) {
  // First-order lag driven by a ramp from 0 starting at t0 (off the output grid), ending at 40.
  const double c = 100.0, g = 0.5, tau = c / g, t0 = 1000.3, rate = 1.0 / 60.0, end = 40.0;
  const double t1 = t0 + end / rate;
  const ThermalNetwork net(OneNode(c, g));
  const ThermalSystem sys(net, Profile::Ramp(0.0, rate, t0, end), {});
  const auto during = [&](double t) { return rate * (t - t0) - rate * tau * (1.0 - std::exp(-(t - t0) / tau)); };
  const double at_t1 = during(t1);
  IntegrateThermal(sys, Times(t1 + 2000.0, 1.0), Eigen::VectorXd::Zero(1), Options(),
                   [&](size_t, double t, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                     double exact = 0.0;
                     if (t > t0 && t <= t1) exact = during(t);
                     if (t > t1) exact = end + (at_t1 - end) * std::exp(-(t - t1) / tau);
                     // 1e-7 °C: an integrator that smoothed over the kinks would be off by
                     // ~rate * h ~ 1e-3 °C for its first steps past each kink.
                     EXPECT_NEAR(x[0], exact, 1e-7) << "t = " << t;
                   });
}

TEST_P(BothMethods, StepsInAmbientAndPowerAreHonoured) {
  // One node, ambient steps 0 -> 10 at t = 100.25 and a heater 0 -> 2 W at t = 300.5:
  // a sum of two shifted exponentials.
  const double c = 100.0, g = 0.5, tau = c / g;
  NetworkSpec spec = OneNode(c, g);
  spec.sources.push_back({"heater", {{0, 1.0}}, 0.0});
  const ThermalNetwork net(spec);
  const ThermalSystem sys(net, Profile::Steps(0.0, {{100.25, 10.0}}), {Profile::Steps(0.0, {{300.5, 2.0}})});
  IntegrateThermal(sys, Times(2000.0, 1.0), Eigen::VectorXd::Zero(1), Options(),
                   [&](size_t, double t, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                     double exact = 0.0;
                     if (t >= 100.25) exact += 10.0 * (1.0 - std::exp(-(t - 100.25) / tau));
                     if (t >= 300.5) exact += (2.0 / g) * (1.0 - std::exp(-(t - 300.5) / tau));
                     EXPECT_NEAR(x[0], exact, 1e-7) << "t = " << t;  // as above
                   });
}

TEST_P(BothMethods, PowerDriftOnSteppedPowerIsAShiftedExponential) {
  // One node heated by P0 (1 + g (T - T_ref)) with P0 stepping 0 -> 2 W at t = 300.5 and
  // -> 1 W at t = 1200.25: after each step the node relaxes with G' = G - P0 g to
  // T_inf = (G T_amb + P0 (1 - g T_ref)) / G'. The exact path folds the drift into A.
  const double c = 100.0, g = 0.5, drift = -0.05, t_ref = 20.0, t_amb = 10.0;
  NetworkSpec spec = OneNode(c, g);
  spec.sources.push_back({"heater", {{0, 1.0}}, 0.0});
  spec.sources.back().drift_node = 0;
  spec.sources.back().drift_per_K = drift;
  spec.sources.back().drift_reference_C = t_ref;
  const ThermalNetwork net(spec);
  const ThermalSystem sys(net, Profile::Constant(t_amb), {Profile::Steps(0.0, {{300.5, 2.0}, {1200.25, 1.0}})});
  auto relax = [&](double p0, double x0, double dt) {
    const double g_eff = g - p0 * drift, x_inf = (g * t_amb + p0 * (1.0 - drift * t_ref)) / g_eff;
    return x_inf + (x0 - x_inf) * std::exp(-dt * g_eff / c);
  };
  const double at_step2 = relax(2.0, t_amb, 1200.25 - 300.5);
  IntegrateThermal(sys, Times(3000.0, 1.0), Eigen::VectorXd::Constant(1, t_amb), Options(),
                   [&](size_t, double t, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                     double exact = t_amb;
                     if (t >= 300.5) exact = relax(2.0, t_amb, std::min(t, 1200.25) - 300.5);
                     if (t >= 1200.25) exact = relax(1.0, at_step2, t - 1200.25);
                     EXPECT_NEAR(x[0], exact, 1e-7) << "t = " << t;  // as above
                   });
}

INSTANTIATE_TEST_SUITE_P(ThermalNetwork, BothMethods,
                         ::testing::Values(ThermalMethod::kCvode, ThermalMethod::kExactLinear),
                         [](const auto& info) { return info.param == ThermalMethod::kCvode ? "Cvode" : "Exact"; });

TEST(ThermalNetwork, ExactAndCvodePathsAgreeOnTheDefaultGyroWithSensorLag) {
  GyroConfig gyro = test::NoiselessDefaultGyro();
  ApplyEffect({"sensor.lag", "T2", {{"time_constant_s", 60.0}}}, gyro);
  std::vector<int> sensor_state;
  const ThermalNetwork net = BuildNetwork(gyro, &sensor_state);
  std::vector<Profile> power;
  for (const auto& s : gyro.network.sources) power.push_back(Profile::Constant(s.power_W));
  const ThermalSystem sys(net, Profile::Table({{0, -10}, {600.5, -10}, {3000, 50}, {5000, 20}}), power);
  const auto [a, b] = ExactAndCvode(sys, Times(7200, 1.0), Eigen::VectorXd::Constant(net.num_states(), -10.0), Tight());
  ASSERT_EQ(a.size(), b.size());
  // CVODE at 1e-10 is within ~1e-7 °C of exact over a 60 °C swing.
  for (size_t k = 0; k < a.size(); k += 13) EXPECT_EIGEN_NEAR(a[k], b[k], 1e-6);
}

TEST(ThermalNetwork, ExactAndCvodePathsAgreeOnPowerDriftWithSteppedPower) {
  // The default gyro with a drifting discharge whose power steps, under an ambient ramp: the
  // exact path (one folded propagator per power level) against CVODE at 1e-10.
  GyroConfig gyro = test::NoiselessDefaultGyro();
  ApplyEffect({"thermal.power_drift", "cathode", {{"g_per_C", 0.01}}}, gyro);
  const ThermalNetwork net(gyro.network);
  ASSERT_FALSE(net.is_linear());
  std::vector<Profile> power;
  for (const auto& s : gyro.network.sources) power.push_back(Profile::Steps(s.power_W, {{1800.5, 1.5 * s.power_W}, {4000, 0.5 * s.power_W}}));
  const ThermalSystem sys(net, Profile::Table({{0, -10}, {600.5, -10}, {3000, 50}, {5000, 20}}), power);
  ASSERT_TRUE(sys.SolvableExactly());
  const auto [a, b] = ExactAndCvode(sys, Times(7200, 1.0), Eigen::VectorXd::Constant(net.num_states(), -10.0), Tight());
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); k += 13) EXPECT_EIGEN_NEAR(a[k], b[k], 1e-6);  // as above
}

TEST(ThermalNetwork, ExactMethodRefusesANonlinearNetwork) {
  GyroConfig gyro = test::NoiselessDefaultGyro();
  ApplyEffect({"thermal.radiation", "block-ambient", {{"emissivity_area_m2", 0.02}}}, gyro);
  const ThermalNetwork net(gyro.network);
  std::vector<Profile> power(net.num_sources(), Profile::Constant(0.5));
  const ThermalSystem sys(net, Profile::Constant(0.0), power);
  SolverOptions o;
  o.method = ThermalMethod::kExactLinear;
  EXPECT_THROW(IntegrateThermal(sys, {0.0, 10.0}, Eigen::VectorXd::Zero(net.num_states()), o,
                                [](size_t, double, const auto&, const auto&) {}),
               InputError);
}

TEST(ThermalNetwork, NodeWithoutPathToAmbientIsRejected) {
  NetworkSpec s = OneNode(100.0, 0.5);
  s.nodes.push_back({"island", 10.0});
  try {
    ThermalNetwork net(s);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'island' has no conductive path to ambient"), std::string::npos) << e.what();
  }
}

TEST(ThermalNetwork, NegativeHeatCapacityIsRejected) {
  EXPECT_THROW(ThermalNetwork(OneNode(-1.0, 0.5)), InputError);
}

TEST(CvodeIntegrator, TooFewStepsIsANumericalErrorNamingTheTime) {
  const ThermalNetwork net(OneNode(100.0, 0.5));
  const ThermalSystem sys(net, Profile::Constant(10.0), {});
  SolverOptions o = Tight();
  o.cvode.max_steps = 1;
  try {
    IntegrateThermal(sys, {0.0, 1000.0}, Eigen::VectorXd::Zero(1), o,
                     [](size_t, double, const Eigen::VectorXd&, const Eigen::VectorXd&) {});
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("CVODE failed at t = "), std::string::npos) << m;
    EXPECT_NE(m.find("CV_TOO_MUCH_WORK"), std::string::npos) << m;
  }
}

/// A system whose right-hand side throws: the exception must come out of AdvanceTo intact.
class ThrowingSystem final : public OdeSystem {
 public:
  int size() const override { return 1; }
  void CalcTimeDerivatives(double t, const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd> xdot,
                           OdeScratch&) const override {
    if (t > 5.0) throw std::domain_error("boom at t > 5");
    xdot[0] = 1.0;
  }
  void CalcJacobian(double, const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::MatrixXd> J,
                    OdeScratch&) const override {
    J.setZero();
  }
};

TEST(CvodeIntegrator, ExceptionInRightHandSideIsRethrownNotLost) {
  ThrowingSystem sys;
  CvodeIntegrator integrator(sys, IntegratorOptions{});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(1);
  integrator.Reset(0.0, x);
  EXPECT_THROW(integrator.AdvanceTo(10.0, 10.0, x), std::domain_error);
}

// A measured ambient is a table with a point every sample, so CVODE stops and restarts at every
// second (what diagnose does with logged T_amb): the restarts must not cost accuracy.
TEST(ThermalNetwork, CvodeRestartedEverySecondStaysExact) {
  const GyroConfig gyro = test::NoiselessDefaultGyro();
  const ThermalNetwork net(gyro.network);
  std::vector<Profile> power;
  for (const auto& s : gyro.network.sources) power.push_back(Profile::Constant(s.power_W));
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k <= 3600; ++k) pts.emplace_back(k, 20.0 + 10.0 * std::sin(k / 600.0) + 0.01 * (k % 7));
  const ThermalSystem sys(net, Profile::Table(pts), power);
  // CVODE at its default tolerances, as diagnose runs it.
  const auto [a, b] = ExactAndCvode(sys, Times(3600, 10.0), Eigen::VectorXd::Constant(net.num_states(), 20.0), SolverOptions{});
  ASSERT_EQ(a.size(), b.size());
  // 0.1 mK: a quarter of the 0.4 mK noise of the 100 s means diagnose scores. (At rtol = atol
  // = 1e-6 this was 1.5 mK: each restart begins at order 1 and the per-step allowance
  // rtol |T| accumulates; 1e-9 gives 17 uK.)
  double worst = 0.0;
  for (size_t k = 0; k < a.size(); ++k) worst = std::max(worst, (a[k] - b[k]).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-4);
}

// The propagator's modal form (used for every thermal network) against Van Loan's augmented
// matrix exponential computed here with Eigen's Pade: same step for irregular h, with a
// sensor-lag follower in the network and ramping inputs.
TEST(ExactLinearPropagator, ModalFormEqualsAugmentedMatrixExponential) {
  GyroConfig gyro = test::NoiselessDefaultGyro();
  ApplyEffect({"sensor.lag", "T2", {{"time_constant_s", 7.0}}}, gyro);
  std::vector<int> sensor_state;
  const ThermalNetwork net = BuildNetwork(gyro, &sensor_state);
  const Eigen::Index n = net.num_states(), m = 1 + net.num_sources();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 2 * m, n + 2 * m);
  M.topLeftCorner(n, n) = net.A();
  M.block(0, n, n, 1) = net.b_amb();
  M.block(0, n + 1, n, m - 1) = net.B_src();
  M.block(n, n + m, m, m).setIdentity();
  ExactLinearPropagator prop(net);
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -3.0, 22.0), xdot(n);
  Eigen::VectorXd u(m), v(m);
  for (Eigen::Index i = 0; i < m; ++i) u[i] = 0.3 + 2.0 * static_cast<double>(i), v[i] = 0.01 * static_cast<double>(i + 1);
  for (double h : {0.37, 1.0, 9.81, 123.4, 3600.0}) {
    Eigen::VectorXd z(n + 2 * m);
    z << x, u, v;
    const Eigen::MatrixXd Mh = M * h;
    const Eigen::VectorXd expected = (Mh.exp() * z).head(n);
    prop.Step(h, u, v, x, xdot);
    // 1e-9 °C: both are exact to round-off; cond(V) ~1e3 times eps on ~20 °C states.
    SCOPED_TRACE(testing::Message() << "h = " << h);
    EXPECT_EIGEN_NEAR(x, expected, 1e-9);
    const Eigen::VectorXd xdot_expected = net.A() * x + M.block(0, n, n, m) * (u + v * h);
    EXPECT_EIGEN_NEAR(xdot, xdot_expected, 1e-9);
    x = expected;
  }
}

// A regular step's affine rows in the order both paths use (ExactLinearPropagator::AffineRows):
// the unrolled form the sample loop runs for N states and the general one give the same bits,
// and both are S [x; 1; tau] to round-off, for every state count the simulator unrolls and more.
TEST(ExactLinearPropagator, AffineRowsUnrolledAndGeneralGiveTheSameBitsAsTheProduct) {
  auto check = [](auto rows_tag) {
    constexpr int kRows = decltype(rows_tag)::value;
    constexpr int n = kRows / 2;  // states; the rows are the states' and their derivatives'
    Eigen::MatrixXd S = Eigen::MatrixXd::Random(kRows, n + 2);
    Eigen::VectorXd x = Eigen::VectorXd::Random(n) * 30.0;
    const double tau = 17.0;
    double fixed[kRows], general[kRows], scratch[2 * kRows];
    ExactLinearPropagator::AffineRows<kRows>(S.data(), kRows, n, x.data(), tau, fixed);
    ExactLinearPropagator::AffineRows<0>(S.data(), kRows, n, x.data(), tau, general, kRows, scratch);
    Eigen::VectorXd z(n + 2);
    z << x, 1.0, tau;
    const Eigen::VectorXd product = S * z;
    for (int r = 0; r < kRows; ++r) {
      EXPECT_EQ(fixed[r], general[r]) << n << " states, row " << r;
      // ~ (n + 2) roundings of terms up to ~30 x 1: 1e-12 is a thousand times that.
      EXPECT_NEAR(fixed[r], product[r], 1e-12) << n << " states, row " << r;
    }
  };
  check(std::integral_constant<int, 2>{});
  check(std::integral_constant<int, 4>{});
  check(std::integral_constant<int, 8>{});
  check(std::integral_constant<int, 12>{});
  check(std::integral_constant<int, 14>{});
}

// ValuesAt walks the points once; it must give exactly Value's numbers, including on, just
// before and just after every breakpoint, and outside the points.
TEST(Profile, ValuesAtEqualsValueEverywhere) {
  const std::vector<Profile> profiles = {
      Profile::Constant(3.0), Profile::Ramp(20.0, 1.0 / 60.0, 100.0, 60.0),
      Profile::Table({{100.0, 10.0}, {250.0, 40.0}, {400.0, 40.0}, {700.0, -5.0}}), Profile::Table({{300.0, 7.0}}),
      Profile::Steps(1.0, {{50.0, 2.0}, {300.0, -1.0}}), Profile::Sine(20.0, 2.0, 600.0, 0.3)};
  std::vector<double> times;
  for (double t = 0.0; t <= 1000.0; t += 0.5) times.push_back(t);
  for (double b : {50.0, 100.0, 250.0, 300.0, 400.0, 700.0}) times.push_back(std::nextafter(b, 0.0));
  std::sort(times.begin(), times.end());
  for (const auto& p : profiles) {
    std::vector<double> got(times.size());
    p.ValuesAt(times, got.data());
    for (size_t k = 0; k < times.size(); ++k) ASSERT_EQ(got[k], p.Value(times[k])) << "t = " << times[k];
  }
}

TEST(Profile, SimplifiedPolylineStaysWithinToleranceAndKeepsTheCorners) {
  // A dwell, a 1 °C/min ramp and a dwell sampled every 10 s with an alternating +-2e-6 wobble: at a
  // tolerance of 1e-5 the curve keeps a point near each corner and drops the rest, and the
  // kept curve passes within the tolerance of every original point.
  const Profile truth = Profile::Table({{0.0, 20.0}, {1800.0, 20.0}, {4200.0, 60.0}, {9000.0, 60.0}});
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k <= 900; ++k) {
    const double t = 10.0 * k;
    pts.emplace_back(t, truth.Value(t) + (k % 2 ? 2e-6 : -2e-6));
  }
  const double tol = 1e-5;
  const auto kept = SimplifyPolyline(pts, tol);
  EXPECT_LE(kept.size(), 8u);  // 4 corners, each possibly kept with a neighbour
  EXPECT_EQ(kept.front(), pts.front());
  EXPECT_EQ(kept.back(), pts.back());
  const Profile simple = Profile::Table(kept);
  for (const auto& [t, v] : pts) EXPECT_LE(std::abs(simple.Value(t) - v), tol * (1.0 + 1e-9)) << "t = " << t;
  // At zero tolerance an alternating wobble keeps every point.
  EXPECT_EQ(SimplifyPolyline(pts, 0.0).size(), pts.size());
}

/// SimplifyPolyline's definition: each segment extended while the chord to the next point passes
/// within tolerance of every point it spans, checked point by point.
std::vector<std::pair<double, double>> SimplifyPolylineByDefinition(const std::vector<std::pair<double, double>>& points,
                                                                    double tolerance) {
  if (points.size() <= 2) return points;
  auto fits = [&](size_t i, size_t j) {
    const auto [t0, v0] = points[i];
    const double slope = (points[j].second - v0) / (points[j].first - t0);
    for (size_t k = i + 1; k < j; ++k)
      if (std::abs(v0 + slope * (points[k].first - t0) - points[k].second) > tolerance) return false;
    return true;
  };
  std::vector<std::pair<double, double>> out = {points.front()};
  size_t i = 0;
  while (i + 1 < points.size()) {
    size_t j = i + 1;
    while (j + 1 < points.size() && fits(i, j + 1)) ++j;
    out.push_back(points[j]);
    i = j;
  }
  return out;
}

TEST(Profile, SimplifiedPolylineKeepsThePointsOfItsPointByPointDefinition) {
  // SimplifyPolyline decides most chords from the running bounds of the slopes that pass every
  // point so far, and leaves the rest to the point-by-point test. The kept points must be the
  // definition's, equal, not close, on inputs that put chords at exactly the tolerance: a
  // wobble of exactly +-tol about a line and about a constant, exact constants and ramps (whose
  // misfits are 0), noise and a random walk at several tolerances, tolerance 0, a point that is
  // NaN, two points at one time, and large offsets (rounding of 20 °C vs 1e5 °C).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> z;
  std::vector<std::pair<std::vector<std::pair<double, double>>, double>> cases;
  for (double offset : {0.0, 20.0, 1e5}) {
    for (double tol : {0.0, 1e-6, 0.01, 0.25}) {
      std::vector<std::pair<double, double>> constant, ramp, wobble, wobble_ramp, noise, walk, corners;
      double w = offset;
      for (int k = 0; k < 600; ++k) {
        const double t = 0.5 * k;
        constant.emplace_back(t, offset);
        ramp.emplace_back(t, offset + 0.01 * t);
        wobble.emplace_back(t, offset + (k % 2 ? tol : -tol));
        wobble_ramp.emplace_back(t, offset + 0.3 * t + (k % 3 == 0 ? tol : (k % 3 == 1 ? -tol : 0.0)));
        noise.emplace_back(t, offset + 0.01 * z(rng));
        w += 0.003 * z(rng);
        walk.emplace_back(t, w);
        corners.emplace_back(t, offset + (k < 200 ? 0.0 : (k < 400 ? 0.05 * (k - 200) : 10.0)));
      }
      for (auto* c : {&constant, &ramp, &wobble, &wobble_ramp, &noise, &walk, &corners}) cases.emplace_back(*c, tol);
      auto with_nan = noise;
      with_nan[37].second = std::numeric_limits<double>::quiet_NaN();
      cases.emplace_back(with_nan, tol);
      auto repeated_time = ramp;
      repeated_time[300].first = repeated_time[299].first;
      cases.emplace_back(repeated_time, tol);
    }
  }
  for (size_t c = 0; c < cases.size(); ++c) {
    const auto& [pts, tol] = cases[c];
    const auto got = SimplifyPolyline(pts, tol), want = SimplifyPolylineByDefinition(pts, tol);
    ASSERT_EQ(got.size(), want.size()) << "case " << c << ", tolerance " << tol;
    for (size_t k = 0; k < got.size(); ++k) {
      // NaN != NaN: compare the kept points' bits.
      EXPECT_EQ(std::memcmp(&got[k], &want[k], sizeof got[k]), 0) << "case " << c << ", kept point " << k;
    }
  }
}

TEST(IntegrateThermal, ARepeatedOutputTimeGivesTheSameStateOnBothPaths) {
  // diagnose asks for the state at power-on and at the first fit block's mid-time, which on
  // 10 s data is power-on again. A zero-length step must leave the state as it is (exactly:
  // Phi(0) = I), on the exact path as on CVODE's; before, the exact path read its output
  // buffer before writing it (Valgrind: uninitialised values from the propagator's
  // constructor) and returned whatever was there.
  const ThermalNetwork net(OneNode(100.0, 0.5));
  const ThermalSystem sys(net, Profile::Ramp(10.0, 1.0 / 60.0, 0.0, 30.0), {});
  const std::vector<double> repeated = {0.0, 0.0, 10.0, 10.0, 20.0}, plain = {0.0, 10.0, 20.0};
  const Eigen::VectorXd x0 = Eigen::VectorXd::Constant(1, 10.0);
  for (const ThermalMethod method : {ThermalMethod::kExactLinear, ThermalMethod::kCvode}) {
    SolverOptions o = Tight();
    o.method = method;
    std::vector<double> got, want;
    IntegrateThermal(sys, repeated, x0, o, [&](size_t, double, const auto& x, const auto&) { got.push_back(x[0]); });
    IntegrateThermal(sys, plain, x0, o, [&](size_t, double, const auto& x, const auto&) { want.push_back(x[0]); });
    ASSERT_EQ(got.size(), 5u);
    // Same arithmetic on the same steps: equal to the last bit on the exact path; CVODE
    // restarts nowhere new, so its steps are the same too.
    EXPECT_EQ(got[0], 10.0);
    EXPECT_EQ(got[1], 10.0);
    EXPECT_EQ(got[2], want[1]);
    EXPECT_EQ(got[3], want[1]);
    EXPECT_EQ(got[4], want[2]);
  }
}

TEST(IntegrateThermal, DecreasingOutputTimesAreRefused) {
  const ThermalNetwork net(OneNode(100.0, 0.5));
  const ThermalSystem sys(net, Profile::Constant(10.0), {});
  EXPECT_THROW(IntegrateThermal(sys, {0.0, 10.0, 5.0}, Eigen::VectorXd::Zero(1), Tight(), [](size_t, double, const auto&, const auto&) {}),
               std::logic_error);
}

/// Outputs of one integration of `sys`: every state and derivative, in order.
std::vector<double> Outputs(const ThermalSystem& sys, const std::vector<double>& times, double x0, const SolverOptions& o) {
  std::vector<double> out;
  IntegrateThermal(sys, times, Eigen::VectorXd::Constant(sys.size(), x0), o,
                   [&](size_t, double, const Eigen::VectorXd& x, const Eigen::VectorXd& xdot) {
                     out.insert(out.end(), x.data(), x.data() + x.size());
                     out.insert(out.end(), xdot.data(), xdot.data() + xdot.size());
                   });
  return out;
}

// A ThermalSystem keeps no working memory of its own (OdeScratch is the caller's): two threads
// integrating one const system get the bytes one thread gets, on the CVODE path (radiation) and
// on the exact one. Under ThreadSanitizer (tools/tsan.sh) this is also a check for data races.
TEST(ThermalSystem, TwoThreadsIntegrateOneConstSystemAsOneThreadDoes) {
  GyroConfig linear_gyro = test::NoiselessDefaultGyro();
  GyroConfig radiating_gyro = linear_gyro;
  ApplyEffect({"thermal.radiation", "block-ambient", {{"emissivity_area_m2", 0.02}}}, radiating_gyro);
  for (const GyroConfig* gyro : {&linear_gyro, &radiating_gyro}) {
    const ThermalNetwork net(gyro->network);
    std::vector<Profile> power;  // each source halves its power at 600.5 s: the inputs move
    for (const auto& s : gyro->network.sources) power.push_back(Profile::Steps(s.power_W, {{600.5, 0.5 * s.power_W}}));
    const ThermalSystem sys(net, Profile::Ramp(10.0, 1.0 / 60.0, 0.0, 40.0), power);
    const std::vector<double> times = Times(3600.0, 10.0);
    const SolverOptions o;  // auto: exact for the linear network, CVODE for the radiating one
    const std::vector<double> want = Outputs(sys, times, 10.0, o);
    std::vector<double> a, b;
    std::thread ta([&] { a = Outputs(sys, times, 10.0, o); });
    std::thread tb([&] { b = Outputs(sys, times, 10.0, o); });
    ta.join();
    tb.join();
    EXPECT_EQ(a, want);
    EXPECT_EQ(b, want);
  }
}

}  // namespace
}  // namespace rlg::sim

#pragma once
/// The one place that talks to SUNDIALS: an RAII wrapper around CVODES (BDF, dense direct
/// linear solver, analytic Jacobian) for any OdeSystem. The simulator owns time and state;
/// the model (OdeSystem) is const and pure, and whatever its evaluations write besides their
/// output goes to an OdeScratch its caller owns.
///
/// Errors: a CVODE failure throws NumericalError naming the time and CVODE's own reason. An
/// exception thrown by the system's callbacks is caught at the C boundary and rethrown here
/// after CVode returns, so it never crosses CVODE's C frames.

#include <Eigen/Dense>
#include <memory>
#include <string>

namespace rlg::sim {

/// Working memory of an OdeSystem's evaluations (the inputs at t, say), kept between calls so
/// that they allocate nothing. Whoever evaluates owns it, never the system: CvodeIntegrator
/// keeps one per integrator and IntegrateThermal one per call, so threads that integrate one
/// const system each write their own.
struct OdeScratch {
  Eigen::VectorXd inputs;
};

/// dx/dt = f(t, x) with Jacobian df/dx. Both evaluations may write `scratch` and nothing else.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int size() const = 0;
  virtual void CalcTimeDerivatives(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                                   Eigen::Ref<Eigen::VectorXd> xdot, OdeScratch& scratch) const = 0;
  virtual void CalcJacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                            Eigen::Ref<Eigen::MatrixXd> J, OdeScratch& scratch) const = 0;
};

struct IntegratorOptions {
  /// Relative and absolute (°C) tolerances. Tight because CVODE restarts at every input
  /// breakpoint (a measured ambient or heater power: every sample), each restart begins at
  /// order 1, and the per-step allowance rtol |T| + atol accumulates over the restarts: with
  /// a breakpoint every second for an hour, 1e-6 drifted 1.5 mK from the exact solution,
  /// 1e-9 17 uK (tests/sim/test_thermal_network.cpp), well below the sensors' 0.4 mK noise
  /// on 100 s means.
  double rtol = 1e-9;
  double atol = 1e-9;
  /// CVODE's limit on internal steps between two outputs (CV_TOO_MUCH_WORK past it).
  long max_steps = 100000;
  /// Largest internal step (s); 0 = no limit.
  double max_step_s = 0.0;

  bool IsValid(std::string* error) const;
};

class CvodeIntegrator {
 public:
  CvodeIntegrator(const OdeSystem& system, const IntegratorOptions& options);
  ~CvodeIntegrator();
  CvodeIntegrator(const CvodeIntegrator&) = delete;
  CvodeIntegrator& operator=(const CvodeIntegrator&) = delete;

  /// (Re)starts integration at (t0, x0). Call it at every discontinuity of the inputs, so the
  /// BDF history never spans a kink.
  void Reset(double t0, const Eigen::Ref<const Eigen::VectorXd>& x0);
  /// Integrates to t_out (never stepping past t_stop >= t_out) and writes x(t_out).
  void AdvanceTo(double t_out, double t_stop, Eigen::Ref<Eigen::VectorXd> x);
  /// Internal steps taken since construction.
  long num_steps() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rlg::sim

#pragma once
/// Polynomial compensation models in one temperature channel, with optional extra terms: the
/// members of the model family (model/causal_regressors.h) that `rlgtherm fit --model
/// poly|px4|ardupilot|auto` fits (model/poly_fit.h, model/model_selection.h). Units: bias B in
/// °/h, temperatures in °C, time in s.
///
///   d    = clamp(T, T_min, T_max) - T_ref   T the model's channel (default T1); [T_min, T_max]
///                                           the range T spanned in the fit (range_C): outside it
///                                           the polynomial is held at the range's edge (clipped)
///                                           and the sample is flagged
///   p(T) = sum_{k=1..order} c_k d^k         order 1..5
///   g_j  = the extra terms' regressors (below), gamma_j their coefficients
///
/// Offset rules:
///   fitted    B      = c0 + p(T) + sum_j gamma_j g_j                   an absolute bias (PX4)
///   power_on  B - B0 = p(T) - P0 + sum_j gamma_j (g_j - G_j,0)        referred to power-on
///             (ArduPilot), with B0 the mean bias over the first b0_window_s (120 s) as in
///             Eq. (2), and P0, G_j,0 the means of p and g_j over the same samples: the bias,
///             the polynomial and the terms are all referred to the B0 window. When T holds
///             still there (a power-on after a soak) P0 = p(T_0), ArduPilot's reference to the
///             temperature at its calibration; when T moves there, a reference to the first
///             sample alone would leave B0 holding the model's own change over the window, a
///             constant error no coefficient can take up (in a test cycle moving 7 °C in the
///             window, it left 1.9 °/h of residual on 0.02 °/h of noise). The compensator uses
///             the running means during the window, then freezes them (as Eq. (2)'s does for B0).
///
/// Extra terms (causal operators of model/causal_operators.h on the channel T):
///   rate        dT/dt (°C/min) through a first-order low-pass of time constant tau_r
///               (RateTau: ten sample periods); gamma in °/h per °C/min
///   hysteresis  T - play_w(T), in [-w/2, w/2]: +w/2 heating, -w/2 cooling, linear across a
///               reversal; the width w (°C) is fitted by profile; gamma in °/h/°C
///   lag         T_L - T, T_L a first-order lag of T whose tau is fitted by profile; gamma in
///               °/h/°C
///   gradient    Tj - T for another channel Tj; gamma in °/h/°C
///
/// Presets:
///   px4        order 3, fitted, T_ref the middle of the fitted span: PX4's
///              Tools/process_sensor_caldata.py, offset = sum_{k=0..3} X_k (T - TREF)^k with
///              TREF = (TMIN + TMAX) / 2 and T clipped to [TMIN, TMAX]
///   ardupilot  order 3, power_on, T_ref = 35 °C: ArduPilot's AP_InertialSensor_tempcal,
///              p(d) = c1 d + c2 d² + c3 d³, d = clamp(T) - 35, correction
///              p(clamp(T) - 35) - p(clamp(T_cal) - 35), T_cal the temperature at the gyro's
///              calibration (here: power-on)

#include <Eigen/Dense>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model/causal_operators.h"
#include "model/causal_regressors.h"

namespace rlg::model {

enum class TermKind { kRate, kHysteresis, kLag, kGradient };

/// "rate", "hysteresis", "lag", "gradient".
const char* TermKindName(TermKind kind);
/// The kind named `name`; nullopt for another name.
std::optional<TermKind> TermKindOf(const std::string& name);

struct PolyTerm {
  TermKind kind = TermKind::kRate;
  std::string channel;   ///< gradient: the other channel Tj
  double tau_s = 0.0;    ///< rate: tau_r of the low-pass; lag: the lag's time constant
  double width_C = 0.0;  ///< hysteresis: w
  /// The coefficient's name: "rate", "hysteresis", "lag", "gradient_T2".
  std::string Name() const;
  /// For tables: "rate (tau_r 5 s)", "hysteresis (w 1.23 °C)", "lag (tau 312 s)", "gradient T2".
  std::string Describe() const;
};

struct PolySpec {
  std::string channel = "T1";
  int order = 3;
  OffsetRule offset = OffsetRule::kFitted;
  double reference_C = 0.0;               ///< T_ref
  std::array<double, 2> range_C{0.0, 0.0};  ///< [T_min, T_max]: T is clipped to it
  double b0_window_s = 120.0;             ///< power_on only
  std::vector<PolyTerm> terms;

  /// The temperature channels the regressors read: the channel, then each gradient's Tj.
  std::vector<std::string> Channels() const;
  /// c0 (fitted offset only), c1..c_order, then the terms' names, in the regressors' order.
  std::vector<std::string> CoefficientNames() const;
  /// The unit of each coefficient, in the same order ("°/h", "°/h/°C^2", "°/h per °C/min").
  std::vector<std::string> CoefficientUnits() const;
  /// "order 3 in T1 (fitted offset) + hysteresis + gradient T2".
  std::string Describe() const;
};

/// One fitted coefficient with its standard error and the degrees of freedom of its Student's t
/// (0: read from a file that did not give them).
struct Coefficient {
  std::string name;
  std::string unit;
  double value = 0.0;
  double standard_error = 0.0;
  double dof = 0.0;
};

/// What `auto` tried (model/model_selection.h): each candidate's cross-validated score inside
/// the training data and whether it was taken.
struct SelectionStep {
  std::string candidate;  ///< e.g. "order 3, power_on" or "+ hysteresis"
  double cv_rms_dph = 0.0;
  bool accepted = false;
  std::string note;       ///< why a candidate could not be scored, if it could not
};
struct SelectionRecord {
  std::string rule;  ///< the stopping rule, in words
  int folds = 0;
  std::vector<SelectionStep> steps;
};

/// A fitted polynomial model: what its coefficient file holds (model/model_json.h).
struct PolyModel {
  PolySpec spec;
  /// How it was made: "poly", "px4", "ardupilot" or "auto" (informative: spec says what it is).
  std::string preset = "poly";
  std::vector<Coefficient> coefficients;  ///< in spec.CoefficientNames() order
  std::string stderr_method;              ///< "cluster_runs" or "cluster_blocks" (model/linear_fit.h)
  int clusters = 0;
  double condition_number = 0.0;
  double residual_rms_dph = 0.0;
  std::vector<std::string> runs;
  std::optional<SelectionRecord> selection;  ///< auto's record

  /// The coefficients' values as a vector, in the regressors' order.
  Eigen::VectorXd Beta() const;
};

/// The causal regressors of a PolySpec (the header's equations), in CoefficientNames() order;
/// a power-on offset's reference to the B0 window is the fit's and the compensator's part
/// (model/linear_fit.h, model/linear_compensator.h).
class PolyRegressors : public CausalRegressors {
 public:
  explicit PolyRegressors(const PolySpec& spec);
  const std::vector<std::string>& channels() const override { return channels_; }
  const std::vector<std::string>& names() const override { return names_; }
  OffsetRule offset() const override { return spec_.offset; }
  double b0_window_s() const override { return spec_.offset == OffsetRule::kPowerOn ? spec_.b0_window_s : 0.0; }
  void Reset() override;
  void Next(double t_s, const double* T, double* row) override;
  std::unique_ptr<CausalRegressors> Clone() const override { return std::make_unique<PolyRegressors>(spec_); }
  bool OutsideFittedRange() const override { return outside_; }
  bool ReferredToB0Window() const override { return spec_.offset == OffsetRule::kPowerOn; }
  const PolySpec& spec() const { return spec_; }

 private:
  PolySpec spec_;
  std::vector<std::string> channels_, names_;
  std::vector<size_t> term_channel_;  ///< index into channels_ of each term's Tj (gradient)
  std::vector<RateFilter> rate_;
  std::vector<PlayOperator> play_;
  std::vector<FirstOrderLag> lag_;
  bool outside_ = false;
};

}  // namespace rlg::model

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
///   product     a product of one to four factors, each a signal of the temperature channels:
///                 Tj          Tj - T_ref (any channel, referred to the model's T_ref)
///                 (Tj-Tk)     a difference of two channels (a gradient)
///                 rate(S)     dT/dt of either (°C/min, the rate term's low-pass of tau_r)
///               spelt with '*' and '^' (a repeated factor): "T1*(T2-T1)" is the temperature x
///               gradient interaction of the Langmuir term (docs/physics.md), "(T2-T1)^2",
///               "T2" a second channel, "T1*rate(T1)"; gamma in °/h per the factors' units
///
/// Beyond the fitted range (beyond_range): `hold` clamps T to [T_min, T_max] (and each product
/// factor to the range its signal spanned in the fit), as PX4 does; `extrapolate` lets every
/// regressor continue, for models chosen on data that held whole runs out (model/model_selection.h),
/// so that a +60 °C power-on after a calibration up to +50 °C follows the polynomial. Either way
/// OutsideFittedRange says when a sample lies beyond the fitted range of any signal.
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
#include <string_view>
#include <vector>

#include "model/b0_window.h"
#include "model/causal_operators.h"
#include "model/causal_regressors.h"

namespace rlg::model {

enum class TermKind { kRate, kHysteresis, kLag, kGradient, kProduct };

/// How a polynomial model was made: fitted as asked (poly), a preset of the header above (px4,
/// ardupilot; PresetOptions, model/poly_fit.h) or selected (auto, model/model_selection.h).
enum class PolyPreset { kPoly, kPx4, kArduPilot, kAuto };
/// "poly", "px4", "ardupilot" or "auto": the model's name in `fit --model` and the file's "preset".
const char* PolyPresetName(PolyPreset preset);
/// The preset PolyPresetName names; nullopt for any other text.
std::optional<PolyPreset> ParsePolyPreset(std::string_view name);

/// "rate", "hysteresis", "lag", "gradient", "product".
const char* TermKindName(TermKind kind);
/// The kind named `name`; nullopt for another name.
std::optional<TermKind> TermKindOf(const std::string& name);

/// One factor of a product term: a signal of the temperature channels.
struct Factor {
  std::string channel;  ///< Tj
  std::string minus;    ///< Tk of a difference Tj - Tk; empty: Tj - T_ref
  bool rate = false;    ///< the signal's rate of change (°C/min) instead of its value
  /// The range the signal spanned in the fit ([lo, hi]; hold clamps to it, both flag beyond it).
  std::array<double, 2> range{0.0, 0.0};
  /// "T1", "(T2-T1)", "rate(T1)", "rate(T2-T1)".
  std::string Name() const;
  /// The value's unit: "°C" or "°C/min".
  const char* Unit() const { return rate ? "°C/min" : "°C"; }
  /// The canonical order of a product's factors: values before rates, channels before
  /// differences, then by name.
  bool operator<(const Factor& other) const;
  bool SameSignal(const Factor& other) const { return channel == other.channel && minus == other.minus && rate == other.rate; }
};

struct PolyTerm {
  TermKind kind = TermKind::kRate;
  std::string channel;   ///< gradient: the other channel Tj
  double tau_s = 0.0;    ///< rate, and a product with a rate factor: tau_r of the low-pass; lag: the lag's time constant
  double width_C = 0.0;  ///< hysteresis: w
  std::vector<Factor> factors;  ///< product: in canonical order (Factor::operator<)
  /// The coefficient's name: "rate", "hysteresis", "lag", "gradient_T2", or a product's
  /// canonical spelling "T1*(T2-T1)", "(T2-T1)^2".
  std::string Name() const;
  /// For tables: "rate (tau_r 5 s)", "hysteresis (w 1.23 °C)", "lag (tau 312 s)", "gradient T2",
  /// "T1*(T2-T1)".
  std::string Describe() const;
  /// How `fit --terms` spells it: "rate", "hysteresis", "lag", "gradient:T2", "T1*(T2-T1)".
  std::string Spelling() const;
  /// The coefficient's unit: "°/h per °C/min", "°/h/°C", "°/h/°C^2", "°/h/°C per °C/min".
  std::string CoefficientUnit() const;
  /// Rate factors of a product.
  bool HasRate() const;
};

/// A term from its `--terms` spelling for a model in `channel`: "rate", "hysteresis", "lag",
/// "gradient:Tj", or a product of factors (header) such as "T1*(T2-T1)", "(T2-T1)^2",
/// "rate(T2-T1)". A product that is one of the named terms (rate(T), (Tj-T)) becomes that term;
/// "gradient" alone (every other channel) is the fit's to expand. nullopt with `error` set for
/// anything else.
std::optional<PolyTerm> ParseTerm(const std::string& text, const std::string& channel, std::string* error);

struct PolySpec {
  std::string channel = "T1";
  int order = 3;
  OffsetRule offset = OffsetRule::kFitted;
  double reference_C = 0.0;               ///< T_ref
  std::array<double, 2> range_C{0.0, 0.0};  ///< [T_min, T_max]: T is clipped to it
  double b0_window_s = kB0Window_s;             ///< power_on only
  std::vector<PolyTerm> terms;
  bool extrapolate = false;               ///< beyond the fitted range: false hold, true extrapolate

  /// The temperature channels the regressors read: the channel, then each gradient's Tj and
  /// each product factor's channels, in order of first use.
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

/// One model `auto` scored (model/model_selection.h): the model, the move that made it from the
/// model before it on the path, and its cross-validated score inside the training data.
struct SelectionStep {
  std::string candidate;  ///< the model: "order 2, fitted + gradient:T2 + T1*(T2-T1)"
  double cv_rms_dph = 0.0;
  bool accepted = false;  ///< on the search's path (or the selected model)
  std::string note;       ///< the move ("+ T1*(T2-T1)", "- rate", "start", "selected"), or why it could not be scored
  int parameters = 0;     ///< coefficients plus fitted widths and time constants (0: not recorded)
};
struct SelectionRecord {
  std::string rule;  ///< the search and the selection rule, in words
  int folds = 0;
  std::vector<SelectionStep> steps;    ///< the path: each move taken, then the selected model
  std::vector<SelectionStep> visited;  ///< every model scored (`compare --json`; not in the coefficient file)
};

/// A fitted polynomial model: what its coefficient file holds (model/model_json.h).
struct PolyModel {
  PolySpec spec;
  /// How it was made (informative: spec says what it is).
  PolyPreset preset = PolyPreset::kPoly;
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
  bool Extrapolates() const override { return spec_.extrapolate; }
  bool ReferredToB0Window() const override { return spec_.offset == OffsetRule::kPowerOn; }
  const PolySpec& spec() const { return spec_; }

 private:
  PolySpec spec_;
  std::vector<std::string> channels_, names_;
  std::vector<size_t> term_channel_;  ///< index into channels_ of each term's Tj (gradient)
  std::vector<RateFilter> rate_;
  std::vector<PlayOperator> play_;
  std::vector<FirstOrderLag> lag_;
  /// A product factor: its channels' indices into channels_ (minus: -1 for Tj - T_ref) and its
  /// rate filter (-1 for a value).
  struct FactorSlot {
    size_t a = 0;
    long minus = -1;
    long rate = -1;
    std::array<double, 2> range{0.0, 0.0};
  };
  std::vector<std::vector<FactorSlot>> product_;  ///< per term (empty for the other kinds)
  bool outside_ = false;
};

}  // namespace rlg::model

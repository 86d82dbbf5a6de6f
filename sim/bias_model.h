#pragma once
/// Deterministic bias physics of the gyro (°/h), evaluated at each output sample from the
/// node temperatures T (°C) and their rates Tdot (°C/s). Noise is added elsewhere (noise.h).
///
///   B = B_intr + B_L + B_PLC + sum of catalog bias effects
///   B_intr = b0 + b1 (T_b - T_ref) + b2 (T_b - T_ref)^2                 intrinsic, T_b = bias node
///   B_L    = (1 + c_T (T_b - T_ref)) (k_I dI + sum_g k_g (T_g1 - T_g2))   Langmuir flow: leg-current
///            imbalance dI (mA) and temperature gradients along the discharge legs
///   B_PLC  = k_plc u,  u = (T_b - T_lock) / dT_mode - m                  path-length control travel
///            in wavelengths; dT_mode = lambda / (L alpha) is the block excursion per mode
///
/// Catalog effects (scenarios/README.md, Effects), all off unless configured; each term is its effect's
/// static Bias_dph (sim/effects/), the function `diagnose`'s regressors call too:
///   bias.temperature_rate  + k dT_n/dt            (k in °/h per °C/min)
///   bias.gradient          + k (T_a - T_b)
///   bias.hysteresis        + sum of k_heat dT_n while heating, k_cool dT_n while cooling
///   bias.play              + k (p - T_ref), p the node's temperature through a play of width w
///   bias.mode_hop          the PLC resets by one mode when |u| > range; the bias steps by
///                          step_dph per mode index m (m = 0 without this effect: the PLC has
///                          unlimited range)
/// T_lock is the bias-node temperature at power-on (the PLC powers on centred on a mode), or,
/// given a mode centre T_c (mode_hop_centre_C), T_c: the PLC powers on at the mode nearest the
/// centre of its travel, m0 = round((T_b(0) - T_c) / dT_mode) (PowerOn), so each run's
/// power-on phase follows from its absolute cavity length.
///
/// The baseline terms (intrinsic, Langmuir, PLC) are the free functions below, which both
/// BiasModel and `diagnose`'s linear bias fit (BaselineRegressors) call.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace rlg::sim {

struct BiasParams {
  int node = 0;               ///< node whose temperature drives intrinsic and PLC terms (block)
  double reference_C = 20.0;  ///< T_ref
  double b0_dph = 0.0;
  double b1_dph_per_C = 0.0;
  double b2_dph_per_C2 = 0.0;

  double langmuir_current_imbalance_mA = 0.0;
  double langmuir_dph_per_mA = 0.0;
  double langmuir_temperature_coeff_per_C = 0.0;  ///< c_T
  struct Gradient {
    int a = 0;
    int b = 0;
    double k_dph_per_C = 0.0;
  };
  std::vector<Gradient> langmuir_gradients;  ///< flow driven by T_a - T_b along a leg

  double path_length_m = 0.43;        ///< cavity perimeter L
  double cte_per_C = 5e-8;            ///< alpha
  double wavelength_m = 632.8e-9;     ///< HeNe
  double plc_dph_per_wavelength = 0.0;  ///< k_plc

  // Catalog effects.
  struct Rate {
    int node = 0;
    double k_dph_per_C_per_min = 0.0;
  };
  std::vector<Rate> rate_terms;
  std::vector<Gradient> extra_gradients;
  struct Hysteresis {
    int node = 0;
    double k_heating_dph_per_C = 0.0;
    double k_cooling_dph_per_C = 0.0;
  };
  std::vector<Hysteresis> hysteresis;
  struct Play {
    int node = 0;
    double k_dph_per_C = 0.0;
    double width_C = 0.0;
    double reference_C = 20.0;
  };
  std::vector<Play> play;  ///< bias.play
  bool mode_hops = false;
  double mode_hop_step_dph = 0.0;
  double mode_hop_range_modes = 0.6;  ///< PLC half-range in modes; > 0.5 gives hysteresis
  double mode_spacing_C = 0.0;        ///< 0: derived as lambda / (L alpha)
  /// A bias-node temperature (°C) at which a mode sits at the centre of the PLC's travel (any
  /// one of them: they repeat every dT_mode); NaN: every run powers on centred on a mode.
  double mode_hop_centre_C = std::numeric_limits<double>::quiet_NaN();

  double ModeSpacing_C() const;
};

/// dT = T_b - T_ref (°C): the bias node's temperature above the reference.
inline double BiasNodeExcess_C(const BiasParams& p, double T_b_C) { return T_b_C - p.reference_C; }

/// Intrinsic term (°/h): b0 + b1 dT + b2 dT².
double IntrinsicBias_dph(double b0_dph, double b1_dph_per_C, double b2_dph_per_C2, double dT_C);

/// Temperature difference along a discharge leg (°C): T_a - T_b, T_C[i] node i's temperature.
inline double LegGradient_C(const BiasParams::Gradient& g, const double* T_C) { return T_C[g.a] - T_C[g.b]; }

/// Langmuir flow term (°/h): (1 + c_T dT) (k_I dI + sum_g k_g (T_g1 - T_g2)).
double LangmuirBias_dph(const BiasParams& p, const double* T_C, double dT_C);

/// Path-length control travel u in wavelengths, u = (T_b - T_lock) / dT_mode - m, after the
/// resets of a finite half-range: while |u| > range_modes the control jumps one mode (m moves
/// by one, u by one wavelength back). range_modes = infinity: it never resets.
/// In two steps: LockTravel, (T_b - T_lock) / dT_mode, then ResetTravel, which moves m. The
/// mode-hop search (diagnosis/catalog/mode_hop_search.cpp) takes LockTravel at the extreme
/// temperatures of a stretch of samples: where neither resets, no sample of the stretch does.
inline double LockTravel(double T_b_C, double T_lock_C, double mode_spacing_C) {
  return (T_b_C - T_lock_C) / mode_spacing_C;
}

/// The most modes a control travels in one sample, |u| before its resets, and the largest mode
/// index |m| it reaches: beyond either (or at a non-finite temperature, with a finite range)
/// ResetTravel gives NaN and leaves m as it was, which the simulator refuses
/// (sim/trace_limits.h), rather than a mode index past what an int holds. 1e9 modes are some
/// 1e8 °C of a real cavity's ~0.1-0.5 °C per mode: no temperature a simulation reaches.
inline constexpr double kMaxModeTravel = 1e9;

/// The fewest whole k >= 1 with u - k <= range_modes, for u > range_modes: ceil of the rounded
/// u - range_modes is never above it (rounding cannot carry a value past a whole number) and at
/// most one below it, which the loop adds; u - k itself is exact (ResetTravel).
inline double FewestJumps(double u, double range_modes) {
  double k = std::max(1.0, std::ceil(u - range_modes));
  while (u - k > range_modes) k += 1.0;
  return k;
}

/// The jumps are counted at once, not one per loop: the same m and u as jumping one mode at a
/// time (for |u| < 2^52, u - k is exact for every whole k up to |u| + 1, so subtracting k at once
/// is subtracting 1 k times), first up while u > range_modes, then down while u < -range_modes
/// (the jumps up of -u), as a loop of single jumps does them (with range_modes below 1/2 the
/// second can undo the first).
inline double ResetTravel(double lock_travel, double range_modes, int& mode) {
  double u = lock_travel - mode;
  if (!(u > range_modes) && !(u < -range_modes)) return u;  // within the range, or NaN
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!(std::abs(u) <= kMaxModeTravel)) return kNaN;
  double up = 0.0, down = 0.0;
  if (u > range_modes) {
    up = FewestJumps(u, range_modes);
    u -= up;
  }
  if (u < -range_modes) {
    down = FewestJumps(-u, range_modes);
    u += down;
  }
  const double to = static_cast<double>(mode) + up - down;  // exact: all below 2^53
  if (!(std::abs(to) <= kMaxModeTravel)) return kNaN;
  mode = static_cast<int>(to);
  return u;
}
inline double PathLengthTravel(double T_b_C, double T_lock_C, double mode_spacing_C, double range_modes, int& mode) {
  return ResetTravel(LockTravel(T_b_C, T_lock_C, mode_spacing_C), range_modes, mode);
}

/// Where the path-length control locks at power-on, with the bias node at T_b (°C): the lock
/// point T_lock of its travel u and the mode index m it starts on.
struct PlcLock {
  double T_lock_C = 0.0;
  int mode = 0;
};
/// Without a mode centre (centre_C NaN) the PLC powers on centred on a mode: T_lock = T_b,
/// m = 0. With one, on the mode nearest the centre of its travel: T_lock = T_c and m0 =
/// round((T_b - T_c) / dT_mode), the index of modes centred at T_c + m dT_mode, so |u| <= 1/2.
/// A start beyond kMaxModeTravel modes from the centre (or non-finite) starts on mode 0: its
/// first ResetTravel then gives NaN.
inline PlcLock PowerOn(double T_b_C, double centre_C, double mode_spacing_C) {
  if (std::isnan(centre_C)) return {T_b_C, 0};
  const double modes = (T_b_C - centre_C) / mode_spacing_C;
  if (!(std::abs(modes) <= kMaxModeTravel)) return {centre_C, 0};
  return {centre_C, static_cast<int>(std::lround(modes))};
}

/// The baseline bias (intrinsic, Langmuir, PLC within one mode) as a linear model for fitting:
///   B = c_run + beta . x,   x = (dT, dT², then per Langmuir gradient G, G dT)
///   beta = (b1 + c_T k_I dI + k_plc / dT_mode, b2, then per gradient k, k c_T)
/// which is exact: c_run takes b0, k_I dI and the PLC's -T_lock / dT_mode, constant in a run.
/// The intrinsic regressors are IntrinsicBias_dph at unit coefficients (the same function, to
/// the bit: 1 x = x and 0 x + y = y); the Langmuir ones are its leg gradient and that times dT.
int NumBaselineRegressors(const BiasParams& p);
/// x at node temperatures T_C (°C) into `x` (NumBaselineRegressors entries).
void BaselineRegressors(const BiasParams& p, const Eigen::Ref<const Eigen::VectorXd>& T_C,
                        Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> x);
/// beta of a gyro file's bias parameters, in the order of x.
std::vector<double> BaselineCoefficients(const BiasParams& p);

class BiasModel {
 public:
  /// History the bias depends on: PLC lock point and mode index, hysteresis integrals.
  struct State {
    double T_lock = 0.0;
    int mode = 0;
    std::vector<double> last_T;
    std::vector<double> hysteresis_dph;
    std::vector<double> play_C;  ///< bias.play's operator outputs
  };

  explicit BiasModel(BiasParams params);
  const BiasParams& params() const { return p_; }
  /// Whether Evaluate reads the temperatures' rates (a rate term); without, Tdot is not read.
  bool UsesRates() const { return !p_.rate_terms.empty(); }

  /// Captures the power-on state (T at t = 0).
  State Start(const Eigen::Ref<const Eigen::VectorXd>& T) const;
  /// Bias at a sample, advancing the history in `state`. Call once per sample, in time order.
  double Evaluate(const Eigen::Ref<const Eigen::VectorXd>& T, const Eigen::Ref<const Eigen::VectorXd>& Tdot,
                  State& state) const;
  /// The biases of n consecutive samples into out[0..n), as n calls of Evaluate: sample j's node
  /// temperatures at T[j * stride + i] and their rates at Tdot[j * stride + i]. The simulator
  /// calls it once per block of samples.
  void Evaluate(const double* T, const double* Tdot, size_t stride, size_t n, double* out, State& state) const;

 private:
  BiasParams p_;
  double mode_spacing_C_;
};

}  // namespace rlg::sim

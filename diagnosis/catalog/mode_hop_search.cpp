#include "diagnosis/catalog/mode_hop_search.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include "diagnosis/catalog/searches.h"
#include "sim/bias_model.h"
#include "sim/effects/mode_hop.h"

namespace rlg::diagnosis {
namespace {

// [est] A typical step: a few times a navigation-grade gyro's 100 s noise (docs/physics.md).
constexpr double kTypical = 0.05;

// The search of Regressors. Spacings from 3 °C (hops closer than that are a staircase finer
// than a gyro block's excursion within a 10 s fit block on a ramp, seen as a slope) to 150 °C
// (5 times the default gyro's 29 K, 2x docs/physics.md's upper estimate; [est]) on a grid of 10 %
// steps, each at 6 centres; three ranges from none to strong hysteresis. The pattern search
// then halves the steps 10 times: 0.005 % in spacing, 1/6144 of a spacing in centre, 1e-4 in
// range, finer than a sample of a 2 °C/min ramp at 1 s moves a 30 °C spacing's edge.
constexpr double kMinSearchSpacing_C = 3.0, kMaxSearchSpacing_C = 150.0;
constexpr double kSpacingRatio = 1.1;
constexpr int kSearchPhases = 6;
constexpr double kSearchRanges[] = {0.5, 0.65, 0.85};
constexpr double kMaxSearchRange = 2.0;
constexpr int kRefineHalvings = 10;
constexpr size_t kStarts = 3;  // pattern searches per form, from the best grid points of distinct spacings
constexpr int kStartHalvings = 4;  // each start's halvings before the best goes on alone

/// bias.mode_hop: the bias node, its shape searched (mode_hop_search.h).
class ModeHop final : public EffectSearch {
 public:
  ModeHop()
      : EffectSearch("bias.mode_hop", {{"step_dph", {kTypical}},
                                       {"range_modes", {0.6, ParameterSearch::Fit::kShape}},
                                       {"mode_spacing_C", {30.0, ParameterSearch::Fit::kShape}},
                                       {"centre_C", {20.0, ParameterSearch::Fit::kShape}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    return {sim::NodeTarget(space.gyro, space.gyro.bias.node)};
  }
  std::vector<BiasRegressor> Regressors(const TargetSpace& space, const std::vector<const Eigen::MatrixXd*>& T_runs,
                                        const ColumnGain& gain) const override;
  double Implausibility(const sim::ParameterMap& reported) const override {
    return Relative(reported, "step_dph", kTypical);
  }
};

/// A shape and its column's gain; -1: the shape makes no run hop.
struct Scored {
  ModeHopShape shape;
  double gain = -1.0;
};

/// The shape search on one model's tracks: which spacings they can show, a centre's canonical
/// form, a shape's gain, the grid and the pattern search. [0] is the centred power-on form, [1]
/// the form locked by an absolute centre.
class ShapeSearch {
 public:
  ShapeSearch(const sim::BiasParams& bias, const std::vector<const Eigen::MatrixXd*>& T_runs, const ColumnGain& gain)
      : tracks_(T_runs, bias.node), gain_(gain), ref_(bias.reference_C) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto* T : T_runs) {
      if (T->cols() == 0) continue;
      lo = std::min(lo, T->row(bias.node).minCoeff());
      hi = std::max(hi, T->row(bias.node).maxCoeff());
    }
    // Spacings the tracks can show: a hop needs the bias node to move by half a spacing (the
    // least range) in a run; beyond twice the span at most one edge is crossed, whatever the
    // spacing, so wider spacings show nothing new.
    spacing_hi_ = std::min(kMaxSearchSpacing_C, 2.0 * (hi - lo));
    if (!Possible()) return;
    // A geometric grid through the gyro file's spacing (kept when it lies inside).
    const double nominal = bias.ModeSpacing_C();
    for (int k = static_cast<int>(std::floor(std::log(kMinSearchSpacing_C / nominal) / step_));
         k <= static_cast<int>(std::ceil(std::log(spacing_hi_ / nominal) / step_)); ++k) {
      const double s = nominal * std::exp(k * step_);
      if (s >= kMinSearchSpacing_C && s <= spacing_hi_) spacings_.push_back(s);
    }
  }

  /// Whether the tracks span enough for the least spacing to show.
  bool Possible() const { return spacing_hi_ >= kMinSearchSpacing_C; }
  /// The tracks with their stretches' extremes, for the chosen shapes' columns.
  const ModeTracks& tracks() const { return tracks_; }

  /// Per form, the best shape: the best grid point of each spacing, then the pattern search
  /// from the kStarts best of those: a staircase's gain is a narrow ridge in spacing and
  /// centre, and the single best grid point lay in another basin (the reference generator's
  /// 13 °C reversible hops at 1 s samples: its grid's best was a 57 °C spacing at gain 12.2,
  /// where the truth's shape gains 31.3).
  std::array<Scored, 2> Best() const {
    std::array<std::vector<Scored>, 2> per_spacing = Grid();
    std::array<Scored, 2> best;
    for (int f = 0; f < 2; ++f) {
      auto& starts = per_spacing[f];
      const size_t n = std::min<size_t>(kStarts, starts.size());
      std::partial_sort(starts.begin(), starts.begin() + static_cast<std::ptrdiff_t>(n), starts.end(),
                        [](const Scored& a, const Scored& b) { return a.gain > b.gain; });
      // Each start its first halvings; the best of them on to the last.
      for (size_t i = 0; i < n; ++i) {
        const Scored b = Refine(starts[i], 0, kStartHalvings);
        if (b.gain > best[f].gain) best[f] = b;
      }
      if (best[f].gain >= 0.0) best[f] = Refine(best[f], kStartHalvings, kRefineHalvings);
    }
    return best;
  }

 private:
  /// A centre is defined modulo its spacing: the one within half a spacing of the bias
  /// reference temperature is reported.
  ModeHopShape Canonical(ModeHopShape s) const {
    if (s.centred) return s;
    const double phase = std::fmod(std::fmod((s.centre_C - ref_) / s.spacing_C + 0.5, 1.0) + 1.0, 1.0);
    s.centre_C = ref_ + s.spacing_C * (phase - 0.5);
    return s;
  }

  /// The gain of shape s's column; -1 when no run hops.
  double Gain(const ModeHopShape& s) const {
    bool hops = false;
    const auto column = tracks_.ModeIndex(s, &hops);
    return hops ? gain_(column) : -1.0;
  }
  /// The same for a grid point: the grid is the same on every search of these tracks, so its
  /// columns are asked for by their shape (ColumnGain::Keyed).
  double GridGain(const ModeHopShape& s) const {
    return gain_.Keyed({s.spacing_C, s.range_modes, s.centre_C, s.centred ? 1.0 : 0.0}, [&]() -> std::optional<RunColumn> {
      bool hops = false;
      RunColumn column = tracks_.ModeIndex(s, &hops);
      if (!hops) return std::nullopt;
      return column;
    });
  }

  /// Per form, the best grid point of each spacing (ranges x phases).
  std::array<std::vector<Scored>, 2> Grid() const {
    std::array<std::vector<Scored>, 2> per_spacing;
    for (double s : spacings_) {
      Scored here[2];
      auto consider = [&](const ModeHopShape& shape) {
        const double g = GridGain(shape);
        Scored& b = here[shape.centred ? 0 : 1];
        if (g > b.gain) b = {shape, g};
      };
      for (double range : kSearchRanges) {
        consider({s, range, 0.0, true});
        for (int j = 0; j < kSearchPhases; ++j)
          consider(Canonical({s, range, ref_ + s * (static_cast<double>(j) / kSearchPhases - 0.5), false}));
      }
      for (int f = 0; f < 2; ++f)
        if (here[f].gain >= 0.0) per_spacing[f].push_back(here[f]);
    }
    return per_spacing;
  }

  /// Pattern search from `b` over spacing (log), range and, for the absolute form, the centre:
  /// every move of -1, 0 or +1 step in each (diagonals too: spacing and range trade along a
  /// ridge, as both move the same edges), each step halved when no move improves; halvings
  /// first..last of the grid's steps.
  Scored Refine(Scored b, int first, int last) const {
    const int dims = b.shape.centred ? 2 : 3;
    const double shrink = std::ldexp(1.0, -first);
    double d_log = 0.5 * step_ * shrink, d_range = 0.5 * (kSearchRanges[1] - kSearchRanges[0]) * shrink,
           d_phase = 0.5 / kSearchPhases * shrink;
    int moves = 1;
    for (int d = 0; d < dims; ++d) moves *= 3;
    for (int halving = first; halving < last; ++halving) {
      for (bool moved = true; moved;) {
        moved = false;
        const ModeHopShape from = b.shape;
        for (int code = 0; code < moves; ++code) {
          const int a = code % 3 - 1, r = code / 3 % 3 - 1, c = dims == 3 ? code / 9 - 1 : 0;
          if (a == 0 && r == 0 && c == 0) continue;
          ModeHopShape s = from;
          s.spacing_C *= std::exp(a * d_log);
          s.range_modes += r * d_range;
          s.centre_C += c * d_phase * from.spacing_C;
          if (s.spacing_C < kMinSearchSpacing_C || s.spacing_C > spacing_hi_) continue;
          if (s.range_modes < 0.5 || s.range_modes > kMaxSearchRange) continue;
          s = Canonical(s);
          const double g = Gain(s);
          if (g > b.gain) {
            b = {s, g};
            moved = true;
          }
        }
      }
      d_log *= 0.5;
      d_phase *= 0.5;
      d_range *= 0.5;
    }
    return b;
  }

  const ModeTracks tracks_;
  const ColumnGain& gain_;
  const double ref_;
  const double step_ = std::log(kSpacingRatio);  ///< the grid's spacing step, log units
  double spacing_hi_ = 0.0;
  std::vector<double> spacings_;
};

std::vector<BiasRegressor> ModeHop::Regressors(const TargetSpace& space,
                                               const std::vector<const Eigen::MatrixXd*>& T_runs,
                                               const ColumnGain& gain) const {
  const sim::BiasParams& bias = space.gyro.bias;
  const ShapeSearch search(bias, T_runs, gain);
  if (!search.Possible()) return {};
  // The column shares its data by value: it outlives this call when a candidate is accepted.
  std::vector<BiasRegressor> out;
  const double plc = bias.plc_dph_per_wavelength;
  for (const Scored& b : search.Best()) {
    if (b.gain < 0.0) continue;
    bool hops = false;
    auto modes = std::make_shared<std::vector<std::vector<double>>>(search.tracks().ModeIndex(b.shape, &hops));
    const ModeHopShape shape = b.shape;
    out.push_back({sim::NodeTarget(space.gyro, bias.node),
                   [modes](const NodeTrack&, size_t k, int r) { return (*modes)[static_cast<size_t>(r)][k]; },
                   [plc, shape](double c) {
                     // The PLC term resets with each hop, so the step seen is step - k_plc.
                     sim::ParameterMap p{{"step_dph", c + plc},
                                         {"range_modes", shape.range_modes},
                                         {"mode_spacing_C", shape.spacing_C}};
                     if (!shape.centred) p["centre_C"] = shape.centre_C;
                     return p;
                   },
                   shape.centred ? 2 : 3});
  }
  return out;
}

}  // namespace

std::vector<std::vector<double>> ModeIndex(const std::vector<const Eigen::MatrixXd*>& T_runs, int node,
                                          const ModeHopShape& shape, bool* hops) {
  return ModeTracks(T_runs, node).ModeIndex(shape, hops);
}

ModeTracks::ModeTracks(const std::vector<const Eigen::MatrixXd*>& T_runs, int node) : T_runs_(T_runs), node_(node) {
  extremes_.resize(T_runs.size());
  for (size_t r = 0; r < T_runs.size(); ++r) {
    const Eigen::MatrixXd& T = *T_runs[r];
    const auto n = static_cast<size_t>(T.cols());
    for (size_t k0 = 0; k0 < n; k0 += kStretch) {
      // NaN is in neither (its travel moves no mode); a stretch of NaN only is taken sample by sample.
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (size_t k = k0; k < std::min(n, k0 + kStretch); ++k) {
        const double v = T(node, static_cast<Eigen::Index>(k));
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
      }
      extremes_[r].emplace_back(lo, hi);
    }
  }
}

std::vector<std::vector<double>> ModeTracks::ModeIndex(const ModeHopShape& shape, bool* hops) const {
  std::vector<std::vector<double>> out(T_runs_.size());
  *hops = false;
  for (size_t r = 0; r < T_runs_.size(); ++r) {
    const Eigen::MatrixXd& T = *T_runs_[r];
    auto& m = out[r];
    m.resize(static_cast<size_t>(T.cols()));
    if (m.empty()) continue;
    const sim::PlcLock on = sim::PowerOn(T(node_, 0), shape.centred ? std::numeric_limits<double>::quiet_NaN() : shape.centre_C,
                                         shape.spacing_C);
    int mode = on.mode;
    for (size_t c = 0; c < extremes_[r].size(); ++c) {
      const size_t k0 = c * kStretch, k1 = std::min(m.size(), k0 + kStretch);
      // sim::PathLengthTravel's reset test at the stretch's extremes: within the range at both,
      // within it at every sample (the same operations, and rounding keeps their order; a
      // spacing that is not positive would reverse it, so it goes sample by sample).
      const double u_lo = sim::LockTravel(extremes_[r][c].first, on.T_lock_C, shape.spacing_C) - mode;
      const double u_hi = sim::LockTravel(extremes_[r][c].second, on.T_lock_C, shape.spacing_C) - mode;
      if (shape.spacing_C > 0.0 && u_hi <= shape.range_modes && u_lo >= -shape.range_modes) {
        std::fill(m.begin() + static_cast<std::ptrdiff_t>(k0), m.begin() + static_cast<std::ptrdiff_t>(k1),
                  sim::ModeHopEffect::Bias_dph(1.0, mode));
        continue;
      }
      // A travel beyond sim::kMaxModeTravel (or at a non-finite temperature) is NaN and leaves
      // the mode as it was: such a shape is flat there, and fits badly, rather than hanging.
      for (size_t k = k0; k < k1; ++k) {
        sim::PathLengthTravel(T(node_, static_cast<Eigen::Index>(k)), on.T_lock_C, shape.spacing_C, shape.range_modes, mode);
        m[k] = sim::ModeHopEffect::Bias_dph(1.0, mode);
        *hops = *hops || mode != on.mode;
      }
    }
  }
  return out;
}

namespace catalog {
std::unique_ptr<const EffectSearch> ModeHopSearch() { return std::make_unique<ModeHop>(); }
}  // namespace catalog

}  // namespace rlg::diagnosis

#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <map>
#include <optional>
#include <type_traits>
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include "sim/bias_model.h"
#include "sim/errors.h"
#include "sim/exact_linear.h"
#include "sim/noise.h"
#include "sim/simd.h"
#include "sim/trace_limits.h"

namespace rlg::sim {

ThermalSystem::ThermalSystem(const ThermalNetwork& network, Profile ambient, std::vector<Profile> power)
    : network_(network), ambient_(std::move(ambient)), power_(std::move(power)) {
  if (static_cast<int>(power_.size()) != network_.num_sources()) {
    throw std::logic_error("ThermalSystem: one power profile per source required");
  }
}

void ThermalSystem::Power(double t, Eigen::VectorXd& p) const {
  p.resize(static_cast<Eigen::Index>(power_.size()));
  for (size_t s = 0; s < power_.size(); ++s) p[static_cast<Eigen::Index>(s)] = power_[s].Value(t);
}

void ThermalSystem::CalcTimeDerivatives(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                                        Eigen::Ref<Eigen::VectorXd> xdot, OdeScratch& scratch) const {
  Power(t, scratch.inputs);
  network_.CalcTimeDerivatives(x, ambient_.Value(t), scratch.inputs, xdot);
}

void ThermalSystem::CalcJacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                                 Eigen::Ref<Eigen::MatrixXd> J, OdeScratch& scratch) const {
  Power(t, scratch.inputs);
  network_.CalcJacobian(x, ambient_.Value(t), scratch.inputs, J);
}

void ThermalSystem::Inputs(double t, Eigen::VectorXd& u) const {
  u.resize(1 + static_cast<Eigen::Index>(power_.size()));
  u[0] = ambient_.Value(t);
  for (size_t s = 0; s < power_.size(); ++s) u[1 + static_cast<Eigen::Index>(s)] = power_[s].Value(t);
}

bool ThermalSystem::SolvableExactly() const {
  if (!network_.linear_at_constant_power() || ambient_.kind() == Profile::Kind::kSine) return false;
  for (size_t s = 0; s < power_.size(); ++s) {
    const Profile::Kind kind = power_[s].kind();
    if (kind == Profile::Kind::kSine) return false;
    const bool drifts = network_.spec().sources[s].drift_per_K != 0.0;
    if (drifts && kind != Profile::Kind::kConstant && kind != Profile::Kind::kSteps) return false;
  }
  return true;
}

std::vector<double> ThermalSystem::Breakpoints(double t0, double t1) const {
  std::vector<double> out;
  auto add = [&](const Profile& p) {
    for (double b : p.Breakpoints())
      if (b > t0 && b < t1) out.push_back(b);
  };
  add(ambient_);
  for (const auto& p : power_) add(p);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

using Visitor = std::function<void(size_t, double, const Eigen::VectorXd&, const Eigen::VectorXd&)>;

// The integrators are templates on the visitor so that SimulateRun's is inlined into the
// sample loop (a std::function costs an indirect call per sample); IntegrateThermal passes its
// std::function through the same code.
template <class Visit>
void IntegrateWithCvode(const ThermalSystem& system, const std::vector<double>& times, const std::vector<double>& breaks,
                        Eigen::VectorXd x, const IntegratorOptions& options, Visit& visit) {
  CvodeIntegrator integrator(system, options);
  OdeScratch scratch;  // the sample loop's; the integrator keeps its own
  Eigen::VectorXd xdot(system.size());
  integrator.Reset(times.front(), x);
  size_t next_break = 0;
  double t_now = times.front();
  for (size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    // Cross every breakpoint up to t: stop exactly on it and restart the BDF history there.
    // At a kink (a logged ambient's point) a restart is not needed for accuracy, but it keeps
    // the output a smooth function of the network's parameters, which diagnose's forward-
    // difference Jacobians need: carried across the kinks of a 100 s-point ambient, CVODE at
    // tol 3e-9 was more accurate (1.3 against 3.0 uK off a radiating network's solution at 1e-12)
    // but the derivative by emissivity at a relative step of 1e-6 was off by 450 % (2e-6 % with
    // restarts), and a radiation refit lost a sixth of its score.
    while (next_break < breaks.size() && breaks[next_break] <= t) {
      const double tb = breaks[next_break++];
      if (tb > t_now) {
        integrator.AdvanceTo(tb, tb, x);
        integrator.Reset(tb, x);
        t_now = tb;
      }
    }
    if (t > t_now) {
      integrator.AdvanceTo(t, next_break < breaks.size() ? breaks[next_break] : times.back(), x);
      t_now = t;
    }
    system.CalcTimeDerivatives(t, x, xdot, scratch);
    visit(k, t, x, xdot);
  }
}

/// The exact propagators of a system: one for a linear network; with power drift, one per set
/// of the drifting sources' (piecewise-constant) powers, whose drift is then folded into A.
class PiecePropagators {
 public:
  explicit PiecePropagators(const ThermalNetwork& network) : network_(network) {
    if (!network.has_drift()) linear_.emplace(network);
  }
  /// The propagator for a piece with inputs u = [T_amb, P]; rewrites the drifting powers in u
  /// to their constant part P0 (1 - g T_ref).
  ExactLinearPropagator& For(Eigen::VectorXd& u) {
    if (linear_) return *linear_;
    Eigen::VectorXd p = u.tail(u.size() - 1);
    const std::vector<double> key(p.data(), p.data() + p.size());
    network_.FoldDrift(p, A_);
    u.tail(u.size() - 1) = p;
    auto it = by_power_.find(key);
    if (it == by_power_.end()) {
      if (by_power_.size() >= 256) by_power_.clear();  // a bound for long runs of ever new powers
      it = by_power_.emplace(key, ExactLinearPropagator(network_, A_)).first;
    }
    return it->second;
  }

 private:
  const ThermalNetwork& network_;
  std::optional<ExactLinearPropagator> linear_;
  std::map<std::vector<double>, ExactLinearPropagator> by_power_;
  Eigen::MatrixXd A_;  // FoldDrift's output, scratch
};

/// The simulator's visitor: it keeps each sample's state (and its derivative, when `rates`) as
/// sample k - first of a block of `block` samples, `stride` values each, and hands every full
/// block (and the last, partial one) to `flush(first, last)`. IntegrateExactly<N> runs the
/// regular samples of a block in a loop of their own (RegularSamples), the state in a local
/// array and the flush after the loop: an Eigen vector passed by reference, and a call in the
/// loop though taken once a block, kept the state in memory, a store and a reload on every
/// sample's dependent chain (perf: half the stage's samples on that reload). Other visitors (a
/// std::function) get Eigen::VectorXd.
/// rates = false: the visitor reads no derivative (the simulator's, when no bias term takes a
/// rate), so the regular samples' steps make the state alone and pass a stale xdot.
template <class Flush>
struct BlockVisitor {
  double* x;
  double* xdot;
  size_t stride, block, n_samples;
  bool rates;
  Flush& flush;
  size_t first = 0;  // the current block's first sample

  /// The current block's last sample.
  size_t Last() const { return std::min(first + block, n_samples) - 1; }
  /// Keeps sample k of the current block; Last() >= k.
  template <class X, class D>
  [[gnu::always_inline]] void Store(size_t k, const X& x_k, const D& xdot_k) {
    using Column = Eigen::Matrix<double, X::RowsAtCompileTime, 1>;
    const auto n = static_cast<Eigen::Index>(stride);
    Eigen::Map<Column>(x + (k - first) * stride, n) = x_k;
    if (rates) Eigen::Map<Column>(xdot + (k - first) * stride, n) = xdot_k;
  }
  /// Store for N states in plain arrays (the derivative only if kRates).
  template <int N, bool kRates>
  [[gnu::always_inline]] void StoreArray(size_t k, const double* x_k, const double* xdot_k) {
    double* const to = x + (k - first) * stride;
    for (int r = 0; r < N; ++r) to[r] = x_k[r];
    if constexpr (kRates) {
      double* const dot_to = xdot + (k - first) * stride;
      for (int r = 0; r < N; ++r) dot_to[r] = xdot_k[r];
    }
  }
  /// Hands the block on if k is its last sample.
  void EndSample(size_t k) {
    if (k != Last()) return;
    flush(first, k);
    first = k + 1;
  }
  template <class X, class D>
  void operator()(size_t k, double, const X& x_k, const D& xdot_k) {
    Store(k, x_k, xdot_k);
    EndSample(k);
  }
};
template <class Visit>
inline constexpr bool kIsBlockVisitor = false;
template <class F>
inline constexpr bool kIsBlockVisitor<BlockVisitor<F>> = true;

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// Steps from sample k - 1 to k, a regular sample of the current piece (step h_piece, inputs
/// affine from t_piece), and on over the regular samples after it, each kept by the visitor,
/// until the visitor's block ends, a sample reaches the next breakpoint or the step changes.
/// Returns the last sample taken.
template <int N, bool kRates, class Visit>
[[gnu::always_inline]] inline size_t RegularSamples(const ExactLinearPropagator& propagator, const std::vector<double>& times,
                                                    double next_break_t, double t_piece, double h_piece, size_t k,
                                                    Eigen::Matrix<double, N, 1>& x, double* xdot, Visit& visit) {
  const size_t last = visit.Last();
  // The state in a local array whose address is not taken outside this loop: kept in registers
  // (in an Eigen vector passed by reference it went through memory, a store and a reload on the
  // chain from one sample to the next).
  double s[N], sdot[N];
  for (int r = 0; r < N; ++r) s[r] = x[r], sdot[r] = xdot[r];
  for (;; ++k) {
    propagator.template AdvanceFixed<N, kRates>(times[k - 1] - t_piece, s, sdot);
    visit.template StoreArray<N, kRates>(k, s, sdot);
    if (k == last || next_break_t <= times[k + 1] || !(times[k + 1] - times[k] == h_piece)) break;
  }
  for (int r = 0; r < N; ++r) x[r] = s[r], xdot[r] = sdot[r];
  return k;
}

/// N > 0: a network of N states, whose regular samples keep the state in registers
/// (ExactLinearPropagator::AdvanceFixed); N = 0: any size.
template <int N, class Visit>
[[gnu::always_inline]] inline void IntegrateExactlyLoop(const ThermalSystem& system, const std::vector<double>& times,
                                                        const std::vector<double>& breaks, Eigen::VectorXd x, Visit& visit) {
  using State = Eigen::Matrix<double, (N > 0 ? N : 1), 1>;
  State x_fixed = State::Zero();  // x between the breakpoints' steps when N > 0
  if constexpr (N > 0) x_fixed = x;
  PiecePropagators propagators(system.network());
  ExactLinearPropagator* propagator = nullptr;  // the current piece's
  OdeScratch scratch;
  Eigen::VectorXd xdot(system.size()), u_a, u_mid, v;
  // A piece [a, b] between breakpoints has linear inputs: the value at its start and at its
  // midpoint give the slope exactly, whatever jumps happen at its ends. Drifting powers are
  // constant over it (SolvableExactly), so their slope is zero before and after folding.
  auto linear_inputs = [&](double a, double b, Eigen::VectorXd& u, Eigen::VectorXd& slope) {
    system.Inputs(a, u);
    if (b > a) {
      system.Inputs(a + 0.5 * (b - a), u_mid);
      slope = (u_mid - u) / (0.5 * (b - a));
    } else {
      slope = Eigen::VectorXd::Zero(u.size());
    }
    propagator = &propagators.For(u);
  };
  auto piece = [&](double a, double b) {
    linear_inputs(a, b, u_a, v);
    propagator->Step(b - a, u_a, v, x, xdot);
  };
  size_t next_break = 0;
  // The current input piece: its start, the inputs there and their constant slope, so that a
  // regular sample costs no profile look-up and only the propagator's per-piece affine step.
  double t_piece = times.front();
  // Step size BeginPiece was prepared for; NaN = not yet (a repeated output time is a real
  // step of 0 s, which BeginPiece prepares as Phi = I).
  double h_piece = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd u_piece, v_piece;
  auto start_piece = [&](double a) {
    t_piece = a;
    h_piece = std::numeric_limits<double>::quiet_NaN();
    linear_inputs(a, next_break < breaks.size() ? breaks[next_break] : times.back(), u_piece, v_piece);
  };
  start_piece(times.front());
  system.CalcTimeDerivatives(times.front(), x, xdot, scratch);
  visit(0, times.front(), x, xdot);
  for (size_t k = 1; k < times.size(); ++k) {
    const double t0 = times[k - 1], t1 = times[k];
    if (next_break < breaks.size() && breaks[next_break] <= t1) {
      // Breakpoints in (t0, t1]: step piece by piece, then take the derivative from the
      // right-continuous inputs at t1 (an input may jump exactly there).
      double a = t0;
      while (next_break < breaks.size() && breaks[next_break] <= t1) {
        const double b = breaks[next_break++];
        if (b > a) piece(a, b);
        a = std::max(a, b);
      }
      if (t1 > a) piece(a, t1);
      system.CalcTimeDerivatives(t1, x, xdot, scratch);
      start_piece(t1);
      if constexpr (N > 0) x_fixed = x;
    } else {
      // Regular sample: inputs linear over (t0, t1] with the piece's slope.
      if (!(t1 - t0 == h_piece)) {
        h_piece = t1 - t0;
        propagator->BeginPiece(h_piece, u_piece, v_piece);
      }
      if constexpr (N > 0 && kIsBlockVisitor<Visit>) {
        // This sample and the regular ones after it, to the block's end, the next breakpoint or
        // a change of step: the same steps, in a loop with no call in it (BlockVisitor).
        const double next_break_t = next_break < breaks.size() ? breaks[next_break] : kInfinity;
        if (visit.rates) {
          k = RegularSamples<N, true>(*propagator, times, next_break_t, t_piece, h_piece, k, x_fixed, xdot.data(), visit);
        } else {
          k = RegularSamples<N, false>(*propagator, times, next_break_t, t_piece, h_piece, k, x_fixed, xdot.data(), visit);
        }
        Eigen::Map<State>(x.data()) = x_fixed;
        visit.EndSample(k);
        continue;
      } else if constexpr (N > 0) {
        propagator->template AdvanceFixed<N>(t0 - t_piece, x_fixed, xdot.data());
        Eigen::Map<State>(x.data()) = x_fixed;
      } else {
        propagator->Advance(t0 - t_piece, x, xdot);
      }
    }
    visit(k, t1, x, xdot);
  }
}

#if defined(RLG_AVX2_DISPATCH)
template <int N, class Visit>
RLG_AVX2 void IntegrateExactlyAvx2(const ThermalSystem& system, const std::vector<double>& times,
                                   const std::vector<double>& breaks, const Eigen::VectorXd& x, Visit& visit) {
  IntegrateExactlyLoop<N>(system, times, breaks, x, visit);
}
#endif

/// The sample loop and what the simulator's visitor does per sample (keep the state for its
/// block) compiled for AVX2 where the machine has it: the regular step's N x (N + 2) product
/// (2N x (N + 2) with the derivatives) in vectors twice as wide, the same bytes (sim/simd.h).
template <int N, class Visit>
void IntegrateExactly(const ThermalSystem& system, const std::vector<double>& times, const std::vector<double>& breaks,
                      const Eigen::VectorXd& x, Visit& visit) {
#if defined(RLG_AVX2_DISPATCH)
  // Only the simulator's own visitor: a std::function's call per sample would cost what the
  // wider vectors save, and each copy is code.
  if constexpr (kIsBlockVisitor<Visit>) {
    if (UseAvx2()) return IntegrateExactlyAvx2<N>(system, times, breaks, x, visit);
  }
#endif
  IntegrateExactlyLoop<N>(system, times, breaks, x, visit);
}

template <class Visit>
void Integrate(const ThermalSystem& system, const std::vector<double>& times, const Eigen::Ref<const Eigen::VectorXd>& x0,
               const SolverOptions& options, Visit& visit) {
  if (times.empty()) return;
  if (!std::is_sorted(times.begin(), times.end())) throw std::logic_error("IntegrateThermal: output times must not decrease");
  const std::vector<double> breaks = system.Breakpoints(times.front(), times.back());
  const bool exact_possible = system.SolvableExactly();
  if (options.method == ThermalMethod::kExactLinear && !exact_possible) {
    throw InputError("solver method 'exact' needs a network without radiation, piecewise-linear inputs (no sine) and "
                     "piecewise-constant power on drifting sources; use 'auto' or 'cvode'");
  }
  if (options.method == ThermalMethod::kCvode || !exact_possible) {
    IntegrateWithCvode(system, times, breaks, x0, options.cvode, visit);
  } else {
    // The sizes ExactLinearPropagator's products unroll (1 to 6 states), at compile time.
    switch (system.size()) {
      case 1: IntegrateExactly<1>(system, times, breaks, x0, visit); break;
      case 2: IntegrateExactly<2>(system, times, breaks, x0, visit); break;
      case 3: IntegrateExactly<3>(system, times, breaks, x0, visit); break;
      case 4: IntegrateExactly<4>(system, times, breaks, x0, visit); break;
      case 5: IntegrateExactly<5>(system, times, breaks, x0, visit); break;
      case 6: IntegrateExactly<6>(system, times, breaks, x0, visit); break;
      default: IntegrateExactly<0>(system, times, breaks, x0, visit); break;
    }
  }
}

}  // namespace

void IntegrateThermal(const ThermalSystem& system, const std::vector<double>& times,
                      const Eigen::Ref<const Eigen::VectorXd>& x0, const SolverOptions& options, const Visitor& visit) {
  Integrate(system, times, x0, options, visit);
}

ThermalNetwork BuildNetwork(const GyroConfig& gyro, std::vector<int>* sensor_state) {
  NetworkSpec spec = gyro.network;
  sensor_state->clear();
  for (const auto& s : gyro.sensors) {
    // Each lag follows the state before it: the node, then the previous stage.
    int state = s.node;
    for (double tau : s.lag_time_constants_s) {
      spec.followers.push_back({state, tau});
      state = static_cast<int>(spec.nodes.size() + spec.followers.size()) - 1;
    }
    sensor_state->push_back(state);
  }
  return ThermalNetwork(std::move(spec));
}

namespace {

/// Makes `column` n long. A buffer too short is replaced (its values are not kept) and, on
/// Linux 5.14 on, its pages are faulted in by one madvise(MADV_POPULATE_WRITE) before they are
/// first written, not one page fault per 4 kB page: a third less of a fresh 24 h run's page
/// cost where faults are dear (docs/performance.md, "Simulation"), ~0.4 ms more where the
/// heap hands back pages it kept. Elsewhere, or where the kernel refuses it, the pages fault at
/// first touch.
void SizeColumn(std::vector<double>& column, size_t n) {
  if (column.capacity() < n) {
    column.clear();
    column.reserve(n);
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    static const auto page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
    const auto first = (reinterpret_cast<uintptr_t>(column.data()) + page - 1) / page * page;
    const auto last = reinterpret_cast<uintptr_t>(column.data() + n) / page * page;
    if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_POPULATE_WRITE);
#endif
  }
  column.resize(n);
}

}  // namespace

Run SimulateRun(const GyroConfig& gyro, const RunSpec& spec, uint64_t seed, uint64_t stream,
                const SolverOptions& options, const SensorChannels& made) {
  Run run;
  SimulateRun(gyro, spec, seed, stream, &run, options, made);
  return run;
}

void SimulateRun(const GyroConfig& gyro, const RunSpec& spec, uint64_t seed, uint64_t stream, Run* out,
                 const SolverOptions& options, const SensorChannels& made) {
  std::vector<int> sensor_state;
  const ThermalNetwork network = BuildNetwork(gyro, &sensor_state);
  std::vector<Profile> power;
  for (const auto& src : gyro.network.sources) {
    const auto it = spec.power.find(src.name);
    if (it != spec.power.end()) {
      power.push_back(it->second);
    } else if (src.driven_by_data) {
      throw InputError(fmt::format("run '{}': source '{}' is driven by data but has no power profile", spec.id, src.name));
    } else {
      power.push_back(Profile::Constant(src.power_W));
    }
  }
  const ThermalSystem system(network, spec.ambient, std::move(power));

  const auto n_samples = static_cast<size_t>(std::floor(spec.duration_s / spec.sample_period_s + 1e-9)) + 1;
  // Reuse the caller's buffers: a column of the right length is overwritten, not reallocated
  // or zeroed (allocating and first touching fresh pages costs more than the simulation).
  Run& run = *out;
  run.id = spec.id;
  run.source.clear();
  run.first_line = 0;
  std::vector<std::string> names{"T_amb"};
  for (const auto& s : gyro.sensors) {
    if (made.Makes(s.channel)) names.push_back(s.channel);
  }
  names.emplace_back("bias_dph");
  if (run.names != names) run.names = std::move(names);
  run.columns.resize(run.names.size());
  SizeColumn(run.t_s, n_samples);
  for (size_t k = 0; k < n_samples; ++k) run.t_s[k] = static_cast<double>(k) * spec.sample_period_s;
  for (auto& c : run.columns) SizeColumn(c, n_samples);
  spec.ambient.ValuesAt(run.t_s, run.columns.front().data());
  double* const bias_out = run.columns.back().data();
  struct Channel {
    double* out;
    int state;
    double offset_C;
    SensorNoise noise;
  };
  std::vector<Channel> channels;
  std::vector<Rng> sensor_rng;  // apart: a few kB each, they would spread the channels over pages
  channels.reserve(gyro.sensors.size());
  sensor_rng.reserve(gyro.sensors.size());
  for (size_t i = 0; i < gyro.sensors.size(); ++i) {
    const auto& s = gyro.sensors[i];
    if (!made.Makes(s.channel)) continue;
    channels.push_back({run.columns[channels.size() + 1].data(), sensor_state[i], s.offset_C, SensorNoise(s.noise)});
    sensor_rng.emplace_back(seed, stream, kSubstreamSensor0 + i);  // sensor i's substream, whichever are made
  }

  GyroNoise gyro_noise(gyro.noise, spec.sample_period_s, seed, stream);
  const BiasModel bias(gyro.bias);
  const int n_nodes = network.num_nodes();
  Eigen::VectorXd x0 = Eigen::VectorXd::Constant(network.num_states(), spec.initial_C.value_or(spec.ambient.Value(0.0)));
  BiasModel::State bias_state = bias.Start(x0.head(n_nodes));

  // The sample loop keeps each state and its derivative; every kNoiseBlock samples the sensor
  // columns and the bias are made from them, and the noise replaces those true values by the
  // measured ones while they are still in L1 (block draws, vectorised loops; the numbers do not
  // depend on the block length, noise.h).
  constexpr size_t kNoiseBlock = Rng::kBlock;
  const Eigen::Index n_states = network.num_states();
  const auto stride = static_cast<size_t>(n_states);
  // Sample j of the block: its states at block_x[j * stride ..], its derivative likewise.
  std::vector<double> block_x(kNoiseBlock * stride), block_xdot(block_x.size());
  // Only a rate term reads the states' derivatives; without one they are neither made nor kept.
  const bool rates = bias.UsesRates();
  // A block's sensor columns, biases and noise: out of line, so that the per-sample part is
  // inlined into the integrator's sample loop.
  auto flush = [&](size_t first, size_t last) __attribute__((noinline)) {
    const size_t m = last + 1 - first;
    for (size_t i = 0; i < channels.size(); ++i) {
      const Channel& c = channels[i];
      const double* const xs = block_x.data() + c.state;
      for (size_t s = 0; s < m; ++s) c.out[first + s] = xs[s * stride] + c.offset_C;
      c.noise.ReadInPlace(c.out + first, m, sensor_rng[i]);
    }
    bias.Evaluate(block_x.data(), block_xdot.data(), stride, m, bias_out + first, bias_state);
    gyro_noise.Apply(bias_out + first, m);
  };
  BlockVisitor<decltype(flush)> visit{block_x.data(), block_xdot.data(), stride, kNoiseBlock, n_samples, rates, flush};
  Integrate(system, run.t_s, x0, options, visit);
}

Trace SimulateScenario(const Scenario& scenario, uint64_t seed, const std::function<void(size_t, size_t)>& progress,
                       const SensorChannels& channels) {
  Trace trace;
  SimulateScenario(scenario, seed, progress, channels, &trace);
  return trace;
}

void SimulateScenario(const Scenario& scenario, uint64_t seed, const std::function<void(size_t, size_t)>& progress,
                      const SensorChannels& channels, Trace* out,
                      const std::function<void(size_t, const Run&)>& simulated) {
  Trace& trace = *out;
  trace.source.clear();
  trace.comments.clear();
  trace.comments.push_back(fmt::format("rlgtherm simulate {} --seed {}", scenario.path, seed));
  trace.comments.push_back(fmt::format("gyro: {}", scenario.gyro.name));
  // A source's power is data unless it is the gyro's constant power_W in every run: every
  // data-driven source, and every source a run gives a profile, is written as P_<name>_W in
  // every run, so that the CSV holds each input its temperatures depend on (diagnose reads it).
  std::vector<size_t> logged;
  const auto& sources = scenario.gyro.network.sources;
  for (size_t s = 0; s < sources.size(); ++s) {
    const bool profiled = std::any_of(scenario.runs.begin(), scenario.runs.end(),
                                      [&](const RunSpec& r) { return r.power.count(sources[s].name) > 0; });
    if (sources[s].driven_by_data || profiled) logged.push_back(s);
  }
  // Room for every run first: a Run's columns are a std::deque, whose move may throw, so a
  // growing vector would copy the runs simulated so far (~6 % of a population gyro's CPU).
  if (trace.runs.size() > scenario.runs.size()) trace.runs.resize(scenario.runs.size());
  trace.runs.reserve(scenario.runs.size());
  for (size_t i = 0; i < scenario.runs.size(); ++i) {
    if (progress) progress(i, scenario.runs.size());
    const RunSpec& spec = scenario.runs[i];
    if (i == trace.runs.size()) trace.runs.emplace_back();
    Run& run = trace.runs[i];
    // A recycled run's power columns lend their buffers too (SimulateRun keeps its own columns
    // only).
    std::vector<std::vector<double>> power_columns(logged.size());
    for (size_t l = 0; l < logged.size(); ++l) {
      const int c = run.Find("P_" + sources[logged[l]].name + "_W");
      if (c >= 0) power_columns[l] = std::move(run.columns[static_cast<size_t>(c)]);
    }
    SimulateRun(scenario.gyro, spec, seed, i, &run, scenario.solver, channels);
    run.source = scenario.path;  // messages about the run name the scenario
    for (size_t l = 0; l < logged.size(); ++l) {
      const auto& source = sources[logged[l]];
      const auto it = spec.power.find(source.name);
      const Profile power = it != spec.power.end() ? it->second : Profile::Constant(source.power_W);
      run.names.push_back("P_" + source.name + "_W");
      std::vector<double>& column = run.columns.emplace_back(std::move(power_columns[l]));
      column.resize(run.size());
      power.ValuesAt(run.t_s, column.data());
    }
    if (simulated) simulated(i, run);
  }
}

uint64_t UsePopulationGyro(Scenario& scenario, uint64_t seed, uint64_t i) {
  Population::Gyro g = Population(scenario.population.value(), scenario.gyro).Draw(seed, i);
  scenario.gyro = std::move(g.config);
  return g.seed;
}

void CheckReadable(const Scenario& scenario, const Trace& trace) {
  for (size_t i = 0; i < trace.runs.size() && i < scenario.runs.size(); ++i) CheckReadable(scenario, i, trace.runs[i]);
}

void CheckReadable(const Scenario& scenario, size_t i, const Run& run) {
  if (const std::string why = FindUnreadableValue(run); !why.empty()) {
    throw InputError(fmt::format("{}:{}: run '{}': the simulated {}; the tidy CSV (docs/data-format.md) cannot hold it, "
                                 "so nothing is written or evaluated (check the gyro's powers and the run's ambient)",
                                 scenario.path, scenario.runs[i].line, scenario.runs[i].id, why));
  }
}

}  // namespace rlg::sim

#pragma once
/// The simulator owns time and state: it drives a ThermalNetwork through its inputs, exactly
/// (ExactLinearPropagator) when the network is linear over each input piece, otherwise with
/// CVODE restarted at every input breakpoint, and at each output sample reads the sensors,
/// evaluates the bias physics and adds noise.

#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sim/ambient.h"
#include "sim/cvode_integrator.h"
#include "sim/solver_options.h"
#include "sim/scenario.h"
#include "sim/sensor_channels.h"
#include "sim/thermal_network.h"
#include "sim/trace.h"

namespace rlg::sim {

/// A network with its inputs over time: ambient temperature and one power profile per source.
/// Immutable once made: its evaluations write only the caller's OdeScratch (the source powers
/// at t), so any number of threads may integrate one ThermalSystem.
class ThermalSystem final : public OdeSystem {
 public:
  ThermalSystem(const ThermalNetwork& network, Profile ambient, std::vector<Profile> power);
  int size() const override { return network_.num_states(); }
  void CalcTimeDerivatives(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                           Eigen::Ref<Eigen::VectorXd> xdot, OdeScratch& scratch) const override;
  void CalcJacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::MatrixXd> J,
                    OdeScratch& scratch) const override;

  /// Source powers at t (W).
  void Power(double t, Eigen::VectorXd& p) const;
  /// Inputs u = [T_amb, P_1 .. P_s] at t (right-continuous).
  void Inputs(double t, Eigen::VectorXd& u) const;
  /// True when the exact propagator applies: no radiation, every input piecewise linear
  /// between its breakpoints, and every drifting source's power piecewise constant (within a
  /// piece its drift is then a linear term, ThermalNetwork::FoldDrift).
  bool SolvableExactly() const;
  /// Sorted, unique input discontinuities in (t0, t1).
  std::vector<double> Breakpoints(double t0, double t1) const;
  const ThermalNetwork& network() const { return network_; }

 private:
  const ThermalNetwork& network_;
  Profile ambient_;
  std::vector<Profile> power_;
};

/// Integrates `system` from x0 at t = times[0] and calls visit(k, t_k, x(t_k), xdot(t_k)) for
/// every output time, in order. The call's working memory is its own (safe on one system from
/// several threads). Times must not decrease (std::logic_error); a repeated time
/// repeats the state. InputError when kExactLinear is asked for a system it cannot solve
/// exactly.
void IntegrateThermal(const ThermalSystem& system, const std::vector<double>& times,
                      const Eigen::Ref<const Eigen::VectorXd>& x0, const SolverOptions& options,
                      const std::function<void(size_t, double, const Eigen::VectorXd&, const Eigen::VectorXd&)>& visit);

/// Network of a gyro with its sensor-lag followers; sensor_state[i] is the state index that
/// sensor i reads.
ThermalNetwork BuildNetwork(const GyroConfig& gyro, std::vector<int>* sensor_state);

/// One run: columns T_amb, the gyro's sensor channels (those `channels` makes), bias_dph. `stream` separates the random
/// streams of the runs of a suite (same seed and stream -> same bytes).
Run SimulateRun(const GyroConfig& gyro, const RunSpec& spec, uint64_t seed, uint64_t stream,
                const SolverOptions& options = {}, const SensorChannels& channels = {});
/// The same run written into a caller-owned `out`, whose buffers are reused: the path for many
/// runs in a row (a population), since allocating and first touching a fresh run's pages costs
/// more than simulating it (docs/performance.md, "Simulation"). Columns other than the run's are dropped; the
/// bytes are those of the allocating overload.
void SimulateRun(const GyroConfig& gyro, const RunSpec& spec, uint64_t seed, uint64_t stream, Run* out,
                 const SolverOptions& options = {}, const SensorChannels& channels = {});

/// Every run of a scenario, stream = run index; progress(i, n) is called before run i.
Trace SimulateScenario(const Scenario& scenario, uint64_t seed,
                       const std::function<void(size_t, size_t)>& progress = nullptr,
                       const SensorChannels& channels = {});
/// The same trace written into `out`: its first runs' buffers are reused, run i into out->runs[i]
/// (SimulateRun's reuse path, and a power column into the recycled run's column of that name),
/// and runs beyond the scenario's are dropped. The same bytes. `simulated(i, run)` is called
/// after run i is made, while its values are still in cache (a check of them). After an
/// exception, what `out` holds is unspecified.
void SimulateScenario(const Scenario& scenario, uint64_t seed, const std::function<void(size_t, size_t)>& progress,
                      const SensorChannels& channels, Trace* out,
                      const std::function<void(size_t, const Run&)>& simulated = nullptr);

/// Gyro i of the scenario's [population] (precondition: it has one) put in place of its gyro,
/// drawn from `seed` (the scenario's or the caller's) and i as in a population suite
/// (sim/population.h); returns the seed that gyro is simulated with. `simulate --gyro i` and the
/// Python module's simulate(gyro=i).
uint64_t UsePopulationGyro(Scenario& scenario, uint64_t seed, uint64_t i);

/// InputError naming the scenario file, the run's line and the value when a simulated trace
/// holds a value the tidy CSV's reader refuses (FindUnreadableValue): the loaders keep inputs
/// within the format's limits, but the physics can still leave them (a heater warming a node
/// past 150 °C). `simulate` calls it before writing, so it never writes a file it cannot read.
void CheckReadable(const Scenario& scenario, const Trace& trace);
/// The same for run i of the scenario alone (`validate` checks each run as it is made:
/// SimulateScenario's `simulated`).
void CheckReadable(const Scenario& scenario, size_t i, const Run& run);

}  // namespace rlg::sim

#pragma once
/// The noise-free simulation of a model on a problem's fit blocks: per run, the block means of
/// every gyro sensor (°C) and of every node's temperature (°C) and rate (°C/s).
///
/// Each run is simulated from power-on after a soak: every state starts at the ambient of the
/// first sample plus the run's start offset (Model::start), driven by the logged ambient curve
/// (or a constant unlogged ambient, Model::ambient) and the run's source powers, and sampled at
/// its blocks' mean sample times; the values there become block means by ToBlockMeans.

#include <Eigen/Core>
#include <vector>

#include "diagnosis/data/block_times.h"
#include "diagnosis/network/model.h"
#include "diagnosis/data/prepare.h"
#include "diagnosis/network/problem.h"
#include "sim/gyro.h"
#include "sim/solver_options.h"

namespace rlg::diagnosis {

struct Prediction {
  std::vector<std::vector<double>> sensor;  ///< per gyro sensor, per fit block (°C)
  Eigen::MatrixXd T, Tdot;                  ///< nodes x fit blocks (original nodes only; °C, °C/s)
};

/// What a simulation keeps: the sensors alone (all a thermal residual reads: every fit's
/// evaluation), or the nodes' temperatures and rates too (the bias regressors'). The sensors
/// are the same bytes either way.
enum class Sampled { kSensors, kSensorsAndNodes };

/// Run p of gyro g at `blocks`, with ambient_C where the run's ambient is unknown and every
/// state started start_offset_C above the ambient at the first sample; T and Tdot empty
/// where only the sensors are `sampled`.
Prediction Simulate(const sim::GyroConfig& g, const PreparedRun& p, const std::vector<BlockTimes>& blocks, double ambient_C,
                    double start_offset_C, int n_nodes, const sim::SolverOptions& solver,
                    Sampled sampled = Sampled::kSensorsAndNodes);

/// Run r of gyro g (Build of m) as prepared in `run` (problem.runs[r], or a copy with another
/// ambient curve), with m's nuisances for it: its ambient, its start and, with per-run gains,
/// its board's own heater gains.
Prediction SimulateRun(const Problem& problem, const sim::GyroConfig& g, const Model& m, const PreparedRun& run, int r,
                       Sampled sampled = Sampled::kSensorsAndNodes);

/// Model m on the runs `which` (indices into problem.runs); the other entries stay empty.
std::vector<Prediction> SimulateAll(const Problem& problem, const Model& m, const std::vector<int>& which,
                                    Sampled sampled = Sampled::kSensorsAndNodes);

}  // namespace rlg::diagnosis

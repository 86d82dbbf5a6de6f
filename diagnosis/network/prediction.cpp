#include "diagnosis/network/prediction.h"

#include "sim/simulator.h"
#include "sim/thermal_network.h"

namespace rlg::diagnosis {

using sim::GyroConfig;
using sim::Profile;

Prediction Simulate(const GyroConfig& g, const PreparedRun& p, const std::vector<BlockTimes>& blocks, double ambient_C,
                    double start_offset_C, int n_nodes, const sim::SolverOptions& solver, Sampled sampled) {
  std::vector<int> sensor_state;
  const sim::ThermalNetwork net = sim::BuildNetwork(g, &sensor_state);
  std::vector<Profile> power;
  for (size_t s = 0; s < g.network.sources.size(); ++s) {
    const auto& src = g.network.sources[s];
    power.push_back(p.power_logged[s] ? p.data_power[s] : Profile::Constant(src.power_W));
  }
  const Profile ambient = p.ambient_known ? p.ambient : Profile::Constant(ambient_C);
  const sim::ThermalSystem system(net, ambient, power);
  const auto n_sensors = static_cast<Eigen::Index>(g.sensors.size());
  // Powered on after a soak: every state starts at the ambient of the first sample (and the
  // run's start offset, Model::start), which is integrated from there through each block's
  // mean sample time.
  std::vector<double> t = {p.run->t_s.front()};
  for (const auto& b : blocks) t.push_back(b.mean);
  const Eigen::VectorXd x0 = Eigen::VectorXd::Constant(net.num_states(), ambient.Value(p.run->t_s.front()) + start_offset_C);
  // Rows: sensors, node temperatures, node rates (none where not sampled); one column per block.
  if (sampled == Sampled::kSensors) n_nodes = 0;
  Eigen::MatrixXd q(n_sensors + 2 * n_nodes, static_cast<Eigen::Index>(blocks.size()));
  sim::IntegrateThermal(system, t, x0, solver, [&](size_t j, double, const Eigen::VectorXd& x, const Eigen::VectorXd& xdot) {
    if (j == 0) return;
    const auto c = static_cast<Eigen::Index>(j - 1);
    for (Eigen::Index i = 0; i < n_sensors; ++i)
      q(i, c) = x[sensor_state[static_cast<size_t>(i)]] + g.sensors[static_cast<size_t>(i)].offset_C;
    q.block(n_sensors, c, n_nodes, 1) = x.head(n_nodes);
    q.block(n_sensors + n_nodes, c, n_nodes, 1) = xdot.head(n_nodes);
  });
  ToBlockMeans(blocks, q);
  Prediction out;
  out.sensor.resize(g.sensors.size());
  for (Eigen::Index i = 0; i < n_sensors; ++i) {
    const Eigen::VectorXd row = q.row(i).transpose();
    out.sensor[static_cast<size_t>(i)].assign(row.data(), row.data() + row.size());
  }
  out.T = q.middleRows(n_sensors, n_nodes);
  out.Tdot = q.bottomRows(n_nodes);
  return out;
}

Prediction SimulateRun(const Problem& problem, const GyroConfig& g, const Model& m, const PreparedRun& run, int r,
                       Sampled sampled) {
  const int q = run.nuisance;
  const double start = m.start.empty() ? 0.0 : m.start[q];
  if (m.run_gain.empty())
    return Simulate(g, run, problem.block_spans[r], m.ambient[q], start, problem.n_nodes, problem.solver, sampled);
  GyroConfig gr = g;  // this run's board: its own heater gains
  for (size_t s = 0; s < gr.network.sources.size(); ++s) gr.network.sources[s].gain *= m.run_gain[q][s];
  return Simulate(gr, run, problem.block_spans[r], m.ambient[q], start, problem.n_nodes, problem.solver, sampled);
}

std::vector<Prediction> SimulateAll(const Problem& problem, const Model& m, const std::vector<int>& which,
                                    Sampled sampled) {
  const GyroConfig g = Build(problem.nominal, problem.knobs, m);
  std::vector<Prediction> out(problem.runs.size());
  for (int r : which) out[r] = SimulateRun(problem, g, m, problem.runs[r], r, sampled);
  return out;
}

}  // namespace rlg::diagnosis

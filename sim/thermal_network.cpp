#include "sim/thermal_network.h"

#include <cmath>
#include <fmt/format.h>

#include "sim/errors.h"

namespace rlg::sim {
namespace {

constexpr double kStefanBoltzmann = 5.670374419e-8;  // W/(m² K⁴), CODATA 2018
constexpr double kKelvin = 273.15;

}  // namespace

int NetworkSpec::FindNode(const std::string& name) const {
  if (name == "ambient") return kAmbient;
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].name == name) return static_cast<int>(i);
  return -2;
}

int NetworkSpec::FindSource(const std::string& name) const {
  for (size_t i = 0; i < sources.size(); ++i)
    if (sources[i].name == name) return static_cast<int>(i);
  return -1;
}

ThermalNetwork::ThermalNetwork(NetworkSpec spec) : spec_(std::move(spec)) {
  const int n = num_nodes();
  const int ns = num_states();
  if (n == 0) throw InputError("thermal network: needs at least one node");
  inv_c_.resize(n);
  for (int i = 0; i < n; ++i) {
    const auto& node = spec_.nodes[i];
    if (!(node.heat_capacity_J_per_K > 0.0) || !std::isfinite(node.heat_capacity_J_per_K)) {
      throw InputError(fmt::format("node '{}': heat_capacity_J_per_K must be positive and finite, got {}", node.name,
                                   node.heat_capacity_J_per_K));
    }
    inv_c_[i] = 1.0 / node.heat_capacity_J_per_K;
  }
  auto name_of = [&](int i) { return i == kAmbient ? std::string("ambient") : spec_.nodes.at(i).name; };

  A_ = Eigen::MatrixXd::Zero(ns, ns);
  b_amb_ = Eigen::VectorXd::Zero(ns);
  B_src_ = Eigen::MatrixXd::Zero(ns, num_sources());

  // Union-find over conductive links to check every node reaches ambient (index n).
  std::vector<int> parent(n + 1);
  for (int i = 0; i <= n; ++i) parent[i] = i;
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto unite = [&](int a, int b) { parent[find(a == kAmbient ? n : a)] = find(b == kAmbient ? n : b); };

  for (const auto& link : spec_.links) {
    const double g = link.conductance_W_per_K;
    if (link.a < 0 || link.a >= n || link.b < kAmbient || link.b >= n || link.a == link.b) {
      throw InputError(fmt::format("link {}-{}: must join two different nodes, or a node and ambient",
                                   name_of(link.a), name_of(link.b)));
    }
    if (!(g >= 0.0) || !std::isfinite(g)) {
      throw InputError(fmt::format("link {}-{}: conductance_W_per_K must be >= 0 and finite, got {}", name_of(link.a),
                                   name_of(link.b), g));
    }
    if (g > 0.0) unite(link.a, link.b);
    A_(link.a, link.a) -= g * inv_c_[link.a];
    if (link.b == kAmbient) {
      b_amb_[link.a] += g * inv_c_[link.a];
    } else {
      A_(link.a, link.b) += g * inv_c_[link.a];
      A_(link.b, link.b) -= g * inv_c_[link.b];
      A_(link.b, link.a) += g * inv_c_[link.b];
    }
  }
  for (const auto& r : spec_.radiation) {
    if (r.a < 0 || r.a >= n || r.b < kAmbient || r.b >= n || r.a == r.b || !(r.emissivity_area_m2 >= 0.0)) {
      throw InputError(fmt::format("radiation {}-{}: needs two different nodes (or ambient) and eps*A >= 0",
                                   name_of(r.a), name_of(r.b)));
    }
    if (r.emissivity_area_m2 > 0.0) {
      has_radiation_ = true;
      unite(r.a, r.b);
    }
  }
  for (int s = 0; s < num_sources(); ++s) {
    const auto& src = spec_.sources[s];
    for (const auto& [node, share] : src.shares) {
      if (node < 0 || node >= n || !(share >= 0.0)) {
        throw InputError(fmt::format("source '{}': shares must name nodes and be >= 0", src.name));
      }
      B_src_(node, s) += share * src.gain * inv_c_[node];
    }
    if (src.drift_per_K != 0.0) {
      if (src.drift_node < 0 || src.drift_node >= n) {
        throw InputError(fmt::format("source '{}': power drift needs a node", src.name));
      }
      has_drift_ = true;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (find(i) != find(n)) {
      throw InputError(fmt::format(
          "node '{}' has no conductive path to ambient: add a link (to ambient or to a node that has one), "
          "otherwise its temperature has no steady state",
          spec_.nodes[i].name));
    }
  }
  for (size_t f = 0; f < spec_.followers.size(); ++f) {
    const auto& fo = spec_.followers[f];
    const int row = n + static_cast<int>(f);
    if (fo.node < 0 || fo.node >= row || !(fo.time_constant_s > 0.0)) {
      throw InputError("sensor lag: needs a node or an earlier lag to follow and a positive time constant");
    }
    A_(row, row) = -1.0 / fo.time_constant_s;
    A_(row, fo.node) = 1.0 / fo.time_constant_s;
  }
}

double ThermalNetwork::EffectivePower(int s, const Eigen::Ref<const Eigen::VectorXd>& x, double p) const {
  const auto& src = spec_.sources[s];
  if (src.drift_per_K == 0.0) return p;
  return p * (1.0 + src.drift_per_K * (x[src.drift_node] - src.drift_reference_C));
}

void ThermalNetwork::FoldDrift(Eigen::Ref<Eigen::VectorXd> power_W, Eigen::MatrixXd& A) const {
  A = A_;
  for (int s = 0; s < num_sources(); ++s) {
    const auto& src = spec_.sources[s];
    if (src.drift_per_K == 0.0) continue;
    A.col(src.drift_node) += B_src_.col(s) * (power_W[s] * src.drift_per_K);
    power_W[s] *= 1.0 - src.drift_per_K * src.drift_reference_C;
  }
}

void ThermalNetwork::CalcTimeDerivatives(const Eigen::Ref<const Eigen::VectorXd>& x, double T_amb_C,
                                         const Eigen::Ref<const Eigen::VectorXd>& power_W,
                                         Eigen::Ref<Eigen::VectorXd> xdot) const {
  xdot.noalias() = A_ * x;
  xdot += b_amb_ * T_amb_C;
  if (is_linear()) {
    xdot.noalias() += B_src_ * power_W;
    return;
  }
  for (int s = 0; s < num_sources(); ++s) xdot += B_src_.col(s) * EffectivePower(s, x, power_W[s]);
  for (const auto& r : spec_.radiation) {
    const double ta = x[r.a] + kKelvin;
    const double tb = (r.b == kAmbient ? T_amb_C : x[r.b]) + kKelvin;
    const double q = r.emissivity_area_m2 * kStefanBoltzmann * (ta * ta * ta * ta - tb * tb * tb * tb);
    xdot[r.a] -= q * inv_c_[r.a];
    if (r.b != kAmbient) xdot[r.b] += q * inv_c_[r.b];
  }
}

void ThermalNetwork::CalcJacobian(const Eigen::Ref<const Eigen::VectorXd>& x, double T_amb_C,
                                  const Eigen::Ref<const Eigen::VectorXd>& power_W,
                                  Eigen::Ref<Eigen::MatrixXd> J) const {
  (void)T_amb_C;
  J = A_;
  if (is_linear()) return;
  for (int s = 0; s < num_sources(); ++s) {
    const auto& src = spec_.sources[s];
    if (src.drift_per_K != 0.0) J.col(src.drift_node) += B_src_.col(s) * (power_W[s] * src.drift_per_K);
  }
  for (const auto& r : spec_.radiation) {
    const double ta = x[r.a] + kKelvin;
    const double dqa = 4.0 * r.emissivity_area_m2 * kStefanBoltzmann * ta * ta * ta;
    J(r.a, r.a) -= dqa * inv_c_[r.a];
    if (r.b != kAmbient) {
      const double tb = x[r.b] + kKelvin;
      const double dqb = -4.0 * r.emissivity_area_m2 * kStefanBoltzmann * tb * tb * tb;
      J(r.a, r.b) -= dqb * inv_c_[r.a];
      J(r.b, r.a) += dqa * inv_c_[r.b];
      J(r.b, r.b) += dqb * inv_c_[r.b];
    }
  }
}

double ThermalNetwork::NetHeatInput_W(const Eigen::Ref<const Eigen::VectorXd>& x, double T_amb_C,
                                      const Eigen::Ref<const Eigen::VectorXd>& power_W) const {
  double q = 0.0;
  for (int s = 0; s < num_sources(); ++s) {
    double share_sum = 0.0;
    for (const auto& sh : spec_.sources[s].shares) share_sum += sh.second * spec_.sources[s].gain;
    q += share_sum * EffectivePower(s, x, power_W[s]);
  }
  for (const auto& link : spec_.links)
    if (link.b == kAmbient) q += link.conductance_W_per_K * (T_amb_C - x[link.a]);
  for (const auto& r : spec_.radiation) {
    if (r.b != kAmbient) continue;
    const double ta = x[r.a] + kKelvin, tb = T_amb_C + kKelvin;
    q -= r.emissivity_area_m2 * kStefanBoltzmann * (ta * ta * ta * ta - tb * tb * tb * tb);
  }
  return q;
}

Eigen::VectorXd ThermalNetwork::LinearSteadyState(double T_amb_C,
                                                  const Eigen::Ref<const Eigen::VectorXd>& power_W) const {
  const Eigen::VectorXd rhs = b_amb_ * T_amb_C + B_src_ * power_W;
  return A_.partialPivLu().solve(-rhs);
}

}  // namespace rlg::sim

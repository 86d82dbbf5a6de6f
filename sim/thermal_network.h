#pragma once
/// Lumped thermal network: any number of nodes with heat capacities C_i, conductive links
/// between nodes and to ambient, radiative links, and heat sources distributed over nodes.
///
///   C_i dT_i/dt = sum_j G_ij (T_j - T_i) + G_i,amb (T_amb - T_i)
///               + sum_s w_si P_s (1 + g_s (T_d(s) - T_ref,s))           (heat sources)
///               - sum_r eps_r sigma A_r (T_i^4 - T_other^4)   [T in K]    (radiation)
///
/// Units: T in °C, C in J/K, G in W/K, P in W, eps*A in m². Besides the node temperatures the
/// state holds "follower" states, first-order lags of a node (a sensor's own time constant):
///   tau_f dS_f/dt = T_node(f) - S_f      (one-way: a sensor draws no heat)
/// The model is const and pure: CalcTimeDerivatives and CalcJacobian depend only on their
/// arguments. Preconditions (checked on construction, InputError): C > 0, G >= 0, tau > 0,
/// source shares >= 0, and every node has a conductive path to ambient (otherwise there
/// is no steady state).

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace rlg::sim {

/// Index used for "ambient" wherever a node index is expected.
inline constexpr int kAmbient = -1;

struct NetworkSpec {
  struct Node {
    std::string name;
    double heat_capacity_J_per_K = 0.0;
  };
  struct Link {
    int a = 0;
    int b = kAmbient;  ///< kAmbient for a link to ambient
    double conductance_W_per_K = 0.0;
  };
  struct Radiation {
    int a = 0;
    int b = kAmbient;
    double emissivity_area_m2 = 0.0;  ///< eps * A
  };
  struct Source {
    std::string name;
    std::vector<std::pair<int, double>> shares;  ///< (node, fraction of P deposited there)
    double power_W = 0.0;                         ///< nominal power when no profile is given
    /// Fraction of the given power that heats the nodes: 1 for a nominal gyro; diagnose
    /// calibrates it (a heater's W per % drive, a discharge's heating efficiency).
    double gain = 1.0;
    bool driven_by_data = false;                  ///< power comes from column P_<name>_W
    int drift_node = kAmbient;                    ///< thermal.power_drift: node whose T scales P
    double drift_per_K = 0.0;                     ///< g in P = P0 (1 + g (T - T_ref))
    double drift_reference_C = 20.0;
  };
  /// A first-order lag, tau dy/dt = x_state - y (a sensor's lag; no heat drawn).
  struct Follower {
    int node = 0;  ///< the state it follows: a node, or an earlier follower (lags in series)
    double time_constant_s = 0.0;
  };

  std::vector<Node> nodes;
  std::vector<Link> links;
  std::vector<Radiation> radiation;
  std::vector<Source> sources;
  std::vector<Follower> followers;

  /// Index of node `name`; kAmbient for "ambient"; -2 if absent.
  int FindNode(const std::string& name) const;
  int FindSource(const std::string& name) const;
};

class ThermalNetwork {
 public:
  /// Validates `spec` (InputError naming the offending node or link) and precomputes the
  /// linear part A, b_amb, B_src of  xdot = A x + b_amb T_amb + B_src P + nonlinear terms.
  explicit ThermalNetwork(NetworkSpec spec);

  int num_nodes() const { return static_cast<int>(spec_.nodes.size()); }
  int num_sources() const { return static_cast<int>(spec_.sources.size()); }
  /// Nodes first, then followers.
  int num_states() const { return num_nodes() + static_cast<int>(spec_.followers.size()); }
  const NetworkSpec& spec() const { return spec_; }
  /// True when there is no radiation and no power drift: the ODE is linear.
  bool is_linear() const { return !has_radiation_ && !has_drift_; }
  /// True when there is no radiation: with every drifting source at a constant power the ODE
  /// is linear (FoldDrift).
  bool linear_at_constant_power() const { return !has_radiation_; }
  bool has_drift() const { return has_drift_; }
  /// A drifting source at a constant power P0 delivers P0 (1 + g (T_node - T_ref)), linear in
  /// x: the network is then xdot = A' x + b_amb T_amb + B_src P' with
  ///   A' = A + sum_s P0_s g_s B_src(:, s) e_node^T,   P'_s = P0_s (1 - g_s T_ref_s).
  /// Writes A' and rewrites `power_W` (P0 in, P' out); sources without drift are unchanged.
  void FoldDrift(Eigen::Ref<Eigen::VectorXd> power_W, Eigen::MatrixXd& A) const;

  /// xdot = f(x, T_amb, P). x has num_states(), P has num_sources() entries.
  void CalcTimeDerivatives(const Eigen::Ref<const Eigen::VectorXd>& x, double T_amb_C,
                           const Eigen::Ref<const Eigen::VectorXd>& power_W,
                           Eigen::Ref<Eigen::VectorXd> xdot) const;
  /// J = df/dx (dense, num_states x num_states).
  void CalcJacobian(const Eigen::Ref<const Eigen::VectorXd>& x, double T_amb_C,
                    const Eigen::Ref<const Eigen::VectorXd>& power_W, Eigen::Ref<Eigen::MatrixXd> J) const;

  /// Linear part, for closed-form checks: xdot = A x + b_amb T_amb + B_src P.
  const Eigen::MatrixXd& A() const { return A_; }
  const Eigen::VectorXd& b_amb() const { return b_amb_; }
  const Eigen::MatrixXd& B_src() const { return B_src_; }

  /// Heat flowing into the network from sources minus heat lost to ambient (W); equals
  /// d/dt sum_i C_i T_i (energy balance).
  double NetHeatInput_W(const Eigen::Ref<const Eigen::VectorXd>& x, double T_amb_C,
                        const Eigen::Ref<const Eigen::VectorXd>& power_W) const;
  /// Steady state of a linear network for constant T_amb and P: x = -A^{-1}(b_amb T_amb + B P).
  Eigen::VectorXd LinearSteadyState(double T_amb_C, const Eigen::Ref<const Eigen::VectorXd>& power_W) const;

 private:
  double EffectivePower(int s, const Eigen::Ref<const Eigen::VectorXd>& x, double p) const;

  NetworkSpec spec_;
  Eigen::VectorXd inv_c_;
  Eigen::MatrixXd A_;
  Eigen::VectorXd b_amb_;
  Eigen::MatrixXd B_src_;
  bool has_radiation_ = false;
  bool has_drift_ = false;
};

}  // namespace rlg::sim

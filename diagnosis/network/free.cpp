#include "diagnosis/network/free.h"

#include <cmath>

namespace rlg::diagnosis {

double CurveStart(const Problem& p, int r) { return p.runs[r].ambient.Value(p.runs[r].run->t_s.front()); }

void SetOne(const Problem& p, Model& m, const Free& f, double x) {
  const double v = f.log ? std::exp(x) : x;
  if (f.kind == Free::kBase) m.base[f.index] = v;
  if (f.kind == Free::kEffect) m.effects[f.index].parameters[f.param] = v;
  if (f.kind == Free::kAmbient) m.ambient[f.index] = v - kKelvin;
  if (f.kind == Free::kRunGain) m.run_gain[f.index][std::stoul(f.param)] = v;
  if (f.kind == Free::kStart) m.start[f.index] = v - kKelvin - CurveStart(p, f.index);
}

void SetFree(const Problem& p, Model& m, const std::vector<Free>& free, const double* x) {
  for (size_t i = 0; i < free.size(); ++i) SetOne(p, m, free[i], x[i]);
}

std::vector<double> GetFree(const Problem& p, const Model& m, const std::vector<Free>& free) {
  std::vector<double> x;
  for (const auto& f : free) {
    double v = 0.0;
    if (f.kind == Free::kBase) v = m.base[f.index];
    if (f.kind == Free::kEffect) v = m.effects[f.index].parameters.at(f.param);
    if (f.kind == Free::kAmbient) v = m.ambient[f.index] + kKelvin;
    if (f.kind == Free::kRunGain) v = m.run_gain[f.index][std::stoul(f.param)];
    if (f.kind == Free::kStart) v = CurveStart(p, f.index) + m.start[f.index] + kKelvin;
    x.push_back(f.log ? std::log(v) : v);
  }
  return x;
}

std::vector<Free> BaselineFree(const Problem& p, const std::vector<int>& which_ambient) {
  std::vector<Free> f;
  for (size_t i = 0; i < p.knobs.size(); ++i) {
    // A prior on every nominal knob: the gyro file's relative uncertainty (log units). It
    // keeps combinations the data cannot see (power vs coupling from one ambient) near
    // nominal, and a well-known gyro from absorbing a small missing effect.
    f.push_back({Free::kBase, static_cast<int>(i), "", true, std::log(p.knobs[i].nominal),
                 p.nominal.calibration_uncertainty});
  }
  for (const auto& a : AmbientFree(p, which_ambient)) f.push_back(a);
  return f;
}

std::vector<Free> AmbientFree(const Problem& p, const std::vector<int>& which) {
  std::vector<Free> f;
  for (int r : which) {
    if (p.runs[r].nuisance != r) continue;  // shares its run's, fitted with it
    if (!p.runs[r].ambient_known) f.push_back({Free::kAmbient, r, "", false});
    if (p.runs[r].ambient_known && p.start_sd[r] > 0.0)
      f.push_back({Free::kStart, r, "", false, CurveStart(p, r) + kKelvin, p.start_sd[r]});
    if (!p.per_run_source_gains) continue;
    for (size_t s = 0; s < p.nominal.network.sources.size(); ++s)
      if (p.nominal.network.sources[s].driven_by_data)
        f.push_back({Free::kRunGain, r, std::to_string(s), true, 0.0, p.nominal.calibration_uncertainty});
  }
  return f;
}

}  // namespace rlg::diagnosis

#include "model/model_selection.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <map>
#include <set>

#include "model/pairs.h"
#include "model/allan.h"
#include "model/profile_search.h"
#include "model/training_span.h"
#include "sim/errors.h"

namespace rlg::model {

std::vector<RowMask> BlockFolds(const std::vector<const sim::Run*>& runs, int folds) {
  if (folds < 2) throw InputError(fmt::format("cross-validation needs at least 2 folds (got {})", folds));
  std::vector<RowMask> out(static_cast<size_t>(folds));
  for (const sim::Run* run : runs) {
    const size_t n = run->size();
    if (n < 2 * static_cast<size_t>(folds)) {
      throw InputError(fmt::format("{} has {} samples: too few to cut into {} pieces of 2 or more for "
                                   "cross-validation", run->Where(), n, folds));
    }
    for (int k = 0; k < folds; ++k) {
      std::vector<char> mask(n, 1);
      const size_t begin = n * static_cast<size_t>(k) / static_cast<size_t>(folds);
      const size_t end = n * static_cast<size_t>(k + 1) / static_cast<size_t>(folds);
      std::fill(mask.begin() + static_cast<std::ptrdiff_t>(begin), mask.begin() + static_cast<std::ptrdiff_t>(end), 0);
      out[static_cast<size_t>(k)].push_back(std::move(mask));
    }
  }
  return out;
}

std::vector<RowMask> RunFolds(const std::vector<const sim::Run*>& runs) {
  std::vector<RowMask> out(runs.size());
  for (size_t k = 0; k < runs.size(); ++k)
    for (size_t r = 0; r < runs.size(); ++r) out[k].emplace_back(runs[r]->size(), r == k ? 0 : 1);
  return out;
}

std::vector<RowMask> SelectionFolds(const std::vector<const sim::Run*>& runs, int folds, int min_runs_as_folds) {
  return static_cast<int>(runs.size()) >= min_runs_as_folds ? RunFolds(runs) : BlockFolds(runs, folds);
}

CvScore BlockedCv(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, const FoldFit& fit,
                  const std::string& bias_column) {
  CvScore score;
  double sum = 0.0;
  size_t count = 0;
  for (const RowMask& mask : folds) {
    LinearCompensator comp = fit(mask);
    const std::vector<std::string>& channels = comp.regressors().channels();
    std::vector<double> T(channels.size());
    double fold_sum = 0.0;
    size_t fold_count = 0;
    for (size_t r = 0; r < runs.size(); ++r) {
      const sim::Run& run = *runs[r];
      std::vector<const std::vector<double>*> columns;
      for (const auto& ch : channels) columns.push_back(&run.Column(ch));
      const std::vector<double>& bias = run.Column(bias_column);
      comp.Reset();
      for (size_t k = 0; k < run.size(); ++k) {
        for (size_t c = 0; c < channels.size(); ++c) T[c] = (*columns[c])[k];
        const double out = comp.Update(run.t_s[k], T.data(), bias[k]);
        if (mask[r][k] || (comp.regressors().OutsideFittedRange() && !comp.regressors().Extrapolates())) continue;
        fold_sum += out * out;
        ++fold_count;
      }
    }
    score.fold_ms.push_back(fold_count > 0 ? fold_sum / static_cast<double>(fold_count) : 0.0);
    score.fold_sse.push_back(fold_sum);
    sum += fold_sum;
    count += fold_count;
  }
  score.rms = std::sqrt(sum / static_cast<double>(std::max<size_t>(count, 1)));
  return score;
}

double BlockedCvRms(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, const FoldFit& fit,
                    const std::string& bias_column) {
  return BlockedCv(runs, folds, fit, bias_column).rms;
}

CvScore PolyCv(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, PolyFitOptions options) {
  options.linear.errors = false;
  return BlockedCv(runs, folds, [&](const RowMask& mask) {
    const PolyModel m = FitPoly(runs, options, mask);
    return LinearCompensator(PolyRegressors(m.spec), m.Beta());
  });
}

bool Beats(const CvScore& b, const CvScore& a, double min_gain) {
  if (!(b.rms * b.rms <= (1.0 - min_gain) * a.rms * a.rms)) return false;
  size_t lower = 0;
  const size_t folds = std::min(b.fold_ms.size(), a.fold_ms.size());
  for (size_t k = 0; k < folds; ++k) lower += b.fold_ms[k] < a.fold_ms[k] ? 1 : 0;
  return 4 * lower >= 3 * folds;
}

int SmallestUnbeatenOrder(const std::vector<CvScore>& by_order, double min_gain) {
  const int orders = static_cast<int>(by_order.size());
  for (int p = 1; p <= orders; ++p) {
    const CvScore& s = by_order[static_cast<size_t>(p - 1)];
    if (!std::isfinite(s.rms)) continue;
    bool beaten = false;
    for (int q = p + 1; q <= orders; ++q) beaten = beaten || Beats(by_order[static_cast<size_t>(q - 1)], s, min_gain);
    if (!beaten) return p;
  }
  return 0;
}

double PolyCvRms(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, PolyFitOptions options) {
  return PolyCv(runs, folds, std::move(options)).rms;
}

bool AutoOptions::IsValid(std::string* error) const {
  std::string why;
  if (folds < 2) why = fmt::format("folds must be at least 2 (got {})", folds);
  else if (min_runs_as_folds < 2) why = fmt::format("min_runs_as_folds must be at least 2 (got {})", min_runs_as_folds);
  else if (patience < 1) why = fmt::format("patience must be at least 1 (got {})", patience);
  else if (max_parameters < 2) why = fmt::format("max_parameters must be at least 2 (got {})", max_parameters);
  else if (!(min_gain >= 0.0 && min_gain < 1.0)) why = fmt::format("min_gain must lie in [0, 1) (got {:g})", min_gain);
  else if (!(confidence >= 0.5 && confidence < 1.0)) why = fmt::format("confidence must lie in [0.5, 1) (got {:g})", confidence);
  else {
    PolyFitOptions o;
    o.channel = channel;
    o.reference_C = reference_C;
    o.b0_window_s = b0_window_s;
    o.rate_tau_s = rate_tau_s;
    o.terms = candidate_terms;
    o.linear = linear;
    o.profile = profile;
    o.IsValid(&why);
  }
  if (error) *error = why;
  return why.empty();
}

std::string AutoRule(const AutoOptions& o) {
  return fmt::format("stepwise search of a library of terms (orders, rate, hysteresis, lag, gradients and their "
                     "products) by cross-validation from sufficient statistics: each run held out whole when there "
                     "are {} or more, else {} contiguous pieces of each run; forward until the score has not improved "
                     "for {} moves, then removals and additions while they lower it, then removals to order 1; "
                     "selected: of every model visited, the fewest parameters (then terms) that the lowest score does "
                     "not beat by {:g} % of mean square and a one-sided {:g} % paired t-test of the folds' log ratios; "
                     "extrapolates beyond its range",
                     o.min_runs_as_folds, o.folds, o.patience, 100.0 * o.min_gain, 100.0 * o.confidence);
}

bool SelectionBeats(const CvScore& b, const CvScore& a, double min_gain, double confidence, bool independent_folds) {
  if (!(a.rms > 0.0) || !(b.rms * b.rms <= (1.0 - min_gain) * a.rms * a.rms)) return false;
  if (b.rms * b.rms <= kClearlyLower * a.rms * a.rms) return true;
  const size_t K = std::min(a.fold_sse.size(), b.fold_sse.size());
  if (K < 2) return false;
  const double n = static_cast<double>(K);
  // The folds' log ratios (t-test), signs (sign test) and differences (one standard error).
  double sum = 0.0, sum2 = 0.0, dsum = 0.0, dsum2 = 0.0;
  size_t lower = 0;
  for (size_t k = 0; k < K; ++k) {
    const double r = std::log(std::max(a.fold_sse[k], 1e-300) / std::max(b.fold_sse[k], 1e-300));
    const double d = a.fold_sse[k] - b.fold_sse[k];
    sum += r;
    sum2 += r * r;
    dsum += d;
    dsum2 += d * d;
    lower += r > 0.0 ? 1 : 0;
  }
  auto sd = [n](double s, double s2) { return std::sqrt(std::max(0.0, (s2 - s * s / n) / (n - 1.0))); };
  if (sum > StudentQuantile(2.0 * confidence - 1.0, n - 1.0) * std::sqrt(n) * sd(sum, sum2)) return true;
  if (independent_folds && dsum > std::sqrt(n) * sd(dsum, dsum2)) return true;
  // The sign test: P(at least `lower` of K folds lower | each lower with probability 1/2).
  double tail = 0.0;
  for (size_t j = lower; j <= K; ++j) {
    tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(static_cast<double>(j) + 1.0) -
                     std::lgamma(n - static_cast<double>(j) + 1.0) - n * std::log(2.0));
  }
  return tail <= 1.0 - confidence;
}

namespace {

/// What auto passes on to every FitPoly: channel, reference, B0 window, rate tau and the fits'
/// options; an extrapolating model (header).
PolyFitOptions AutoFitOptions(const AutoOptions& a) {
  PolyFitOptions o;
  o.channel = a.channel;
  o.reference_C = a.reference_C;
  o.b0_window_s = a.b0_window_s;
  o.rate_tau_s = a.rate_tau_s;
  o.linear = a.linear;
  o.profile = a.profile;
  o.extrapolate = true;
  o.preset = PolyPreset::kAuto;
  return o;
}

}  // namespace

PolyFitOptions OptionsOf(const PolyModel& m, const AutoOptions& a) {
  PolyFitOptions o = AutoFitOptions(a);
  o.channel = m.spec.channel;
  o.order = m.spec.order;
  o.offset = m.spec.offset;
  o.extrapolate = m.spec.extrapolate;
  o.preset = PolyPreset::kPoly;
  for (const auto& t : m.spec.terms) o.terms.push_back(t.Spelling());
  return o;
}

namespace {

/// One entry of auto's library: a power of the channel or a term, its column in the library's
/// design, the entries it needs, and its exclusive group (one hysteresis, one lag).
struct Item {
  std::string name;       ///< "order 2", "gradient:T2", "T1*(T2-T1)", "hysteresis (w 2.3 °C)"
  std::string spelling;   ///< the term's `--terms` spelling; empty for a power
  int power = 0;          ///< 2..5 for a power
  int column = 0;
  int extra = 0;          ///< profiled parameters (width or time constant)
  int group = -1;         ///< 0: hysteresis, 1: lag
  std::vector<size_t> parents;
};

/// The library (model/model_selection.h) and the spec that computes its columns: the constant,
/// T^1..T^5, then one column per term item.
struct Library {
  PolySpec spec;
  std::vector<Item> items;
};

/// The terms a product is made of that are in the library: each product with one factor fewer.
std::vector<std::string> SubTerms(const PolyTerm& t, const std::string& channel, int& power_needed) {
  std::vector<std::string> out;
  power_needed = 0;
  if (t.kind != TermKind::kProduct) return out;
  for (size_t drop = 0; drop < t.factors.size(); ++drop) {
    if (drop > 0 && t.factors[drop].SameSignal(t.factors[drop - 1])) continue;
    std::vector<Factor> rest = t.factors;
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(drop));
    if (rest.empty()) continue;
    const bool powers = std::all_of(rest.begin(), rest.end(), [&](const Factor& f) {
      return f.channel == channel && f.minus.empty() && !f.rate;
    });
    if (powers) {
      power_needed = std::max(power_needed, static_cast<int>(rest.size()));
      continue;
    }
    PolyTerm sub;
    sub.kind = TermKind::kProduct;
    sub.factors = rest;
    const auto parsed = ParseTerm(sub.Name(), channel, nullptr);
    if (parsed) out.push_back(parsed->Spelling());
  }
  return out;
}

/// The spellings of auto's candidate terms: the options' (with "gradient" expanded to every other
/// channel the runs share), or by default the rate, hysteresis, lag and every gradient product.
std::vector<std::string> CandidateSpellings(const std::vector<const sim::Run*>& runs, const AutoOptions& a) {
  std::vector<std::string> spellings = a.candidate_terms;
  std::vector<std::string> others;
  for (const auto& ch : TemperatureChannels(*runs.front())) {
    bool everywhere = ch != a.channel;
    for (const sim::Run* run : runs) everywhere = everywhere && run->Has(ch);
    if (everywhere) others.push_back(ch);
  }
  if (spellings.empty()) {
    const std::string& c = a.channel;
    spellings = {"rate", c + "*rate(" + c + ")", "hysteresis", "lag"};
    for (const auto& j : others) {
      const std::string g = "(" + j + "-" + c + ")";
      for (const std::string& t : {"gradient:" + j, c + "*" + g, g + "^2", c + "^2*" + g, "rate(" + j + "-" + c + ")"})
        spellings.push_back(t);
    }
    for (size_t j = 0; j < others.size(); ++j)
      for (size_t k = j + 1; k < others.size(); ++k)
        spellings.push_back("(" + others[j] + "-" + a.channel + ")*(" + others[k] + "-" + a.channel + ")");
  } else {
    std::vector<std::string> expanded;
    for (const auto& t : spellings) {
      if (t != "gradient") {
        expanded.push_back(t);
        continue;
      }
      for (const auto& j : others) expanded.push_back("gradient:" + j);
    }
    spellings = expanded;
  }
  return spellings;
}

/// Refuses a candidate term (`text` as given) whose channels some run lacks.
void CheckCandidateChannels(const std::vector<const sim::Run*>& runs, const AutoOptions& a, const std::string& text,
                            const PolyTerm& t) {
  for (const auto& f : t.factors)
    for (const std::string* ch : {&f.channel, &f.minus})
      for (const sim::Run* run : runs)
        if (!ch->empty() && !run->Has(*ch)) throw InputError(fmt::format("auto: term '{}': {} has no channel '{}'", text, run->Where(), *ch));
  if (t.kind == TermKind::kGradient)
    for (const sim::Run* run : runs)
      if (!run->Has(t.channel) || t.channel == a.channel) throw InputError(fmt::format("auto: term '{}': {} has no other channel '{}'", text, run->Where(), t.channel));
}

/// One library item per value of term t's profiled parameter (width °C or time constant s; one
/// item for a term without one), with rates at time constant tau_r (s) and unbounded factors.
void AddTermItems(Library& lib, const PolyTerm& t, const std::vector<double>& values, double tau_r) {
  PolySpec& s = lib.spec;
  for (double v : values) {
    PolyTerm term = t;
    Item it;
    it.spelling = t.Spelling();
    it.name = t.Spelling();
    if (t.kind == TermKind::kRate || t.HasRate()) term.tau_s = tau_r;
    if (t.kind == TermKind::kHysteresis) {
      term.width_C = v;
      it.name = fmt::format("hysteresis (w {:.3g} °C)", v);
      it.extra = 1;
      it.group = 0;
    }
    if (t.kind == TermKind::kLag) {
      term.tau_s = v;
      it.name = fmt::format("lag (tau {:.3g} s)", v);
      it.extra = 1;
      it.group = 1;
    }
    for (auto& f : term.factors) f.range = {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    it.column = 6 + static_cast<int>(s.terms.size());
    s.terms.push_back(term);
    lib.items.push_back(it);
  }
}

/// Each term item's parents: the terms a product is made of, and the powers it needs.
void SetParents(Library& lib, const std::map<std::string, size_t>& by_spelling, const std::string& channel) {
  for (Item& it : lib.items) {
    if (it.spelling.empty()) continue;
    int power = 0;
    const PolyTerm& t = lib.spec.terms[static_cast<size_t>(it.column - 6)];
    for (const auto& sub : SubTerms(t, channel, power)) {
      const auto at = by_spelling.find(sub);
      if (at != by_spelling.end()) it.parents.push_back(at->second);
    }
    if (power >= 2) it.parents.push_back(static_cast<size_t>(power - 2));
  }
}

Library MakeLibrary(const std::vector<const sim::Run*>& runs, const AutoOptions& a, double lo, double hi, double dt,
                    double longest) {
  Library lib;
  PolySpec& s = lib.spec;
  s.channel = a.channel;
  s.order = 5;
  s.offset = OffsetRule::kFitted;
  s.reference_C = a.reference_C ? *a.reference_C : 0.5 * (lo + hi);
  s.range_C = {lo, hi};
  s.extrapolate = true;
  s.b0_window_s = a.b0_window_s;
  for (int k = 2; k <= 5; ++k) {
    Item it;
    it.name = fmt::format("order {}", k);
    it.power = k;
    it.column = k;
    if (k > 2) it.parents.push_back(static_cast<size_t>(k - 3));
    lib.items.push_back(it);
  }
  const std::vector<std::string> spellings = CandidateSpellings(runs, a);
  const double span = hi - lo;
  const double tau_r = a.rate_tau_s > 0.0 ? a.rate_tau_s : RateTau(dt);
  std::map<std::string, size_t> by_spelling;
  for (const auto& text : spellings) {
    std::string why;
    const auto parsed = ParseTerm(text, a.channel, &why);
    if (!parsed) throw InputError("auto: " + why);
    PolyTerm t = *parsed;
    CheckCandidateChannels(runs, a, text, t);
    if (by_spelling.count(t.Spelling())) continue;
    std::vector<double> values{0.0};
    if (t.kind == TermKind::kHysteresis) {
      const auto [heats, cools] = HeatsAndCools(runs, {}, a.channel, span / 10.0);
      if (!heats || !cools) continue;  // FitPoly would refuse it: the data have no loop to fit
      values = LogGrid(span / 200.0, span / 2.0, 6);
    }
    if (t.kind == TermKind::kLag) {
      if (!(longest / 2.0 > 2.0 * dt)) continue;
      values = LogGrid(2.0 * dt, longest / 2.0, 6);
    }
    by_spelling[t.Spelling()] = lib.items.size();
    AddTermItems(lib, t, values, tau_r);
  }
  // Parents: the terms a product is made of, and the powers it needs.
  SetParents(lib, by_spelling, a.channel);
  return lib;
}

/// The raw Grams of every (run, fold) piece of the library's columns and the bias, and each
/// run's means over its B0 window.
/// The means the parsimony order compares models of equal size on (header): Table 2's 100 s.
constexpr double kTieAverage_s = 100.0;

struct Statistics {
  std::vector<RunFoldGram> pieces;
  std::vector<RunFoldGram> means;  ///< the same pieces as kTieAverage_s means
  std::vector<Eigen::VectorXd> b0_means;
  size_t folds = 0;
  bool loro = false;
};

Statistics Accumulate(const std::vector<const sim::Run*>& runs, const PolySpec& spec, const AutoOptions& a) {
  Statistics st;
  st.loro = static_cast<int>(runs.size()) >= a.min_runs_as_folds;
  st.folds = st.loro ? runs.size() : static_cast<size_t>(a.folds);
  PolyRegressors g(spec);
  const std::vector<std::string>& channels = g.channels();
  const auto L = static_cast<Eigen::Index>(g.names().size());
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Z;
  std::vector<double> T(channels.size());
  for (size_t r = 0; r < runs.size(); ++r) {
    const sim::Run& run = *runs[r];
    std::vector<const std::vector<double>*> cols;
    for (const auto& ch : channels) cols.push_back(&run.Column(ch));
    const std::vector<double>& bias = run.Column("bias_dph");
    const auto n = static_cast<Eigen::Index>(run.size());
    Z.resize(n, L + 1);
    g.Reset();
    for (Eigen::Index k = 0; k < n; ++k) {
      for (size_t c = 0; c < channels.size(); ++c) T[c] = (*cols[c])[static_cast<size_t>(k)];
      g.Next(run.t_s[static_cast<size_t>(k)], T.data(), Z.row(k).data());
      Z(k, L) = bias[static_cast<size_t>(k)];
    }
    Eigen::VectorXd g0 = Eigen::VectorXd::Zero(L + 1);
    Eigen::Index window = 0;
    while (window < n && run.t_s[static_cast<size_t>(window)] < run.t_s.front() + a.b0_window_s) ++window;
    if (window > 0) g0 = Z.topRows(window).colwise().mean().transpose();
    st.b0_means.push_back(g0);
    // Run r whole in fold r, or its `folds` contiguous pieces in folds 0 .. folds-1 (BlockFolds).
    const size_t pieces = st.loro ? 1 : st.folds;
    const double dt = run.size() >= 2 ? SamplePeriod(run.t_s) : kTieAverage_s;
    const auto average = static_cast<Eigen::Index>(std::max(1.0, std::round(kTieAverage_s / dt)));
    for (size_t k = 0; k < pieces; ++k) {
      const auto begin = static_cast<Eigen::Index>(static_cast<size_t>(n) * k / pieces);
      const auto end = static_cast<Eigen::Index>(static_cast<size_t>(n) * (k + 1) / pieces);
      RunFoldGram p;
      p.run = r;
      p.fold = st.loro ? r : k;
      p.gram = Eigen::MatrixXd::Zero(L + 1, L + 1);
      p.gram.selfadjointView<Eigen::Lower>().rankUpdate(Z.middleRows(begin, end - begin).transpose());
      p.gram = p.gram.selfadjointView<Eigen::Lower>();
      // The piece as consecutive means of `average` samples (the last one shorter).
      RunFoldGram m = p;
      const Eigen::Index rows = end - begin, blocks = (rows + average - 1) / average;
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> means(blocks, L + 1);
      for (Eigen::Index b = 0; b < blocks; ++b) {
        const Eigen::Index from = begin + b * average;
        means.row(b) = Z.middleRows(from, std::min(average, end - from)).colwise().mean();
      }
      m.gram.setZero();
      m.gram.selfadjointView<Eigen::Lower>().rankUpdate(means.transpose());
      m.gram = m.gram.selfadjointView<Eigen::Lower>();
      st.pieces.push_back(std::move(p));
      st.means.push_back(std::move(m));
    }
  }
  return st;
}

/// A model of the search: which items it holds, under which offset.
struct Model {
  OffsetRule offset = OffsetRule::kFitted;
  std::vector<char> in;
};

class Search {
 public:
  Search(const Library& lib, const GramCv& cv, OffsetRule offset, const AutoOptions& a, SelectionRecord& record)
      : lib_(lib), cv_(cv), offset_(offset), a_(a), record_(record) {}

  /// The search of the header (steps 1 and 2).
  void Run() {
    Model cur;
    cur.offset = offset_;
    cur.in.assign(lib_.items.size(), 0);
    double cur_rms = Score(cur).rms;
    Path(cur, "start");
    Model best = cur;
    double best_rms = cur_rms;
    // 1. Forward, whatever each move does, until `patience` moves bring no new best.
    for (int since = 0; since < a_.patience;) {
      Model next;
      double next_rms = std::numeric_limits<double>::infinity();
      std::string move;
      for (size_t i = 0; i < lib_.items.size(); ++i) {
        Model m = cur;
        if (!Add(m, i)) continue;
        const double v = Score(m).rms;
        if (v < next_rms) {
          next = m;
          next_rms = v;
          move = "+ " + lib_.items[i].name;
        }
      }
      if (!std::isfinite(next_rms)) break;
      cur = next;
      cur_rms = next_rms;
      Path(cur, move);
      if (cur_rms < best_rms) {
        best = cur;
        best_rms = cur_rms;
        since = 0;
      } else {
        ++since;
      }
    }
    // 2. Stepwise from the forward path's best.
    cur = best;
    cur_rms = best_rms;
    if (Key(cur) != last_path_key_) Path(cur, "back to the best of the forward path");
    for (int round = 0; round < 50; ++round) {
      bool moved = false;
      for (const bool removing : {true, false}) {
        for (;;) {
          Model next;
          double next_rms = cur_rms;
          std::string move;
          for (size_t i = 0; i < lib_.items.size(); ++i) {
            Model m = cur;
            if (removing ? !Remove(m, i) : !Add(m, i)) continue;
            const double v = Score(m).rms;
            if (v < next_rms) {
              next = m;
              next_rms = v;
              move = (removing ? "- " : "+ ") + lib_.items[i].name;
            }
          }
          if (move.empty()) break;
          cur = next;
          cur_rms = next_rms;
          Path(cur, move);
          moved = true;
        }
      }
      if (!moved) break;
    }
    // 3. Backward from there to order 1: the removal of lowest score, whatever it does, so that
    // the nested models the parsimony rule chooses among are all scored.
    for (;;) {
      Model next;
      double next_rms = std::numeric_limits<double>::infinity();
      bool found = false;
      for (size_t i = 0; i < lib_.items.size(); ++i) {
        Model m = cur;
        if (!Remove(m, i)) continue;
        const double v = Score(m).rms;
        if (!found || v < next_rms) {
          next = m;
          next_rms = v;
          found = true;
        }
      }
      if (!found) break;
      cur = next;
    }
  }

  const std::map<std::string, std::pair<Model, CvScore>>& visited() const { return visited_; }

  /// The library's columns of model m: the constant (a fitted offset), T, each item's.
  std::vector<int> Columns(const Model& m) const {
    std::vector<int> columns;
    if (m.offset == OffsetRule::kFitted) columns.push_back(0);
    columns.push_back(1);
    for (size_t i = 0; i < m.in.size(); ++i)
      if (m.in[i]) columns.push_back(lib_.items[i].column);
    return columns;
  }

  /// The offset (a fitted c0, or each run's measured B0), T's coefficient and each item's.
  int Parameters(const Model& m) const {
    int k = 2;
    for (size_t i = 0; i < m.in.size(); ++i) k += m.in[i] ? 1 + lib_.items[i].extra : 0;
    return k;
  }

  std::string Describe(const Model& m) const {
    int order = 1;
    std::string terms;
    for (size_t i = 0; i < m.in.size(); ++i) {
      if (!m.in[i]) continue;
      if (lib_.items[i].power > 0) order = std::max(order, lib_.items[i].power);
      else terms += " + " + lib_.items[i].name;
    }
    return fmt::format("order {}, {}{}", order, OffsetName(m.offset), terms);
  }

 private:
  std::string Key(const Model& m) const { return std::string(OffsetName(m.offset)) + std::string(m.in.begin(), m.in.end()); }

  const CvScore& Score(const Model& m) {
    const std::string key = Key(m);
    auto at = visited_.find(key);
    if (at != visited_.end()) return at->second.second;
    return visited_.emplace(key, std::make_pair(m, cv_.Score(Columns(m)))).first->second.second;
  }

  void Path(const Model& m, const std::string& move) {
    SelectionStep step;
    step.candidate = Describe(m);
    step.cv_rms_dph = Score(m).rms;
    step.accepted = true;
    step.note = move;
    step.parameters = Parameters(m);
    record_.steps.push_back(step);
    last_path_key_ = Key(m);
  }

  /// Item i and whatever it needs; false when it is in, its group is taken, or the model grows
  /// beyond max_parameters.
  bool Add(Model& m, size_t i) const {
    if (m.in[i]) return false;
    std::vector<size_t> todo{i};
    while (!todo.empty()) {
      const size_t j = todo.back();
      todo.pop_back();
      if (m.in[j]) continue;
      const int group = lib_.items[j].group;
      if (group >= 0) {
        for (size_t l = 0; l < m.in.size(); ++l)
          if (m.in[l] && lib_.items[l].group == group) return false;
      }
      m.in[j] = 1;
      for (size_t p : lib_.items[j].parents) todo.push_back(p);
    }
    return Parameters(m) <= a_.max_parameters;
  }

  /// Item i alone, when it is in and nothing in the model needs it.
  bool Remove(Model& m, size_t i) const {
    if (!m.in[i]) return false;
    for (size_t l = 0; l < m.in.size(); ++l) {
      if (!m.in[l]) continue;
      const auto& parents = lib_.items[l].parents;
      if (std::find(parents.begin(), parents.end(), i) != parents.end()) return false;
    }
    m.in[i] = 0;
    return true;
  }

  const Library& lib_;
  const GramCv& cv_;
  OffsetRule offset_;
  const AutoOptions& a_;
  SelectionRecord& record_;
  std::map<std::string, std::pair<Model, CvScore>> visited_;
  std::string last_path_key_;
};

/// The training data's temperature range (°C), median sample period (s) and longest run (s).
/// The channel's span over all samples (model/training_span.h); refuses runs without the
/// channel or the bias, too short to cut into folds, or data at one temperature.
TrainingSpan CheckedSpan(const std::vector<const sim::Run*>& runs, const AutoOptions& a) {
  for (const sim::Run* run : runs) {
    if (!run->Has(a.channel)) {
      throw InputError(fmt::format("{} has no temperature channel '{}' (columns: {})", run->Where(), a.channel,
                                   fmt::join(run->names, ",")));
    }
    run->Column("bias_dph");
    if (static_cast<int>(runs.size()) < a.min_runs_as_folds && run->size() < 2 * static_cast<size_t>(a.folds)) {
      throw InputError(fmt::format("{} has {} samples: too few to cut into {} pieces of 2 or more for "
                                   "cross-validation", run->Where(), run->size(), a.folds));
    }
  }
  const TrainingSpan span = SpanOf(runs, a.channel, [](size_t, size_t) { return true; });
  if (span.dt == 0.0) throw InputError("auto: every run has fewer than 2 samples");
  if (!(span.hi > span.lo)) {
    throw NumericalError(fmt::format("auto: {} stays at {:.4g} °C in every training sample: no polynomial in it can be "
                                     "fitted; the data must cover a range of temperatures", a.channel, span.lo));
  }
  return span;
}

/// The offset rules to search: the one asked for, or a fitted offset and, when every run
/// outlasts the B0 window, the power-on one.
std::vector<OffsetRule> SearchedOffsets(const std::vector<const sim::Run*>& runs, const AutoOptions& a) {
  std::vector<OffsetRule> offsets;
  if (a.offset) {
    offsets.push_back(*a.offset);
  } else {
    offsets.push_back(OffsetRule::kFitted);
    bool spans = true;
    for (const sim::Run* run : runs) spans = spans && run->size() > 0 && run->t_s.back() >= run->t_s.front() + a.b0_window_s;
    if (spans) offsets.push_back(OffsetRule::kPowerOn);
  }
  return offsets;
}

/// A model the search scored, with what the parsimony order compares.
struct Visit {
  Model model;
  CvScore score;
  double means_rms = 0.0;  ///< the score of its kTieAverage_s means
  int parameters = 0;
  int terms = 0;  ///< items beyond the polynomial's powers
  std::string description;
};

/// Every model the search visits under each offset rule, with its scores (°/h); the search's
/// path goes into record.
std::vector<Visit> VisitAll(const Library& lib, const Statistics& st, const std::vector<OffsetRule>& offsets,
                            const AutoOptions& a, SelectionRecord& record) {
  std::vector<Visit> all;
  for (const OffsetRule offset : offsets) {
    const GramCv cv(st.pieces, st.b0_means, st.folds, offset == OffsetRule::kPowerOn);
    const GramCv means(st.means, st.b0_means, st.folds, offset == OffsetRule::kPowerOn);
    Search search(lib, cv, offset, a, record);
    search.Run();
    for (const auto& [key, v] : search.visited()) {
      int terms = 0;
      for (size_t i = 0; i < v.first.in.size(); ++i) terms += v.first.in[i] && lib.items[i].power == 0 ? 1 : 0;
      all.push_back({v.first, v.second, means.Score(search.Columns(v.first)).rms, search.Parameters(v.first), terms,
                     search.Describe(v.first)});
    }
  }
  return all;
}

/// The final fit of the first eligible model (in parsimony order) that FitPoly can fit, its
/// selection record completed; refuses when none can.
PolyModel FitSelected(const std::vector<const sim::Run*>& runs, const AutoOptions& a, const Library& lib,
                      const std::vector<const Visit*>& eligible, const Visit& best, SelectionRecord& record) {
  PolyFitOptions o = AutoFitOptions(a);
  std::string why;
  for (const Visit* v : eligible) {  // the fewest parameters first; the next where a final fit fails
    o.offset = v->model.offset;
    o.order = 1;
    o.terms.clear();
    for (size_t i = 0; i < v->model.in.size(); ++i) {
      if (!v->model.in[i]) continue;
      const Item& it = lib.items[i];
      if (it.power > 0) o.order = std::max(o.order, it.power);
      else o.terms.push_back(it.spelling);
    }
    try {
      PolyModel m = FitPoly(runs, o);
      SelectionStep step;
      step.candidate = v->description;
      step.cv_rms_dph = v->score.rms;
      step.accepted = true;
      step.parameters = v->parameters;
      step.note = fmt::format("selected: the simplest model the lowest score ({:.5f} °/h, {}) does not beat",
                              best.score.rms, best.description);
      record.steps.push_back(step);
      m.selection = record;
      return m;
    } catch (const NumericalError& e) {
      why = e.what();
    }
  }
  throw NumericalError(fmt::format("auto: no selected polynomial in {} could be fitted on every sample: {}", a.channel, why));
}

}  // namespace

PolyModel FitAuto(const std::vector<const sim::Run*>& runs, const AutoOptions& a) {
  std::string invalid;
  if (!a.IsValid(&invalid)) throw InputError("auto: " + invalid);
  if (runs.empty()) throw InputError("auto: no runs to fit");
  const TrainingSpan data = CheckedSpan(runs, a);

  const Library lib = MakeLibrary(runs, a, data.lo, data.hi, data.dt, data.longest);
  const Statistics st = Accumulate(runs, lib.spec, a);
  SelectionRecord record;
  record.rule = AutoRule(a);
  record.folds = static_cast<int>(st.folds);

  std::vector<Visit> all = VisitAll(lib, st, SearchedOffsets(runs, a), a, record);
  // The parsimony order: fewer parameters, then fewer terms beyond the polynomial, then the
  // lower score of 100 s means, then of samples (then the description, so that the order is
  // the same on every machine).
  std::sort(all.begin(), all.end(), [](const Visit& x, const Visit& y) {
    if (x.parameters != y.parameters) return x.parameters < y.parameters;
    if (x.terms != y.terms) return x.terms < y.terms;
    if (x.means_rms != y.means_rms) return x.means_rms < y.means_rms;
    if (x.score.rms != y.score.rms) return x.score.rms < y.score.rms;
    return x.description < y.description;
  });
  const Visit* best = nullptr;
  for (const auto& v : all)
    if (std::isfinite(v.score.rms) && (!best || v.score.rms < best->score.rms)) best = &v;
  if (!best) throw NumericalError(fmt::format("auto: no polynomial in {} could be fitted on these data", a.channel));
  // The parsimony rule: the first model in that order that the lowest score does not beat.
  std::vector<const Visit*> eligible;
  for (const auto& v : all)
    if (std::isfinite(v.score.rms) && !SelectionBeats(best->score, v.score, a.min_gain, a.confidence, st.loro)) {
      eligible.push_back(&v);
    }
  for (const auto& v : all) {
    SelectionStep step;
    step.candidate = v.description;
    step.cv_rms_dph = v.score.rms;
    step.parameters = v.parameters;
    record.visited.push_back(step);
  }
  return FitSelected(runs, a, lib, eligible, *best, record);
}

}  // namespace rlg::model

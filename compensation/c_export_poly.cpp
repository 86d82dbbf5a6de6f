#include "compensation/c_export_poly.h"

#include <algorithm>
#include <fmt/format.h>
#include <stdexcept>
#include <vector>

namespace rlg::compensation::c_export {
namespace {

using model::TermKind;

bool Has(const model::PolySpec& s, TermKind kind) {
  for (const auto& t : s.terms)
    if (t.kind == kind) return true;
  return false;
}

const model::PolyTerm& Term(const model::PolySpec& s, TermKind kind) {
  for (const auto& t : s.terms)
    if (t.kind == kind) return t;
  throw std::logic_error("no such term");
}

/// The time constants of the rate low-passes, each once, the rate term's first: the code
/// evaluates 1 - exp(-dt / tau_r) once per time constant, where the library does so in each
/// RateFilter (the same value).
std::vector<double> RateTaus(const model::PolySpec& s) {
  std::vector<double> taus;
  auto add = [&](double tau) {
    if (std::find(taus.begin(), taus.end(), tau) == taus.end()) taus.push_back(tau);
  };
  for (const auto& t : s.terms)
    if (t.kind == TermKind::kRate) add(t.tau_s);
  for (const auto& t : s.terms)
    if (t.kind == TermKind::kProduct && t.HasRate()) add(t.tau_s);
  return taus;
}
std::string TauName(size_t j) { return j == 0 ? "RATE_TAU_S" : fmt::format("RATE_TAU{}_S", j + 1); }
std::string GainName(size_t j) { return j == 0 ? "rate_gain" : fmt::format("rate_gain{}", j + 1); }
size_t TauIndex(const std::vector<double>& taus, double tau) {
  return static_cast<size_t>(std::find(taus.begin(), taus.end(), tau) - taus.begin());
}

/// A product factor as the code holds it: f[i] of the update, in the order of the terms and
/// their factors (PolyRegressors' FactorSlot), each with its own rate filter.
struct FactorCode {
  const model::PolyTerm* term = nullptr;
  const model::Factor* factor = nullptr;
  std::string signal;  ///< its signal in C: "T_C[0]", "T_C[1] - T_C[0]"
  long rate = -1;      ///< a rate factor's index into the state's factor_* arrays; -1 for a value
  size_t tau = 0;      ///< a rate factor's time constant, an index into RateTaus()
};

std::vector<FactorCode> Factors(const Writer& w, const model::PolySpec& s) {
  const std::vector<double> taus = RateTaus(s);
  std::vector<FactorCode> out;
  long rates = 0;
  for (const auto& t : s.terms) {
    for (const auto& f : t.factors) {
      FactorCode c{&t, &f, fmt::format("T_C[{}]", w.ChannelIndex(f.channel))};
      if (!f.minus.empty()) c.signal += fmt::format(" - T_C[{}]", w.ChannelIndex(f.minus));
      if (f.rate) {
        c.rate = rates++;
        c.tau = TauIndex(taus, t.tau_s);
      }
      out.push_back(c);
    }
  }
  return out;
}

long RateFactors(const std::vector<FactorCode>& factors) {
  return static_cast<long>(
      std::count_if(factors.begin(), factors.end(), [](const FactorCode& c) { return c.rate >= 0; }));
}

/// A factor's signal in the header: "T1", "T2 - T1", "r(T2 - T1)".
std::string SignalText(const model::Factor& f) {
  const std::string s = CommentText(f.channel) + (f.minus.empty() ? "" : " - " + CommentText(f.minus));
  return f.rate ? "r(" + s + ")" : s;
}

/// `text` as the lines of a header comment: " * " + indent, words wrapped before column 99.
std::string Paragraph(const std::string& text, const std::string& indent = "") {
  std::string out, line;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find(' ', at);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(at, end - at);
    if (!line.empty() && 3 + indent.size() + line.size() + 1 + word.size() > 98) {
      out += " * " + indent + line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    at = end + 1;
  }
  return out + " * " + indent + line + "\n";
}

/// The units as ASCII: "°/h/°C^2" -> "deg/h/degC^2".
std::string Ascii(const std::string& unit) {
  std::string out;
  for (size_t i = 0; i < unit.size();) {
    if (unit.compare(i, 3, "°C") == 0) {
      out += "degC";
      i += 3;
    } else if (unit.compare(i, 2, "°") == 0) {
      out += "deg";
      i += 2;
    } else {
      out += unit[i++];
    }
  }
  return out;
}

/// The samples_outside count of the update (with products, after their factors).
const char* const kCountOutside = "  if (s->outside_range) ++s->samples_outside;\n";

/// One polynomial's C code, written in steps: what the model holds (its terms, product factors,
/// rate time constants) read once, each step a part of the header or of the source in order.
class PolyCode {
 public:
  PolyCode(const Writer& w, const model::PolyModel& m)
      : w_(w), m_(m), s_(m.spec), power_on_(s_.offset == model::OffsetRule::kPowerOn),
        rate_(Has(s_, TermKind::kRate)), lag_(Has(s_, TermKind::kLag)), play_(Has(s_, TermKind::kHysteresis)),
        products_(Has(s_, TermKind::kProduct)), factors_(Factors(w, s_)), nr_(RateFactors(factors_)),
        taus_(RateTaus(s_)), timed_(rate_ || lag_ || nr_ > 0), n_(m.coefficients.size()), nf_(factors_.size()),
        zero_(w.Lit(0.0)) {}

  std::string Header() const {
    std::string pre = w_.Preamble("a polynomial, " + s_.Describe());
    pre += ModelLines();
    for (const auto& t : s_.terms) pre += TermLines(t);
    pre += OperatorLines();
    pre += StartLines();
    pre += RangeLines();
    pre += UseLines();
    return w_.Guarded(pre, w_.Macros(ChannelRoles(), power_on_ ? s_.b0_window_s : 0.0) + "\n" + w_.Api(StateDeclarations()));
  }

  std::string Source() const {
    std::string out = Constants();
    out += Init();
    out += UpdateStart();
    out += Operators();
    out += Play();
    out += ProductFactors();
    out += Regressors();
    out += Result();
    return out;
  }

 private:
  // ---- the header ----

  /// The model's equations: d, p and the output.
  std::string ModelLines() const {
    std::string p;
    for (int k = 1; k <= s_.order; ++k) p += fmt::format("{}c{} d{}", k > 1 ? " + " : "", k, k > 1 ? fmt::format("^{}", k) : "");
    std::string out = fmt::format(
        " * The model (T = T_C[0], the channel {ch}; B the measured bias):\n"
        " *   d = {d} - T_ref,  [T_min, T_max] = [{lo:g}, {hi:g}] degC (the range T\n"
        " *     spanned in the fit{beyond}), T_ref = {ref:g} degC\n"
        " *   p = {p}\n",
        fmt::arg("ch", CommentText(s_.channel)), fmt::arg("d", s_.extrapolate ? "T" : "clamp(T, T_min, T_max)"),
        fmt::arg("beyond", s_.extrapolate ? "; beyond it d continues" : ""), fmt::arg("lo", s_.range_C[0]),
        fmt::arg("hi", s_.range_C[1]), fmt::arg("ref", s_.reference_C), fmt::arg("p", p));
    if (power_on_) {
      out += " *   out = B - B0 - (p + sum_j gamma_j g_j - G0)     (power-on offset)\n";
    } else {
      out += " *   out = B - (c0 + p + sum_j gamma_j g_j)          (fitted offset)\n";
    }
    if (!s_.terms.empty()) out += " * with the terms g_j (the coefficients c_k, gamma_j are the fit's, in " + w_.P() + ".c):\n";
    return out;
  }

  /// One term g_j: what it is, its operator.
  std::string TermLines(const model::PolyTerm& t) const {
    switch (t.kind) {
      case TermKind::kHysteresis:
        return fmt::format(
            " *   hysteresis  T - P, P the play operator of width w = {w:g} degC:\n"
            " *               P = clamp(P, T - w/2, T + w/2) every sample, P = T at the first\n",
            fmt::arg("w", t.width_C));
      case TermKind::kRate:
        return fmt::format(
            " *   rate        r (degC/min): the backward difference 60 (T - T_prev) / dt through a\n"
            " *               first-order low-pass, r += (1 - exp(-dt / tau_r)) (60 (T - T_prev) / dt - r),\n"
            " *               tau_r = {tau:g} s; r = 0 at the first sample\n",
            fmt::arg("tau", t.tau_s));
      case TermKind::kLag:
        return fmt::format(
            " *   lag         L - T, L a first-order lag of T with tau = {tau:g} s, advanced exactly for T\n"
            " *               linear between samples; L = T at the first sample{form}\n",
            fmt::arg("tau", t.tau_s),
            fmt::arg("form", w_.Float() ? ".\n"
                                          " *               Float keeps it as its deviation E = L - T_prev, advanced by\n"
                                          " *               E += -(1 - a) E - ((1 - a) / x) (T - T_prev), x = dt / tau,\n"
                                          " *               a = exp(-x): L itself near 50 degC is spaced 3.8e-6 degC in\n"
                                          " *               float, too coarse for its steps"
                                        : ""));
      case TermKind::kGradient:
        return fmt::format(" *   gradient    T_C[{}] - T  ({} - {})\n", w_.ChannelIndex(t.channel), CommentText(t.channel),
                           CommentText(s_.channel));
      case TermKind::kProduct: return ProductLines(t);
    }
    return "";
  }

  /// A product term: its formula, the time constant of its rates, its factors' fitted ranges.
  std::string ProductLines(const model::PolyTerm& t) const {
    std::string formula, ranges;
    int shown = 0;  // ranges listed: a repeated factor's once
    for (size_t i = 0; i < t.factors.size(); ++i) {
      const model::Factor& f = t.factors[i];
      const std::string signal = SignalText(f);
      formula += (i ? " " : "") + (f.rate ? signal : "(" + signal + (f.minus.empty() ? " - T_ref)" : ")"));
      if (i > 0 && f.SameSignal(t.factors[i - 1]) && f.range == t.factors[i - 1].range) continue;
      ++shown;
      ranges += fmt::format("{}{} in [{:g}, {:g}] {}", ranges.empty() ? "" : ", ", signal, f.range[0], f.range[1],
                            f.rate ? "degC/min" : "degC");
    }
    if (t.HasRate()) formula += fmt::format(", tau_r = {:g} s", t.tau_s);
    std::string out = fmt::format(" *   {:<11} {}\n", CommentText(t.Name()), formula);
    return out + Paragraph((shown > 1 ? "fitted ranges: " : "fitted range: ") + ranges, "              ");
  }

  /// What the terms share: the product factors, the rate factors' filters, the time steps.
  std::string OperatorLines() const {
    std::string out;
    if (products_) {
      out += Paragraph(
          std::string("A product's factors: Tj - T_ref for a channel Tj, Tj - Tk for a difference, r(S) for a rate. ") +
              (s_.extrapolate ? "Each factor's signal (Tj, Tj - Tk, r(S)) is used as it is, beyond its fitted range too; "
                                "a factor beyond its range flags the sample."
                              : "Each factor's signal (Tj, Tj - Tk, r(S)) is clamped to its fitted range, before T_ref is "
                                "subtracted; a factor beyond its range flags the sample."),
          "  ");
    }
    if (nr_ > 0) {
      out += " *   r(S) (degC/min): the rate of the signal S (Tj or Tj - Tk, as it is) through a first-order\n"
             " *   low-pass of its own (one per rate factor, in the state), r = 0 at the first sample:\n"
             " *     r += (1 - exp(-dt / tau_r)) (60 (S - S_prev) / dt - r)\n";
    }
    if (timed_) {
      const std::string rates = nr_ > 0 ? "the rates" : rate_ ? "the rate" : "";
      out += fmt::format(
          " *   dt = t_s - t_s of the previous sample; a sample whose time does not advance (dt <= 0)\n"
          " *   leaves {} as {} were. exp is evaluated every sample ({}),\n"
          " *   so sample times may be irregular.\n",
          rates.empty() ? "the lag" : lag_ ? rates + " and the lag" : rates,
          (lag_ && !rates.empty()) || nr_ > 0 ? "they" : "it", w_.Expm1());
    }
    return out;
  }

  /// What the first sample captures, and the B0 window.
  std::string StartLines() const {
    std::string out = " * Captured at the first sample after " + w_.P() + "_init: t_first = t_s";
    if (!s_.terms.empty()) out += "\n *   and the start values of the terms above";
    out += ".\n";
    if (power_on_) {
      out += fmt::format(
          " * B0 window: while t_s < t_first + {M}_B0_WINDOW_S ({w:g} s), B0 is the running mean of B and\n"
          " *   G0 that of p + sum_j gamma_j g_j over the samples so far (the output there uses the means\n"
          " *   known so far); at the first sample past the window both are frozen for the rest of the run.\n",
          fmt::arg("M", w_.M()), fmt::arg("w", s_.b0_window_s));
    }
    return out + " *\n";
  }

  /// What the code does outside the fitted range, and the flag it sets.
  std::string RangeLines() const {
    const std::string flagged =
        fmt::format("s->outside_range is 1 when the last sample's T lay outside [T_min, T_max]{}, s->samples_outside "
                    "counts such samples since {}_init.",
                    products_ ? " or a product factor's signal outside its fitted range" : "", w_.P());
    if (s_.extrapolate) {
      return Paragraph(std::string("Beyond the fitted range the model extrapolates (beyond_range extrapolate): nothing "
                                   "is clamped, the polynomial continues in d") +
                       (products_ ? " and each product with its factors" : "") + ". " + flagged);
    }
    return Paragraph(std::string("Outside the fitted range [T_min, T_max]: the polynomial is held at the range's edge "
                                 "(T is clamped in d") +
                     (products_ ? ", each product factor to its own fitted range; the other terms use T as it is). "
                                : "; the terms use T as it is). ") +
                     flagged);
  }

  /// How to call the code, what it needs, what it does.
  std::string UseLines() const {
    return fmt::format(
        " *\n"
        " * Use: {P}_init(&s) at power-on (and before each new run), then for every sample\n"
        " * out = {P}_update(&s, t_s, T_C, bias_dph), t_s increasing (any origin{float_note}).\n"
        " * The state is plain data owned by the caller: no heap, no global state, one state per\n"
        " * gyro axis. {libm}\n"
        " * The operations of rlgtherm's LinearCompensator (model/linear_compensator.h), its sums\n"
        " * taken left to right{lagform}.\n"
        " */\n",
        fmt::arg("P", w_.P()), fmt::arg("lagform", w_.Float() && lag_ ? ", the lag as E (above)" : ""),
        fmt::arg("float_note", w_.Float() && timed_ ? ";\n * in float, time since power-on: dt is a difference of "
                                                      "t_s, whose float spacing grows with t_s"
                                                    : ""),
        fmt::arg("libm", timed_ ? "Needs " + w_.Expm1() + " from libm (<math.h>; link with -lm)."
                                : std::string("Needs nothing from libm.")));
  }

  /// A field of the state: its declaration in the header and its zero in <prefix>_init.
  struct Field {
    std::string type, name, what;
    long count = 0;  ///< > 0: an array of one value per rate factor, zeroed in init's loop
  };

  /// The state's fields, in their order in the struct and in init.
  std::vector<Field> StateFields() const {
    const std::string& R = w_.R();
    std::vector<Field> fields = {{"int", "started", "0 until the first sample after init"}};
    if (products_) {
      fields.push_back({"int", "outside_range", "1: the last sample's T or a product factor lay outside its fitted range"});
      fields.push_back({"unsigned long", "samples_outside", "samples so flagged since init"});
    } else {
      fields.push_back({"int", "outside_range", "1: the last sample's T lay outside [T_min, T_max]"});
      fields.push_back({"unsigned long", "samples_outside", "samples outside [T_min, T_max] since init"});
    }
    if (power_on_) {
      fields.push_back({"int", "b0_frozen", "1 once the B0 window has passed"});
      fields.push_back({"long", "b0_count", "samples in the B0 mean"});
      fields.push_back({R, "t_first_s", "t_s of the first sample (s)"});
      fields.push_back({R, "b0_sum_dph", "the sum of B over the B0 mean's samples (deg/h)"});
      fields.push_back({R, "b0_dph", "B0 (deg/h): the running mean in the window, then frozen"});
      fields.push_back({R, "g0_sum_dph", "the sum of the model over the same samples (deg/h)"});
      fields.push_back({R, "g0_dph", "G0 (deg/h): its running mean, then frozen"});
    }
    if (timed_) fields.push_back({R, "t_prev_s", "t_s of the last sample that advanced time (s)"});
    if (rate_ || lag_) fields.push_back({R, "T_prev_C", "T then (degC)"});
    if (play_) fields.push_back({R, "play_C", "P (degC)"});
    if (rate_) fields.push_back({R, "rate_C_per_min", "r (degC/min)"});
    if (lag_) fields.push_back(w_.Float() ? Field{R, "lag_dev_C", "E = L - T_prev (degC)"} : Field{R, "lag_C", "L (degC)"});
    if (nr_ > 0) {
      fields.push_back({R, "factor_prev_C", "each rate factor's S then (degC)", nr_});
      fields.push_back({R, "factor_rate_C_per_min", "each rate factor's r (degC/min)", nr_});
    }
    return fields;
  }

  /// The state's fields as the header declares them, "  TYPE NAME; /* what */" a line.
  std::string StateDeclarations() const {
    std::string out;
    for (const Field& f : StateFields()) {
      out += fmt::format("  {} {}{}; /* {} */\n", f.type, f.name, f.count > 0 ? fmt::format("[{}]", f.count) : "", f.what);
    }
    return out;
  }

  /// What each channel of T_C is to the model.
  std::vector<std::string> ChannelRoles() const {
    const std::vector<std::string>& channels = w_.Channels();
    std::vector<std::string> roles(channels.size());
    roles[0] = "T, the polynomial's channel";
    for (size_t i = 1; i < channels.size(); ++i) {
      bool gradient = false, product = false;
      for (const auto& t : s_.terms) {
        gradient = gradient || (t.kind == TermKind::kGradient && t.channel == channels[i]);
        for (const auto& f : t.factors) product = product || f.channel == channels[i] || f.minus == channels[i];
      }
      roles[i] = gradient && product ? "a gradient's and a product's channel"
                 : gradient          ? "a gradient's channel"
                                     : "a product's channel";
    }
    return roles;
  }

  // ---- the source ----

  /// The opening comment, the includes, the coefficients and the fitted range of T.
  std::string Constants() const {
    std::string out = fmt::format(
        "/* {P}.c: {what},\n * generated by `rlgtherm export`; the API and the model are in {P}.h. */\n",
        fmt::arg("P", w_.P()), fmt::arg("what", CommentText(s_.Describe())));
    if (timed_) out += "#include <math.h>\n";
    out += fmt::format("#include \"{}.h\"\n\n", w_.P());
    out += fmt::format("/* The coefficients, in the order of the regressors g[] below. */\nstatic const {} BETA[{}] = {{\n",
                       w_.R(), n_);
    for (size_t i = 0; i < n_; ++i) {
      const auto& c = m_.coefficients[i];
      out += fmt::format("  {}{} /* {} ({}) */\n", w_.Lit(c.value), i + 1 < n_ ? "," : " ", CommentText(c.name),
                         CommentText(Ascii(c.unit)));
    }
    out += "};\n";
    out += fmt::format("/* The fitted range of T and the reference (degC). */\nstatic const {R} T_MIN_C = {lo};\n"
                       "static const {R} T_MAX_C = {hi};\nstatic const {R} T_REF_C = {ref};\n",
                       fmt::arg("R", w_.R()), fmt::arg("lo", w_.Lit(s_.range_C[0])), fmt::arg("hi", w_.Lit(s_.range_C[1])),
                       fmt::arg("ref", w_.Lit(s_.reference_C)));
    out += FactorRanges();
    out += OperatorConstants();
    return out;
  }

  /// The range each product factor's signal spanned in the fit.
  std::string FactorRanges() const {
    if (nf_ == 0) return "";
    std::string out =
        fmt::format("/* The product factors f[] of the update: the range each one's signal spanned in the fit. */\n"
                    "static const {} FACTOR_RANGE[{}][2] = {{\n",
                    w_.R(), nf_);
    for (size_t i = 0; i < nf_; ++i) {
      const model::Factor& f = *factors_[i].factor;
      out += fmt::format("  {{{}, {}}}{} /* f[{}]: {} of {} ({}) */\n", w_.Lit(f.range[0]), w_.Lit(f.range[1]),
                         i + 1 < nf_ ? "," : " ", i, SignalText(f), CommentText(factors_[i].term->Name()),
                         f.rate ? "degC/min" : "degC");
    }
    return out + "};\n";
  }

  /// The play operator's half width and the time constants of the rates and the lag.
  std::string OperatorConstants() const {
    const std::string& R = w_.R();
    std::string out;
    if (play_) {
      out += fmt::format("/* Half the play operator's width (degC). */\nstatic const {} HALF_WIDTH_C = {};\n", R,
                         w_.Lit(0.5 * Term(s_, TermKind::kHysteresis).width_C));
    }
    if (rate_ && nr_ == 0) {
      out += fmt::format("/* The rate's low-pass time constant (s). */\nstatic const {} RATE_TAU_S = {};\n", R,
                         w_.Lit(Term(s_, TermKind::kRate).tau_s));
    }
    for (size_t j = 0; j < taus_.size() && nr_ > 0; ++j) {
      std::string users = rate_ && j == 0 ? "the rate term" : "";
      for (const auto& t : s_.terms) {
        if (t.kind == TermKind::kProduct && t.HasRate() && t.tau_s == taus_[j]) {
          users += (users.empty() ? "" : ", ") + t.Name();
        }
      }
      out += fmt::format("/* The time constant of the rate low-pass of {} (s). */\nstatic const {} {} = {};\n",
                         CommentText(users), R, TauName(j), w_.Lit(taus_[j]));
    }
    if (lag_) {
      out += fmt::format("/* The lag's time constant (s). */\nstatic const {} LAG_TAU_S = {};\n", R,
                         w_.Lit(Term(s_, TermKind::kLag).tau_s));
    }
    return out;
  }

  /// <prefix>_init: every field of the state zero.
  std::string Init() const {
    std::string out = fmt::format("\nvoid {P}_init({P}_state *s) {{\n", fmt::arg("P", w_.P()));
    if (nr_ > 0) out += "  int i;\n";
    std::string arrays;
    for (const Field& f : StateFields()) {
      const std::string zero = f.type == w_.R() ? zero_ : "0";
      if (f.count > 0) {
        arrays += fmt::format("    s->{}[i] = {};\n", f.name, zero);
      } else {
        out += fmt::format("  s->{} = {};\n", f.name, zero);
      }
    }
    if (nr_ > 0) out += fmt::format("  for (i = 0; i < {}; ++i) {{\n{}  }}\n", nr_, arrays);
    return out + "}\n\n";
  }

  /// <prefix>_update's start: d of T (held or not), the locals, the first sample and the flag.
  std::string UpdateStart() const {
    const std::string& R = w_.R();
    std::string out = fmt::format("{R} {P}_update({P}_state *s, {R} t_s, const {R} *T_C, {R} bias_dph) {{\n",
                                  fmt::arg("R", R), fmt::arg("P", w_.P()));
    out += fmt::format("  const {R} T = T_C[0];\n", fmt::arg("R", R));
    if (s_.extrapolate) {
      out += fmt::format("  const {R} d = T - T_REF_C;\n", fmt::arg("R", R));
    } else {
      out += fmt::format("  const {R} clipped = T < T_MIN_C ? T_MIN_C : (T_MAX_C < T ? T_MAX_C : T);\n"
                         "  const {R} d = clipped - T_REF_C;\n",
                         fmt::arg("R", R));
    }
    out += fmt::format("  const int first = !s->started;\n  {R} g[{n}];\n", fmt::arg("R", R), fmt::arg("n", n_));
    if (nf_ > 0) out += fmt::format("  {} f[{}];\n", R, nf_);
    if (nr_ > 0) out += fmt::format("  {} S[{}];\n", R, nr_);
    out += fmt::format("  {} model = {};\n  int i;\n", R, zero_);
    if (!power_on_ && !timed_) out += "  (void)t_s;\n";
    out += "  s->started = 1;\n";
    if (power_on_) out += "  if (first) s->t_first_s = t_s;\n";
    out += "  s->outside_range = T < T_MIN_C || T > T_MAX_C;\n";
    if (nf_ == 0) out += kCountOutside;
    if (!play_ && !timed_) out += "  (void)first;\n";
    return out;
  }

  /// The timed operators (model/causal_operators.cpp): the rate factors' signals, the start
  /// values at the first sample, then each sample that advances time.
  std::string Operators() const {
    std::string out;
    if (nr_ > 0) {
      out += "  /* the rate factors' signals S, as they are */\n";
      for (const auto& c : factors_)
        if (c.rate >= 0) out += fmt::format("  S[{}] = {};\n", c.rate, c.signal);
    }
    if (!timed_) return out;
    out += "  if (first) {\n    s->t_prev_s = t_s;\n";
    if (rate_ || lag_) out += "    s->T_prev_C = T;\n";
    if (rate_) out += fmt::format("    s->rate_C_per_min = {};\n", zero_);
    if (lag_) out += w_.Float() ? fmt::format("    s->lag_dev_C = {};\n", zero_) : "    s->lag_C = T;\n";
    if (nr_ > 0) {
      out += fmt::format("    for (i = 0; i < {}; ++i) {{\n      s->factor_prev_C[i] = S[i];\n"
                         "      s->factor_rate_C_per_min[i] = {};\n    }}\n",
                         nr_, zero_);
    }
    out += "  } else {\n";
    out += fmt::format("    const {} dt = t_s - s->t_prev_s;\n    if (dt > {}) {{\n", w_.R(), zero_);
    out += Advance();
    out += "      s->t_prev_s = t_s;\n";
    if (rate_ || lag_) out += "      s->T_prev_C = T;\n";
    return out + "    }\n  }\n";
  }

  /// A step of dt > 0: the rate low-passes (with rate factors, 1 - exp(-dt / tau_r) once per
  /// time constant, the rate term's too), the lag, the rate factors' filters.
  std::string Advance() const {
    std::string out;
    for (size_t j = 0; j < taus_.size() && nr_ > 0; ++j) {
      out += fmt::format("      const {R} {gain} = -{expm1}(-dt / {tau}); /* 1 - exp(-dt / tau_r) */\n",
                         fmt::arg("R", w_.R()), fmt::arg("gain", GainName(j)), fmt::arg("expm1", w_.Expm1()),
                         fmt::arg("tau", TauName(j)));
    }
    if (rate_) {
      out += fmt::format(
          "      const {R} difference = {sixty} * (T - s->T_prev_C) / dt;\n"
          "      s->rate_C_per_min += {gain} * (difference - s->rate_C_per_min);\n",
          fmt::arg("R", w_.R()), fmt::arg("sixty", w_.Lit(60.0)),
          fmt::arg("gain", nr_ > 0 ? GainName(0) : "-" + w_.Expm1() + "(-dt / RATE_TAU_S)"));
    }
    if (lag_) out += LagStep();
    for (const auto& c : factors_) {
      if (c.rate < 0) continue;
      out += fmt::format(
          "      s->factor_rate_C_per_min[{k}] +=\n"
          "          {gain} * ({sixty} * (S[{k}] - s->factor_prev_C[{k}]) / dt - s->factor_rate_C_per_min[{k}]);\n"
          "      s->factor_prev_C[{k}] = S[{k}];\n",
          fmt::arg("k", c.rate), fmt::arg("gain", GainName(c.tau)), fmt::arg("sixty", w_.Lit(60.0)));
    }
    return out;
  }

  /// The lag's step, exact for T linear between samples.
  std::string LagStep() const {
    if (w_.Float()) {
      // E = L - T_prev: L_k = a L + (1 - a) T_prev + (T - T_prev) phi with phi = 1 - (1 - a) / x
      // gives E_k = a E - (1 - phi) (T - T_prev), 1 - phi = (1 - a) / x: no difference of
      // nearly equal numbers, and E is small, so float keeps its steps.
      return fmt::format(
          "      const {R} x = dt / LAG_TAU_S;\n"
          "      const {R} one_minus_a = -{expm1}(-x);\n"
          "      s->lag_dev_C -= one_minus_a * s->lag_dev_C + one_minus_a / x * (T - s->T_prev_C);\n",
          fmt::arg("R", w_.R()), fmt::arg("expm1", w_.Expm1()));
    }
    return fmt::format(
        "      const {R} x = dt / LAG_TAU_S;\n"
        "      const {R} one_minus_a = -{expm1}(-x);\n"
        "      /* phi = 1 - (1 - a) / x, by its series below x = 1e-4 (the difference loses digits) */\n"
        "      const {R} phi = x < {small} ? x * ({half} - x / {six}) : {one} - one_minus_a / x;\n"
        "      s->lag_C = ({one} - one_minus_a) * s->lag_C + one_minus_a * s->T_prev_C +\n"
        "                 (T - s->T_prev_C) * phi;\n",
        fmt::arg("R", w_.R()), fmt::arg("expm1", w_.Expm1()), fmt::arg("small", w_.Lit(1e-4)),
        fmt::arg("half", w_.Lit(0.5)), fmt::arg("six", w_.Lit(6.0)), fmt::arg("one", w_.Lit(1.0)));
  }

  /// The play operator's step.
  std::string Play() const {
    if (!play_) return "";
    return fmt::format(
        "  if (first) s->play_C = T;\n"
        "  {{\n"
        "    const {R} lo = T - HALF_WIDTH_C;\n"
        "    const {R} hi = T + HALF_WIDTH_C;\n"
        "    s->play_C = s->play_C < lo ? lo : (hi < s->play_C ? hi : s->play_C);\n"
        "  }}\n",
        fmt::arg("R", w_.R()));
  }

  /// The product factors f[]: each signal, flagged beyond its fitted range (and held to it
  /// unless the model extrapolates); then the samples_outside count.
  std::string ProductFactors() const {
    if (nf_ == 0) return "";
    std::string out = s_.extrapolate
                          ? "  /* the product factors: each signal, flagged beyond the range it spanned in the fit */\n"
                          : "  /* the product factors: each signal, flagged beyond the range it spanned in the fit\n"
                            "   * and held to it */\n";
    for (size_t i = 0; i < nf_; ++i) {
      out += factors_[i].rate >= 0 ? fmt::format("  f[{}] = s->factor_rate_C_per_min[{}];\n", i, factors_[i].rate)
                                   : fmt::format("  f[{}] = {};\n", i, factors_[i].signal);
    }
    out += fmt::format("  for (i = 0; i < {}; ++i) {{\n"
                       "    if (f[i] < FACTOR_RANGE[i][0] || f[i] > FACTOR_RANGE[i][1]) s->outside_range = 1;\n",
                       nf_);
    if (!s_.extrapolate) {
      out += "    f[i] = f[i] < FACTOR_RANGE[i][0] ? FACTOR_RANGE[i][0]\n"
             "                                     : (FACTOR_RANGE[i][1] < f[i] ? FACTOR_RANGE[i][1] : f[i]);\n";
    }
    return out + "  }\n" + kCountOutside;
  }

  /// The regressors g[], in the coefficients' order (model/poly_model.cpp).
  std::string Regressors() const {
    size_t at = 0, next_factor = 0;
    std::string out = "  /* the regressors */\n";
    if (!power_on_) out += fmt::format("  g[{}] = {};\n", at++, w_.Lit(1.0));
    out += fmt::format("  g[{}] = d;\n", at++);
    for (int k = 2; k <= s_.order; ++k, ++at) out += fmt::format("  g[{}] = g[{}] * d;\n", at, at - 1);
    for (const auto& t : s_.terms) {
      switch (t.kind) {
        case TermKind::kRate: out += fmt::format("  g[{}] = s->rate_C_per_min;\n", at++); break;
        case TermKind::kHysteresis: out += fmt::format("  g[{}] = T - s->play_C;\n", at++); break;
        case TermKind::kLag:
          // float: L - T = E + T_prev - T, and T_prev = T after a sample that advanced time.
          out += w_.Float() ? fmt::format("  g[{}] = s->lag_dev_C - (T - s->T_prev_C);\n", at++)
                            : fmt::format("  g[{}] = s->lag_C - T;\n", at++);
          break;
        case TermKind::kGradient:
          out += fmt::format("  g[{}] = T_C[{}] - T;\n", at++, w_.ChannelIndex(t.channel));
          break;
        case TermKind::kProduct:
          out += fmt::format("  g[{}] = {}; /* {} */\n", at++, Product(t, next_factor), CommentText(t.Name()));
          break;
      }
    }
    return out;
  }

  /// A product term's regressor, its factors from f[next_factor] on (advanced past them). The
  /// library's product starts from 1.0 and multiplies left to right: 1.0 * f is f.
  static std::string Product(const model::PolyTerm& t, size_t& next_factor) {
    std::string product;
    for (const auto& f : t.factors) {
      const size_t i = next_factor++;
      product += (product.empty() ? "" : " * ") +
                 (f.minus.empty() && !f.rate ? fmt::format("(f[{}] - T_REF_C)", i) : fmt::format("f[{}]", i));
    }
    return product;
  }

  /// The model's sum and the compensated bias (referred to the power-on B0 and G0 or not).
  std::string Result() const {
    std::string out = fmt::format("  for (i = 0; i < {}; ++i) model += BETA[i] * g[i];\n", n_);
    if (power_on_) {
      out += w_.B0Update(true);
      out += "  return bias_dph - s->b0_dph - (model - s->g0_dph);\n";
    } else {
      out += "  return bias_dph - model;\n";
    }
    return out + "}\n";
  }

  const Writer& w_;
  const model::PolyModel& m_;
  const model::PolySpec& s_;
  const bool power_on_, rate_, lag_, play_, products_;
  const std::vector<FactorCode> factors_;
  const long nr_;                   ///< the rate factors
  const std::vector<double> taus_;  ///< RateTaus()
  const bool timed_;                ///< the code keeps time: a rate, a lag or a rate factor
  const size_t n_, nf_;             ///< the coefficients, the product factors
  const std::string zero_;          ///< 0 as a literal of the type
};

}  // namespace

std::string PolyHeader(const Writer& w, const model::PolyModel& m) { return PolyCode(w, m).Header(); }

std::string PolySource(const Writer& w, const model::PolyModel& m) { return PolyCode(w, m).Source(); }

}  // namespace rlg::compensation::c_export

#include "tools/rlgtherm/verb_figures.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <optional>
#include <plplot/plstream.h>

#include "model/allan.h"
#include "tools/rlgtherm/plot_kit.h"

namespace rlg::cli {
namespace {

using plot::Colour;

/// Means of consecutive blocks of m samples, as the figures show the bias: 1 s samples of a
/// laser gyro are mostly white noise. A last, shorter block is dropped (it is not an m-sample
/// mean, and one of a few samples stands out as a spike), unless it is the only one.
std::vector<double> BlockMeans(const std::vector<double>& v, size_t m) {
  std::vector<double> out;
  for (size_t i = 0; i < v.size(); i += m) {
    const size_t end = std::min(v.size(), i + m);
    if (end - i < m && i > 0) break;
    double sum = 0.0;
    for (size_t k = i; k < end; ++k) sum += v[k];
    out.push_back(sum / static_cast<double>(end - i));
  }
  return out;
}

/// Labels of a log10 axis the reader can read values from: 1, 2 and 5 x 10^k when the axis
/// spans up to three decades, else the decades; written as plain numbers ("0.02", "500").
/// `side` "b" or "l" (PLplot mtex sides); the axis box is drawn without numeric labels.
void LogAxisLabels(plstream& pls, const char* side, std::pair<double, double> range) {
  const bool fine = range.second - range.first <= 3.0;
  pls.col0(plot::kBlack);
  pls.schr(0.0, 0.8);
  for (int k = static_cast<int>(std::floor(range.first)); k <= static_cast<int>(std::ceil(range.second)); ++k) {
    for (double m : {1.0, 2.0, 5.0}) {
      if (!fine && m != 1.0) continue;
      const double v = m * std::pow(10.0, k), at = (std::log10(v) - range.first) / (range.second - range.first);
      if (at < 0.0 || at > 1.0) continue;
      const std::string text = fmt::format("{:g}", v);
      if (side[0] == 'b') pls.mtex("b", 1.6, at, 0.5, text.c_str());
      else pls.mtex("lv", 0.8, at, 1.0, text.c_str());
    }
  }
}

std::vector<double> Log10(const std::vector<double>& v) {
  std::vector<double> out;
  for (double x : v) out.push_back(x > 0.0 ? std::log10(x) : NAN);
  return out;
}

/// Ranges in log10 units padded by a tenth of a decade, so that a log axis shows at least one
/// labelled decade boundary or a few minor ticks.
std::pair<double, double> LogPadded(const plot::Range& r) {
  if (!(r.hi >= r.lo)) return {-1.0, 1.0};
  const double lo = std::log10(r.lo), hi = std::log10(r.hi);
  const double pad = std::max(0.1, 0.05 * (hi - lo));
  return {lo - pad, hi + pad};
}

/// `dir`, once PLplot is known to draw PNG: no directory is made for figures it cannot draw.
const std::string& DrawableDir(const std::string& dir) {
  plot::RequirePngCairo("--plot");
  return dir;
}

}  // namespace

FigureDirectory::FigureDirectory(const std::string& dir)
    : dir_(DrawableDir(dir), io::OutputDirectoryNaming{"--plot", "figures", "figure"}) {}

std::string FigureDirectory::Stage(const std::string& stem, std::string& name) {
  name = stem + ".png";
  for (int k = 2; std::find(names_.begin(), names_.end(), name) != names_.end(); ++k) name = fmt::format("{}-{}.png", stem, k);
  names_.push_back(name);
  return dir_.Stage(name);
}

void FigureDirectory::Commit() {
  const std::vector<std::string> names = dir_.Commit();
  fmt::print(stderr, "rlgtherm: {} figure{} in {}: {}\n", names.size(), names.size() == 1 ? "" : "s", dir_.dir(),
             fmt::join(names, ", "));
}

void FigureDirectory::Check(const std::string& path, const std::string& name) {
  plot::CheckPngComplete(path, dir_.dir() + "/" + name, dir_.NothingWritten());
}

void FigureDirectory::WriteBias(const sim::Run& run, const std::vector<double>& before, const std::string& before_label,
                                const std::vector<double>& after, const std::string& after_label,
                                const std::string& suffix) {
  const double dt = model::SamplePeriod(run.t_s);
  const size_t m = std::max<size_t>(1, static_cast<size_t>(std::lround(100.0 / dt)));
  std::vector<double> hours;
  for (double t : BlockMeans(run.t_s, m)) hours.push_back(t / 3600.0);
  const std::vector<double> b = BlockMeans(before, m), a = BlockMeans(after, m);
  std::vector<std::pair<std::string, std::vector<double>>> temperatures;
  for (size_t c = 0; c < run.names.size(); ++c) {
    if (run.names[c].size() > 1 && run.names[c][0] == 'T') temperatures.emplace_back(run.names[c], BlockMeans(run.columns[c], m));
  }
  plot::Range rx, rb, ra, rt;
  rx.Add(hours);
  rb.Add(b);
  rb.Add(a);
  ra.Add(a);
  for (const auto& [name, v] : temperatures) rt.Add(v);
  const auto x = rx.Padded();
  const std::string means = fmt::format("{:g} s means", static_cast<double>(m) * dt);

  std::string name;
  const std::string path = Stage("bias_" + plot::FileNamePart(run.id) + suffix, name);
  {
    plot::Page page(path, 1400, 1200, 1, 3);
    page.pls().syax(5, 0);  // 0.02 °/h as such, not 2 under a "(x10^-2)" beside the title
    const std::string time = "time since power-on (h)";
    page.Frame(1, x, rb.Padded(), time, "bias (°/h)", fmt::format("run {}: bias before and after compensation, {}", run.id, means));
    page.Legend({{plot::kRed, fmt::format("before ({})", before_label)}, {plot::kBlue, fmt::format("after ({})", after_label)}});
    page.Curve(plot::kGrey, {x.first, x.second}, {0.0, 0.0});
    page.Curve(plot::kRed, hours, b);
    page.Curve(plot::kBlue, hours, a);

    page.Frame(2, x, ra.Padded(), time, "bias (°/h)", fmt::format("run {}: after compensation alone, {}", run.id, means));
    page.Legend({{plot::kBlue, fmt::format("after ({})", after_label)}});
    page.Curve(plot::kGrey, {x.first, x.second}, {0.0, 0.0});
    page.Curve(plot::kBlue, hours, a);

    page.Frame(3, x, rt.Padded(), time, "temperature (°C)", fmt::format("run {}: temperatures, {}", run.id, means));
    const Colour colours[] = {plot::kRed, plot::kBlue, plot::kGreen, plot::kOrange, plot::kPurple};
    std::vector<std::pair<Colour, std::string>> legend;
    size_t next = 0;
    for (const auto& [channel, v] : temperatures) {
      // The ambient dashed in black; the sensors in colours (repeating past five, then dashed).
      const bool ambient = channel == "T_amb";
      const Colour c = ambient ? plot::kBlack : colours[next % 5];
      const int style = ambient || next >= 5 ? 2 : 1;
      if (!ambient) ++next;
      page.Curve(c, hours, v, style);
      legend.emplace_back(c, ambient ? channel + " (dashed)" : channel);
    }
    page.Legend(legend);
  }
  Check(path, name);
}

void FigureDirectory::WriteAllan(const std::string& run, const std::string& series, const model::AllanCurve& curve,
                                 const model::NoiseReadOffs& r, const std::string& suffix) {
  using model::NoiseTerm;
  std::vector<double> tau, adev;  // the positive points (a log axis has no place for 0)
  for (size_t i = 0; i < curve.tau_s.size(); ++i) {
    if (curve.adev[i] > 0.0) tau.push_back(curve.tau_s[i]), adev.push_back(curve.adev[i]);
  }
  // The resolved terms, each with its line sigma(tau) and where the report reads it: N at
  // tau = 1 s on the -1/2 line, K at tau = 3 s on the +1/2 line, B from the flat floor 0.664 B.
  struct Line {
    NoiseTerm term;
    Colour colour;
    std::string label;
    double read_tau_s;  ///< 0: flat (the floor, read along the curve)
    double read_sigma;
    std::function<double(double)> sigma;
  };
  std::vector<Line> lines;
  std::vector<std::string> unresolved;
  const model::NoiseTerms& f = r.fitted;
  auto add = [&](NoiseTerm t, Colour c, const char* what, const char* unit, const char* where, double tau0, double sig0,
                 std::function<double(double)> sigma) {
    const std::string value = model::FormatReadOff(r, t, 5);
    if (r[t].resolved) {
      lines.push_back({t, c, fmt::format("{} {} {} ({})", what, value, unit, where), tau0, sig0, std::move(sigma)});
    } else {
      unresolved.push_back(fmt::format("{}: {} {}", what, value, unit));
    }
  };
  add(NoiseTerm::kArw, plot::kRed, "ARW", "°/√h", "σ at τ = 1 s, slope -1/2", 1.0, f.arw,
      [n = f.arw](double t) { return n / std::sqrt(t); });
  add(NoiseTerm::kBiasInstability, plot::kGreen, "bias instability", "°/h", "floor σ = 0.664 B", 0.0,
      0.664 * f.bias_instability, [b = f.bias_instability](double) { return 0.664 * b; });
  add(NoiseTerm::kRrw, plot::kPurple, "RRW", "°/h/√h", "σ at τ = 3 s, slope +1/2", 3.0, f.rrw,
      [k = f.rrw](double t) { return k * std::sqrt(t / 3.0); });

  plot::Range rt, rs;
  rt.Add(tau);
  rs.Add(adev);
  for (const auto& l : lines) {
    if (l.read_tau_s > 0.0) rt.Add(l.read_tau_s);  // the read-off point is in the picture
    rs.Add(l.read_sigma);
  }
  const auto x = LogPadded(rt), y = LogPadded(rs);

  std::string name;
  const std::string path = Stage("allan_" + plot::FileNamePart(run) + suffix, name);
  {
    plot::Page page(path, 1200, 900, 1, 1);
    plstream& pls = page.pls();
    page.ReserveBelow(static_cast<int>(lines.size() + unresolved.size()) + 2);  // + the gap under the axis label
    page.Frame(1, x, y, "averaging time τ (s)", "Allan deviation σ(τ) (°/h)",
               fmt::format("run {}: Allan deviation of {}", run, series), "bcstl", "bcstvl");
    LogAxisLabels(pls, "b", x);
    LogAxisLabels(pls, "l", y);
    std::vector<std::pair<Colour, std::string>> legend{{plot::kBlack, "measured"}};
    page.Curve(plot::kBlack, Log10(tau), Log10(adev));
    page.Dots(plot::kBlack, Log10(tau), Log10(adev), true);
    for (const auto& l : lines) {
      std::vector<double> lx, ly;
      for (int i = 0; i <= 50; ++i) {
        const double lt = x.first + (x.second - x.first) * i / 50.0;
        lx.push_back(lt);
        ly.push_back(std::log10(l.sigma(std::pow(10.0, lt))));
      }
      page.Curve(l.colour, lx, ly, 2);
      if (l.read_tau_s > 0.0) {
        page.Dots(l.colour, {std::log10(l.read_tau_s)}, {std::log10(l.read_sigma)}, true);
      }
    }
    // The read-offs under the axis, where no curve can run through them: the resolved terms in
    // their lines' colours, then the terms the curve does not resolve in grey, with their bounds.
    int row = 0;
    for (const auto& l : lines) page.Below(row++, l.colour, l.label);
    for (const auto& u : unresolved) page.Below(row++, plot::kGrey, u + ", no line drawn");
    page.Legend({{plot::kBlack, "measured σ(τ), overlapping, octave τ"}, {plot::kGrey, "dashed: fitted noise terms (IEEE Std 952)"}});
  }
  Check(path, name);
}

void FigureDirectory::WriteTable1(const std::vector<model::PairScore>& scores, const std::map<std::string, double>& paper,
                                  double average_s) {
  // The paper's SSE_ave are ~100x rlgtherm's (docs/results.md, "The default gyro against the paper"):
  // on one axis rlgtherm's bars would be flat. Each gets its own panel and scale; what compares
  // is the ranking of the pairs.
  const bool with_paper = std::any_of(scores.begin(), scores.end(), [&](const auto& s) { return paper.count(s.combination.name) > 0; });
  const double n = static_cast<double>(scores.size());
  std::string name;
  const std::string path = Stage("table1", name);
  {
    plot::Page page(path, 1200, with_paper ? 1100 : 650, 1, with_paper ? 2 : 1);
    plstream& pls = page.pls();
    pls.syax(5, 0);  // 0.0242 as such, not 2.42 under a "(x10^-2)" the bar labels do not share
    auto panel = [&](int subpage, const std::string& title, Colour colour, const std::vector<std::optional<double>>& values) {
      plot::Range ry;
      ry.Add(0.0);
      for (const auto& v : values)
        if (v) ry.Add(*v);
      const double top = ry.hi > 0.0 ? ry.hi * 1.12 : 1.0;  // room above the tallest bar for its value
      size_t best = values.size();
      for (size_t i = 0; i < values.size(); ++i)
        if (values[i] && (best == values.size() || *values[i] < *values[best])) best = i;
      page.Frame(subpage, {0.4, n + 0.6}, {0.0, top}, "", "SSE_ave ((°/h)²)", title, "bc", "bcnstv");
      const double w = 0.6;
      for (size_t i = 0; i < values.size(); ++i) {
        const double centre = static_cast<double>(i) + 1.0;
        const double at = (centre - 0.4) / (n + 0.2);  // fraction of the frame's width
        pls.col0(plot::kBlack);
        pls.schr(0.0, 0.8);
        pls.mtex("b", 1.5, at, 0.5, fmt::format("{}{}", scores[i].combination.name, i == best ? " (best)" : "").c_str());
        pls.mtex("b", 3.0, at, 0.5,
                 fmt::format("({}, {})", scores[i].combination.pair[0], scores[i].combination.pair[1]).c_str());
        if (!values[i]) continue;
        PLFLT bx[4] = {centre - w / 2, centre - w / 2, centre + w / 2, centre + w / 2};
        PLFLT by[4] = {0.0, *values[i], *values[i], 0.0};
        pls.col0(colour);
        pls.fill(4, bx, by);
        pls.col0(plot::kBlack);
        pls.schr(0.0, 0.65);
        pls.ptex(centre, *values[i] + 0.015 * top, 0.0, 0.0, 0.5, fmt::format("{:.4g}", *values[i]).c_str());
      }
    };
    std::vector<std::optional<double>> ours, theirs;
    for (const auto& s : scores) {
      ours.emplace_back(s.sse_ave);
      const auto it = paper.find(s.combination.name);
      theirs.push_back(it == paper.end() ? std::nullopt : std::optional<double>(it->second));
    }
    panel(1,
          fmt::format("Table 1 analogue: SSE_ave (Eq. 3) of Eq. (2) per sensor pair{}",
                      average_s > 0 ? fmt::format(", {:g} s means", average_s) : ""),
          plot::kBlue, ours);
    if (with_paper) panel(2, "the paper's Table 1 (Guo 2006), its own scale: compare the ranking", plot::kGrey, theirs);
  }
  Check(path, name);
}

void FigureDirectory::WritePareto(const std::vector<PlanPoint>& points, double target_dph, const std::string& title) {
  plot::Range rx, ry;
  rx.Add(0.0);
  ry.Add(target_dph);
  for (const auto& p : points) {
    rx.Add(p.chamber_h);
    ry.Add(p.p95);
    if (p.lo > 0.0) ry.Add(p.lo);
    if (std::isfinite(p.hi)) ry.Add(p.hi);
  }
  plot::Range ly;
  ly.Add(std::log10(ry.lo));
  ly.Add(std::log10(ry.hi));
  const std::pair<double, double> y = {ly.lo - 0.15, ly.hi + 0.15};
  const std::pair<double, double> x = {0.0, rx.hi * 1.08 + 1.0};
  std::string name;
  const std::string path = Stage("pareto", name);
  {
    // Points are numbered in the plan's order and named in a key under the axis: names beside
    // points that share hours (three soaks of 1 h, five of 2 h ...) would overwrite each other.
    std::vector<std::string> key(1);
    for (size_t i = 0; i < points.size(); ++i) {
      const std::string entry = fmt::format("{} {}", i + 1, points[i].name);
      if (!key.back().empty() && key.back().size() + entry.size() + 3 > 95) key.emplace_back();
      key.back() += (key.back().empty() ? "" : "   ") + entry;
    }
    plot::Page page(path, 1300, 1000, 1, 1);
    plstream& pls = page.pls();
    page.ReserveBelow(static_cast<int>(key.size()) + 1);
    page.Frame(1, x, y, "chamber hours (settling + runs)", "p95 |bias after| over gyros (°/h)", title, "bcnst", "bcstv");
    LogAxisLabels(pls, "l", y);
    const bool any = std::any_of(points.begin(), points.end(), [](const PlanPoint& p) { return p.recommended; });
    page.Legend({{plot::kBlue, "candidate, 90 % interval"},
                 {plot::kGreen, "Pareto front"},
                 {plot::kRed, fmt::format("target {:g} °/h", target_dph)},
                 {plot::kOrange, any ? "recommended" : "recommended: none"}});
    page.Curve(plot::kRed, {x.first, x.second}, {std::log10(target_dph), std::log10(target_dph)}, 2);
    std::vector<const PlanPoint*> front;
    for (const auto& p : points)
      if (p.pareto) front.push_back(&p);
    std::sort(front.begin(), front.end(), [](const PlanPoint* a, const PlanPoint* b) { return a->chamber_h < b->chamber_h; });
    std::vector<double> fx, fy;
    for (const auto* p : front) {  // a staircase: the best p95 that so many hours buy
      if (!fx.empty()) {
        fx.push_back(p->chamber_h);
        fy.push_back(fy.back());
      }
      fx.push_back(p->chamber_h);
      fy.push_back(std::log10(p->p95));
    }
    if (!fx.empty()) {
      fx.push_back(x.second);
      fy.push_back(fy.back());
      page.Curve(plot::kGreen, fx, fy);
    }
    const auto [mm_x, mm_y] = page.WorldPerMm();
    for (const auto& p : points) {
      const double top = std::isfinite(p.hi) ? std::log10(p.hi) : y.second;
      const double bottom = p.lo > 0.0 ? std::log10(p.lo) : y.first;
      page.Curve(plot::kBlue, {p.chamber_h, p.chamber_h}, {bottom, top});
      page.Curve(plot::kBlue, {p.chamber_h - 0.8 * mm_x, p.chamber_h + 0.8 * mm_x}, {bottom, bottom});
      if (std::isfinite(p.hi)) page.Curve(plot::kBlue, {p.chamber_h - 0.8 * mm_x, p.chamber_h + 0.8 * mm_x}, {top, top});
    }
    std::vector<double> px, py;
    for (const auto& p : points) {
      px.push_back(p.chamber_h);
      py.push_back(std::log10(p.p95));
    }
    page.Dots(plot::kBlue, px, py, true);
    for (const auto& p : points) {
      if (!p.recommended) continue;
      std::vector<double> cx, cy;
      for (int k = 0; k <= 40; ++k) {
        const double a = 2.0 * M_PI * k / 40.0;
        cx.push_back(p.chamber_h + 2.5 * mm_x * std::cos(a));
        cy.push_back(std::log10(p.p95) + 2.5 * mm_y * std::sin(a));
      }
      page.Curve(plot::kOrange, cx, cy);
    }
    pls.col0(plot::kBlack);
    pls.schr(0.0, 0.7);
    for (size_t i = 0; i < points.size(); ++i) {
      // Alternately right and left of the point, so that neighbours at the same hours stay apart.
      const bool right = i % 2 == 0;
      pls.ptex(points[i].chamber_h + (right ? 1.2 : -1.2) * mm_x, std::log10(points[i].p95) - 0.8 * mm_y, 1.0, 0.0,
               right ? 0.0 : 1.0, fmt::format("{}", i + 1).c_str());
    }
    for (size_t l = 0; l < key.size(); ++l) page.Below(static_cast<int>(l), plot::kBlack, key[l]);
  }
  Check(path, name);
}

void FigureDirectory::WriteResidualVsTemperature(const std::string& label, const std::string& title,
                                                 const std::string& channel, const std::vector<double>& T,
                                                 const std::vector<double>& residual) {
  plot::Range rx, ry;
  rx.Add(T);
  ry.Add(residual);
  ry.Add(0.0);
  // Means over 40 equal temperature bins (bins with samples only), to show a trend the dots hide.
  const int bins = 40;
  std::vector<double> sum(bins, 0.0), count(bins, 0.0), bx, by;
  const double lo = rx.lo, width = rx.hi > rx.lo ? (rx.hi - rx.lo) / bins : 1.0;
  for (size_t i = 0; i < T.size() && i < residual.size(); ++i) {
    if (!std::isfinite(T[i]) || !std::isfinite(residual[i])) continue;
    const int b = std::clamp(static_cast<int>((T[i] - lo) / width), 0, bins - 1);
    sum[static_cast<size_t>(b)] += residual[i];
    count[static_cast<size_t>(b)] += 1.0;
  }
  for (int b = 0; b < bins; ++b) {
    if (count[static_cast<size_t>(b)] == 0.0) continue;
    bx.push_back(lo + (b + 0.5) * width);
    by.push_back(sum[static_cast<size_t>(b)] / count[static_cast<size_t>(b)]);
  }
  std::string name;
  const std::string path = Stage("heldout_" + plot::FileNamePart(label), name);
  {
    plot::Page page(path, 1200, 800, 1, 1);
    page.pls().syax(5, 0);
    page.Frame(1, rx.Padded(), ry.Padded(), fmt::format("{} (°C)", channel), "compensated bias (°/h)", title);
    page.Legend({{plot::kGrey, "held-out samples"}, {plot::kBlue, fmt::format("means over 1/{} of the range", bins)}});
    const auto x = rx.Padded();
    page.Curve(plot::kBlack, {x.first, x.second}, {0.0, 0.0}, 2);
    page.Dots(plot::kGrey, T, residual, T.size() < 300);
    page.Curve(plot::kBlue, bx, by);
    page.Dots(plot::kBlue, bx, by, true);
  }
  Check(path, name);
}

}  // namespace rlg::cli

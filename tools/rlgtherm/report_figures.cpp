#include "tools/rlgtherm/report_figures.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <iterator>
#include <limits>
#include <plplot/plstream.h>
#include <sys/resource.h>
#include <sys/statvfs.h>

#include "sim/errors.h"

namespace rlg::cli {
namespace {

// Colour map 0 entries used below.
enum Colour { kWhite = 0, kBlack = 1, kRed = 2, kBlue = 3, kGrey = 4 };

/// True when this PLplot build can write PNG through cairo. Asked before plinit, which
/// would otherwise prompt on stdin for a device.
bool HasPngCairo() {
  int n = 128;
  std::vector<const char*> menu(static_cast<size_t>(n)), names(static_cast<size_t>(n));
  const char** m = menu.data();
  const char** d = names.data();
  plgDevs(&m, &d, &n);
  for (int i = 0; i < n; ++i)
    if (std::string(d[i]) == "pngcairo") return true;
  return false;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(const std::vector<double>& v) {
    for (double x : v)
      if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  /// Padded by 5 % (and opened up when flat or empty) so that no curve sits on the frame.
  std::pair<double, double> Padded() const {
    if (!(hi >= lo)) return {-1.0, 1.0};
    const double pad = hi > lo ? 0.05 * (hi - lo) : std::max(1e-6, 0.05 * std::abs(hi));
    return {lo - pad, hi + pad};
  }
};

/// The reason a file the PNG writer left incomplete most likely has: PLplot and cairo report
/// no write error, so look at what stops writes (a full file system, the file size limit).
std::string LikelyWriteFailure(const std::string& path, std::uintmax_t size) {
  struct statvfs fs {};
  if (::statvfs(path.c_str(), &fs) == 0 && fs.f_bavail == 0) return std::strerror(ENOSPC);
  struct rlimit limit {};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY && size >= limit.rlim_cur) {
    return std::strerror(EFBIG);
  }
  return "the PNG writer stopped without saying why";
}

/// OutputError unless `path` is a whole PNG: its signature, and the IEND chunk (length 0,
/// type, CRC) as the last 12 bytes. A PNG cut short by a full disk lacks the end.
void CheckPngComplete(const std::string& path, const std::string& shown) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static const unsigned char kIend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const bool whole = bytes.size() >= 20 && std::memcmp(bytes.data(), kSignature, 8) == 0 &&
                     std::memcmp(bytes.data() + bytes.size() - 12, kIend, 12) == 0;
  if (!whole) {
    throw OutputError(fmt::format("{}: drawing the figure failed ({} bytes, not a whole PNG): {} (no report written)", shown,
                                  bytes.size(), LikelyWriteFailure(path, bytes.size())));
  }
}

/// One panel: frame and labels in black, then the caller draws.
void Frame(plstream& pls, int subpage, std::pair<double, double> x, std::pair<double, double> y, const std::string& xlabel,
           const std::string& ylabel, const std::string& title) {
  pls.adv(subpage);
  pls.col0(kBlack);
  pls.schr(0.0, 0.8);
  pls.vsta();
  pls.wind(x.first, x.second, y.first, y.second);
  pls.box("bcnst", 0.0, 0, "bcnstv", 0.0, 0);
  pls.lab(xlabel.c_str(), ylabel.c_str(), "");
  pls.mtex("t", 2.6, 0.0, 0.0, title.c_str());
}

void Legend(plstream& pls, bool measured, bool extended) {
  pls.schr(0.0, 0.7);
  double at = 0.0;
  if (measured) {
    pls.col0(kBlack);
    pls.mtex("t", 1.0, at, 0.0, "measured");
    at += 0.2;
  }
  pls.col0(kRed);
  pls.mtex("t", 1.0, at, 0.0, "calibrated nominal");
  if (extended) {
    pls.col0(kBlue);
    pls.mtex("t", 1.0, at + 0.35, 0.0, "extended (accepted effects)");
  }
  pls.schr(0.0, 0.8);
}

void Curve(plstream& pls, Colour c, const std::vector<double>& x, const std::vector<double>& y) {
  pls.col0(c);
  pls.line(static_cast<PLINT>(std::min(x.size(), y.size())), x.data(), y.data());
}

/// Scatter: single dots for dense clouds, small filled circles (Hershey code 17) when the
/// points are few enough to be seen one by one.
void Dots(plstream& pls, Colour c, const std::vector<double>& x, const std::vector<double>& y, bool sparse) {
  pls.col0(c);
  pls.ssym(0.0, 0.6);
  pls.poin(static_cast<PLINT>(std::min(x.size(), y.size())), x.data(), y.data(), sparse ? 17 : 1);
}

void WriteChannelFigure(const std::string& path, const model::ChannelFigure& f, bool extended, double score_block_s) {
  const std::string& ch = f.channel;
  const std::string& temperature = f.temperature;
  const bool bias = ch == "bias_dph";
  const std::string unit = bias ? "°/h" : "°C";
  // Runs end to end on one time axis (h), with a small gap between them.
  std::vector<std::vector<double>> hours, measured, sim_base, sim_ext, res_hours, res_base, res_ext, temp, rate;
  std::vector<std::pair<double, std::string>> starts;
  double offset = 0.0;
  for (const auto& run : f.runs) {
    const size_t n = run.t_s.size();
    std::vector<double> h(n);
    for (size_t i = 0; i < n; ++i) h[i] = offset + (run.t_s[i] - run.t_s.front()) / 3600.0;
    starts.emplace_back(offset, run.run);
    offset = h.back() + 0.02 * (h.back() - offset) + 1e-3;
    hours.push_back(h);
    measured.push_back(run.measured);
    sim_base.push_back(run.simulated_baseline);
    sim_ext.push_back(run.simulated_extended);
    res_hours.push_back(model::GroupMeans(h, run.blocks_per_score_block));
    res_base.push_back(run.residual_baseline);
    res_ext.push_back(run.residual_extended);
    temp.push_back(run.temperature_C);
    rate.push_back(run.rate_C_per_min);
  }
  if (hours.empty()) return;
  Range rx, ry, rr, rt, rdt;
  for (size_t k = 0; k < hours.size(); ++k) {
    rx.Add(hours[k]);
    ry.Add(measured[k]);
    ry.Add(sim_base[k]);
    rr.Add(res_base[k]);
    rt.Add(temp[k]);
    rdt.Add(rate[k]);
    if (extended) ry.Add(sim_ext[k]), rr.Add(res_ext[k]);
  }
  const auto x = rx.Padded(), y = ry.Padded(), r = rr.Padded();
  size_t points = 0;
  for (const auto& v : res_base) points += v.size();
  const bool sparse = points < 1000;

  plstream pls;
  pls.sdev("pngcairo");
  pls.sfnam(path.c_str());
  pls.spage(0.0, 0.0, 1400, 900, 0, 0);
  pls.scol0(kWhite, 255, 255, 255);
  pls.scol0(kBlack, 0, 0, 0);
  pls.scol0(kRed, 214, 39, 40);
  pls.scol0(kBlue, 31, 119, 180);
  pls.scol0(kGrey, 150, 150, 150);
  pls.ssub(2, 2);
  pls.init();

  auto run_separators = [&](std::pair<double, double> yr) {
    pls.col0(kGrey);
    pls.schr(0.0, 0.55);
    for (size_t i = 0; i < starts.size(); ++i) {
      const auto& [t0, id] = starts[i];
      pls.lsty(2);
      pls.join(t0, yr.first, t0, yr.second);
      pls.lsty(1);
      // Labels on two alternating rows, so that long run ids of short runs do not overlap.
      const double row = (i % 2 == 0 ? 0.04 : 0.09) * (yr.second - yr.first);
      pls.ptex(t0 + 0.005 * (x.second - x.first), yr.second - row, 1.0, 0.0, 0.0, id.c_str());
    }
    pls.schr(0.0, 0.8);
  };

  Frame(pls, 1, x, y, "time, runs end to end (h)", fmt::format("{} ({})", ch, unit),
        fmt::format("{}: data and model (fit-block means)", ch));
  Legend(pls, true, extended);
  run_separators(y);
  for (size_t k = 0; k < hours.size(); ++k) {
    Curve(pls, kBlack, hours[k], measured[k]);
    Curve(pls, kRed, hours[k], sim_base[k]);
    if (extended) Curve(pls, kBlue, hours[k], sim_ext[k]);
  }

  Frame(pls, 2, x, r, "time, runs end to end (h)", fmt::format("residual ({})", unit),
        fmt::format("{}: measured - simulated, {:.3g} s means{}", ch, score_block_s, bias ? ", held out" : ""));
  Legend(pls, false, extended);
  run_separators(r);
  for (size_t k = 0; k < hours.size(); ++k) {
    Curve(pls, kRed, res_hours[k], res_base[k]);
    if (extended) Curve(pls, kBlue, res_hours[k], res_ext[k]);
  }
  pls.col0(kGrey);
  pls.join(x.first, 0.0, x.second, 0.0);

  Frame(pls, 3, rt.Padded(), r, fmt::format("{} (°C)", temperature), fmt::format("residual ({})", unit),
        fmt::format("{} residual against temperature", ch));
  Legend(pls, false, extended);
  for (size_t k = 0; k < hours.size(); ++k) {
    Dots(pls, kRed, temp[k], res_base[k], sparse);
    if (extended) Dots(pls, kBlue, temp[k], res_ext[k], sparse);
  }

  Frame(pls, 4, rdt.Padded(), r, fmt::format("d{}/dt (°C/min)", temperature), fmt::format("residual ({})", unit),
        fmt::format("{} residual against the rate of {}", ch, temperature));
  Legend(pls, false, extended);
  for (size_t k = 0; k < hours.size(); ++k) {
    Dots(pls, kRed, rate[k], res_base[k], sparse);
    if (extended) Dots(pls, kBlue, rate[k], res_ext[k], sparse);
  }
}  // ~plstream ends the stream and closes the file

}  // namespace

void WriteDiagnosisFigures(sim::OutputDirectory& report, const model::DiagnosisFigures& figures) {
  if (!HasPngCairo()) {
    throw InputError("diagnose --report: PLplot has no 'pngcairo' device for the figures; install the Debian package "
                          "plplot-driver-cairo (tools/setup.sh does)");
  }
  for (const auto& figure : figures.channels) {
    const std::string name = "fit_" + figure.channel + ".png";
    const std::string path = report.Stage(name);
    WriteChannelFigure(path, figure, figures.extended, figures.score_block_s);
    if (!std::filesystem::exists(path)) continue;  // no run has this channel; Commit skips it
    CheckPngComplete(path, report.dir() + "/" + name);
  }
}

}  // namespace rlg::cli

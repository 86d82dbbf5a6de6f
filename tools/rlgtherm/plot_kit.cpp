#include "tools/rlgtherm/plot_kit.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <iterator>
#include <plplot/plstream.h>
#include <sys/resource.h>
#include <sys/statvfs.h>

#include "sim/errors.h"

namespace rlg::cli::plot {
namespace {

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

/// Bytes of the UTF-8 character starting at s[i].
size_t CharBytes(const std::string& s, size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  const size_t n = c < 0x80 ? 1 : c < 0xe0 ? 2 : c < 0xf0 ? 3 : 4;
  return std::min(n, s.size() - i);
}

}  // namespace

void RequirePngCairo(const std::string& option) {
  if (!HasPngCairo()) {
    throw InputError(fmt::format("{}: PLplot has no 'pngcairo' device for the figures; install the Debian package "
                                 "plplot-driver-cairo (tools/setup.sh does)",
                                 option));
  }
}

void Range::Add(double x) {
  if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
}

void Range::Add(const std::vector<double>& v) {
  for (double x : v) Add(x);
}

std::pair<double, double> Range::Padded() const {
  if (!(hi >= lo)) return {-1.0, 1.0};
  const double pad = hi > lo ? 0.05 * (hi - lo) : std::max(1e-6, 0.05 * std::abs(hi));
  return {lo - pad, hi + pad};
}

std::string FileNamePart(const std::string& id) {
  std::string out = id;
  for (char& c : out) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '+' || c == '-';
    if (!keep) c = '_';
  }
  if (out.empty() || out.front() == '.') out.insert(out.begin(), '_');  // never hidden, never "." or ".."
  return out;
}

Page::Page(const std::string& path, int width_px, int height_px, int nx, int ny)
    : pls_(std::make_unique<plstream>()), nx_(nx), ny_(ny) {
  plstream& pls = *pls_;
  pls.sdev("pngcairo");
  pls.sfnam(path.c_str());
  pls.spage(0.0, 0.0, width_px, height_px, 0, 0);
  pls.scol0(kWhite, 255, 255, 255);
  pls.scol0(kBlack, 0, 0, 0);
  pls.scol0(kRed, 214, 39, 40);
  pls.scol0(kBlue, 31, 119, 180);
  pls.scol0(kGrey, 150, 150, 150);
  pls.scol0(kGreen, 44, 160, 44);
  pls.scol0(kOrange, 255, 127, 14);
  pls.scol0(kPurple, 148, 103, 189);
  pls.ssub(nx, ny);
  pls.init();
}

Page::~Page() = default;  // ~plstream ends the stream and closes the file

void Page::Frame(int subpage, std::pair<double, double> x, std::pair<double, double> y, const std::string& xlabel,
                 const std::string& ylabel, const std::string& title, const char* xopt, const char* yopt) {
  plstream& pls = *pls_;
  pls.adv(subpage);
  pls.col0(kBlack);
  pls.lsty(1);
  pls.schr(0.0, 0.8);
  pls.vsta();
  if (below_lines_ > 0) {  // raise the frame's bottom by the lines kept free (Below: 0.75 scale, 1.6 apart)
    PLFLT vx0, vx1, vy0, vy1, sx0, sx1, sy0, sy1, default_mm, height_mm;
    pls.gvpd(vx0, vx1, vy0, vy1);
    pls.gspa(sx0, sx1, sy0, sy1);
    pls.gchr(default_mm, height_mm);
    // One Below line in page fractions; gchr gives the height at the current 0.8 scale.
    const double line = 1.6 * (0.75 / 0.8) * height_mm / ((sy1 - sy0) * ny_);
    // plgvpd gives page fractions, plvpor wants fractions of the subpage (one of nx x ny).
    pls.vpor(vx0 * nx_ - std::floor(vx0 * nx_), vx1 * nx_ - std::floor(vx0 * nx_),
             (vy0 + below_lines_ * line) * ny_ - std::floor(vy0 * ny_), vy1 * ny_ - std::floor(vy0 * ny_));
  }
  pls.wind(x.first, x.second, y.first, y.second);
  pls.box(xopt, 0.0, 0, yopt, 0.0, 0);
  if (std::strchr(yopt, 'l') != nullptr && std::strchr(yopt, 'n') == nullptr) {
    // A log axis labelled by the caller in plain numbers ("0.005"): wider than PLplot's own
    // labels, so the axis title goes further out than plot's 5 character heights.
    pls.lab(xlabel.c_str(), "", "");
    pls.mtex("l", 6.2, 0.5, 0.5, ylabel.c_str());
  } else {
    pls.lab(xlabel.c_str(), ylabel.c_str(), "");
  }
  pls.mtex("t", 2.6, 0.0, 0.0, title.c_str());
  x_ = x;
  y_ = y;
}

void Page::Below(int line, Colour c, const std::string& text) {
  pls_->col0(c);
  pls_->schr(0.0, 0.75);
  // Under the x-axis label (3.2 lines of the 0.8 scale down, ~4.3 of this 0.75 scale to its foot).
  pls_->mtex("b", 5.6 + 1.6 * line, 0.0, 0.0, text.c_str());
  pls_->schr(0.0, 0.8);
}

void Page::Curve(Colour c, const std::vector<double>& x, const std::vector<double>& y, int style) {
  pls_->col0(c);
  pls_->lsty(style);
  pls_->line(static_cast<PLINT>(std::min(x.size(), y.size())), x.data(), y.data());
  pls_->lsty(1);
}

void Page::Dots(Colour c, const std::vector<double>& x, const std::vector<double>& y, bool sparse) {
  pls_->col0(c);
  pls_->ssym(0.0, 0.6);
  pls_->poin(static_cast<PLINT>(std::min(x.size(), y.size())), x.data(), y.data(), sparse ? 17 : 1);
}

std::pair<double, double> Page::WorldPerMm() {
  // The subpage's size in mm (plgspa) and the viewport's share of it: the viewport's
  // normalized device coordinates (plgvpd, fractions of the page) over the subpage's (1/nx).
  PLFLT sx0, sx1, sy0, sy1, vx0, vx1, vy0, vy1;
  pls_->gspa(sx0, sx1, sy0, sy1);
  pls_->gvpd(vx0, vx1, vy0, vy1);
  const double vp_w_mm = (vx1 - vx0) * nx_ * (sx1 - sx0);
  const double vp_h_mm = (vy1 - vy0) * ny_ * (sy1 - sy0);
  return {(x_.second - x_.first) / vp_w_mm, (y_.second - y_.first) / vp_h_mm};
}

double Page::TextWidth(const std::string& text) {
  // PLplot 5.15 does not measure strings (no plstrl): an advance per character in units of the
  // character height plgchr reports, for cairo's sans font. Measured on TCLab's run ids in
  // fit_T1.png (lower case, digits, '_'): 0.79; 0.82 leaves a margin, and capitals, m and w,
  // the widest glyphs, get 1.0.
  double advance = 0.0;
  for (size_t i = 0; i < text.size(); i += CharBytes(text, i)) {
    const char c = text[i];
    advance += std::isupper(static_cast<unsigned char>(c)) || c == 'm' || c == 'w' ? 1.0 : 0.82;
  }
  PLFLT default_mm, height_mm;
  pls_->gchr(default_mm, height_mm);
  return advance * height_mm * WorldPerMm().first;
}

void Page::Legend(const std::vector<std::pair<Colour, std::string>>& entries) {
  plstream& pls = *pls_;
  pls.schr(0.0, 0.7);
  const double span = x_.second - x_.first;
  double at = 0.0;  // fraction of the viewport width
  for (const auto& [colour, text] : entries) {
    pls.col0(colour);
    pls.mtex("t", 1.0, at, 0.0, text.c_str());
    at += (TextWidth(text) + TextWidth("    ")) / span;
  }
  pls.schr(0.0, 0.8);
}

std::string Ellipsize(const std::string& text, double room, const std::function<double(const std::string&)>& width) {
  if (width(text) <= room) return text;
  std::vector<size_t> ends;  // byte offsets after each whole character
  for (size_t i = 0; i < text.size(); i += CharBytes(text, i)) ends.push_back(i + CharBytes(text, i));
  // Longest prefix that fits with the ellipsis (widths grow with the prefix: bisect).
  size_t lo = 0, hi = ends.size();  // prefixes of lo characters fit; of hi do not
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (width(text.substr(0, ends[mid - 1]) + "…") <= room) lo = mid;
    else hi = mid;
  }
  return lo == 0 ? std::string() : text.substr(0, ends[lo - 1]) + "…";
}

void Page::RunSeparators(const std::vector<std::pair<double, std::string>>& starts) {
  plstream& pls = *pls_;
  pls.col0(kGrey);
  pls.schr(0.0, 0.55);
  const double pad = 0.005 * (x_.second - x_.first);  // between a separator and its label
  const double gap = 2.0 * pad;                       // between two labels of one row
  const auto width = [&](const std::string& s) { return TextWidth(s); };
  // Round-robin on k rows: id i may use the room up to id i + k (or the frame's right end).
  auto room = [&](size_t i, size_t k) {
    const double end = i + k < starts.size() ? starts[i + k].first - gap : x_.second - pad;
    return end - starts[i].first - pad;
  };
  constexpr size_t kMaxRows = 3;
  size_t rows = kMaxRows;
  for (size_t k = 1; k <= kMaxRows; ++k) {
    bool whole = true;
    for (size_t i = 0; i < starts.size() && whole; ++i) whole = width(starts[i].second) <= room(i, k);
    if (whole) {
      rows = k;
      break;
    }
  }
  PLFLT default_mm, height_mm;
  pls.gchr(default_mm, height_mm);
  const double row_height = 1.6 * height_mm * WorldPerMm().second;  // a line and its leading
  for (size_t i = 0; i < starts.size(); ++i) {
    const auto& [t0, id] = starts[i];
    pls.lsty(2);
    pls.join(t0, y_.first, t0, y_.second);
    pls.lsty(1);
    const std::string shown = Ellipsize(id, room(i, rows), width);
    const double y = y_.second - (static_cast<double>(i % rows) + 1.0) * row_height;
    if (!shown.empty()) pls.ptex(t0 + pad, y, 1.0, 0.0, 0.0, shown.c_str());
  }
  pls.schr(0.0, 0.8);
}

void CheckPngComplete(const std::string& path, const std::string& shown, const std::string& nothing) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static const unsigned char kIend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const bool whole = bytes.size() >= 20 && std::memcmp(bytes.data(), kSignature, 8) == 0 &&
                     std::memcmp(bytes.data() + bytes.size() - 12, kIend, 12) == 0;
  if (!whole) {
    throw OutputError(fmt::format("{}: drawing the figure failed ({} bytes, not a whole PNG): {}{}", shown, bytes.size(),
                                  LikelyWriteFailure(path, bytes.size()), nothing));
  }
}

}  // namespace rlg::cli::plot

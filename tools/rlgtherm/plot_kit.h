#pragma once
// What every PNG figure of the CLI shares (diagnose --report, --plot of compensate, evaluate,
// validate and allan): the pngcairo check, one page of panels, padded ranges, frames, curves,
// run labels that never overlap, and the check that PLplot wrote a whole PNG.

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io/atomic_output.h"

class plstream;

namespace rlg::cli::plot {

// Colour map 0 entries of every figure.
enum Colour { kWhite = 0, kBlack = 1, kRed = 2, kBlue = 3, kGrey = 4, kGreen = 5, kOrange = 6, kPurple = 7 };

/// InputError naming `option` unless PLplot can write PNG through cairo (Debian package
/// plplot-driver-cairo). Asked before plinit, which would otherwise prompt on stdin for a device.
void RequirePngCairo(const std::string& option);

/// The finite range of some values, padded by 5 % (and opened up when flat or empty) so that
/// no curve sits on the frame.
struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double x);
  void Add(const std::vector<double>& v);
  std::pair<double, double> Padded() const;
};

/// A file name for a run id: characters other than letters, digits and ._+- become '_'.
std::string FileNamePart(const std::string& id);

/// One PNG page of nx x ny panels on the pngcairo device, drawn into `path` (a staged file of
/// an OutputDirectory). The file is complete when the Page is destroyed; then CheckPngComplete.
class Page {
 public:
  Page(const std::string& path, int width_px, int height_px, int nx, int ny);
  ~Page();
  Page(const Page&) = delete;
  Page& operator=(const Page&) = delete;
  plstream& pls() { return *pls_; }

  /// Starts panel `subpage` (1-based): frame, ticks and axis labels in black, the title above.
  /// `xopt`/`yopt` are PLplot box options ("bcnst"; add "l" for a log10 axis).
  void Frame(int subpage, std::pair<double, double> x, std::pair<double, double> y, const std::string& xlabel,
             const std::string& ylabel, const std::string& title, const char* xopt = "bcnst",
             const char* yopt = "bcnstv");
  /// Lines of text to keep free below the following panels' x-axis labels (Below writes them).
  void ReserveBelow(int lines) { below_lines_ = lines; }
  /// Text line `line` (0 = first) of the room ReserveBelow kept under the current panel.
  void Below(int line, Colour c, const std::string& text);
  void Curve(Colour c, const std::vector<double>& x, const std::vector<double>& y, int style = 1);
  /// Scatter: single dots for dense clouds, small filled circles when the points are few enough
  /// to be seen one by one.
  void Dots(Colour c, const std::vector<double>& x, const std::vector<double>& y, bool sparse);
  /// A legend line above the current panel: entries in their colours, left to right, spaced by
  /// their widths so that none overlaps the next.
  void Legend(const std::vector<std::pair<Colour, std::string>>& entries);
  /// Dashed separators at the run starts (world x, ascending) of the current panel, and the
  /// run ids beside them near the top: on as few rows (up to three) as keep every id whole and
  /// apart, else each id shortened with an ellipsis to the room before the next id of its row.
  void RunSeparators(const std::vector<std::pair<double, std::string>>& starts);
  /// World units per mm of the current panel's viewport, along x and y.
  std::pair<double, double> WorldPerMm();
  /// Width of `text` in world x units at the current character size.
  double TextWidth(const std::string& text);

 private:
  std::unique_ptr<plstream> pls_;
  int nx_, ny_;
  std::pair<double, double> x_{0.0, 1.0}, y_{0.0, 1.0};  ///< the current panel's world window
  int below_lines_ = 0;
};

/// `text` shortened (whole UTF-8 characters, then "…") so that `width(text)` <= room; "" when
/// not even one character and the ellipsis fit.
std::string Ellipsize(const std::string& text, double room, const std::function<double(const std::string&)>& width);

/// OutputError unless `path` is a whole PNG: its signature, and the IEND chunk as the last 12
/// bytes (a PNG cut short by a full disk lacks the end). `shown` names the file in the message,
/// `nothing` says what the failure leaves (OutputDirectory::NothingWritten).
void CheckPngComplete(const std::string& path, const std::string& shown, const std::string& nothing);

}  // namespace rlg::cli::plot

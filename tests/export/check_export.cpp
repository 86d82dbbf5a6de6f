// check_export COEFFS DATA VALUES MAX_DIFF MAX_TABLE2 FLAG_MARGIN [COMPENSATED_CSV]: compares
// what an exported compensator printed for every row of DATA (harness.c: "value,outside_range"
// per row) with the library's own compensation of the same rows, unrounded
// (compensation::CompensateRun), and the Table 2 numbers of each run (bias after, stability at
// 1 s and at 100 s after: EvaluateCompensated) computed from the C values with those computed
// from the library's. Prints the largest differences; exits 1 when a value differs by more than
// MAX_DIFF (°/h), a Table 2 number by more than MAX_TABLE2 (°/h), the flag disagrees with the
// library's (Eq. (2): Ti0 outside T10_range_C; polynomials: ModelCompensator::OutsideFittedRange
// after the sample, which a product's factors set too), or the row count differs; 2 on bad
// usage. FLAG_MARGIN (0: none) excuses a flag that disagrees where the library itself flags the
// sample differently with every range grown by the margin than with every range shrunk by it: a
// signal within the margin of an edge (in the signal's unit, °C or °C/min), which float's
// rounding may put on the other side. With COMPENSATED_CSV (`rlgtherm compensate DATA -o`), also
// when a value differs from its bias_comp_dph by more than that column's rounding (half of 1e-6
// °/h) plus MAX_DIFF.

#include <array>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

#include "compensation/evaluation.h"
#include "compensation/model_compensator.h"
#include "io/csv.h"
#include "model/coefficients_json.h"

namespace {

/// The library's outside-the-fitted-range flag after each sample of `run`: Eq. (2)'s, Ti0 outside
/// T10_range_C; a polynomial's, its compensator's after the sample (the channel, and a product's
/// factors, outside their ranges).
std::vector<bool> LibraryFlags(const rlg::model::FittedModel& m, const rlg::sim::Run& run) {
  using namespace rlg;
  std::vector<bool> out(run.size());
  if (const auto* eq2 = std::get_if<model::Guo2006Coefficients>(&m)) {
    const double Ti0 = run.Column(eq2->pair[0]).front();
    out.assign(run.size(), Ti0 < eq2->t10_range_C[0] || Ti0 > eq2->t10_range_C[1]);
    return out;
  }
  compensation::ModelCompensator comp(m);
  std::vector<const std::vector<double>*> columns;
  for (const auto& ch : comp.channels()) columns.push_back(&run.Column(ch));
  const auto& b = run.Column("bias_dph");
  std::vector<double> T(columns.size());
  for (size_t k = 0; k < run.size(); ++k) {
    for (size_t c = 0; c < columns.size(); ++c) T[c] = (*columns[c])[k];
    comp.Update(run.t_s[k], T.data(), b[k]);
    out[k] = comp.OutsideFittedRange();
  }
  return out;
}

/// `m` with every fitted range grown by `margin` at both ends (shrunk for a negative margin).
rlg::model::FittedModel RangesGrown(rlg::model::FittedModel m, double margin) {
  auto grow = [margin](std::array<double, 2>& range) {
    range[0] -= margin;
    range[1] += margin;
  };
  if (auto* eq2 = std::get_if<rlg::model::Guo2006Coefficients>(&m)) {
    grow(eq2->t10_range_C);
  } else {
    auto& spec = std::get<rlg::model::PolyModel>(m).spec;
    grow(spec.range_C);
    for (auto& t : spec.terms)
      for (auto& f : t.factors) grow(f.range);
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace rlg;
  if (argc != 7 && argc != 8) {
    fmt::print(stderr, "usage: check_export COEFFS DATA VALUES MAX_DIFF MAX_TABLE2 FLAG_MARGIN [COMPENSATED_CSV]\n");
    return 2;
  }
  const model::FittedModel m = model::ReadModelFile(argv[1]);
  const sim::Trace trace = io::ReadTraceCsv(argv[2]).trace;
  const double max_diff = std::stod(argv[4]), max_table2 = std::stod(argv[5]), margin = std::stod(argv[6]);
  const model::FittedModel grown = RangesGrown(m, margin), shrunk = RangesGrown(m, -margin);
  std::ifstream values(argv[3]);
  std::vector<double> c_values;
  std::vector<int> c_flags;
  for (std::string line; std::getline(values, line);) {
    const auto comma = line.find(',');
    c_values.push_back(std::stod(line.substr(0, comma)));
    c_flags.push_back(std::stoi(line.substr(comma + 1)));
  }
  size_t rows = 0;
  for (const auto& run : trace.runs) rows += run.size();
  if (rows != c_values.size()) {
    fmt::print("the C harness printed {} rows for {} rows of data\n", c_values.size(), rows);
    return 1;
  }
  double worst = 0.0, worst_bias = 0.0, worst_stab = 0.0, worst_stab100 = 0.0;
  std::string worst_where;
  size_t at = 0, flag_mismatches = 0, near_edge = 0, flagged = 0;
  for (const auto& run : trace.runs) {
    const std::vector<double> lib = compensation::CompensateRun(m, run);
    std::vector<double> c(c_values.begin() + static_cast<long>(at), c_values.begin() + static_cast<long>(at + run.size()));
    const std::vector<bool> outside = LibraryFlags(m, run), outside_grown = LibraryFlags(grown, run),
                            outside_shrunk = LibraryFlags(shrunk, run);
    for (size_t k = 0; k < run.size(); ++k) {
      const double d = std::abs(c[k] - lib[k]);
      if (!(d <= worst)) {  // also takes a NaN
        worst = d;
        worst_where = fmt::format("run {} at t = {} s: C {:.17g}, library {:.17g}", run.id, run.t_s[k], c[k], lib[k]);
      }
      flagged += outside[k] ? 1 : 0;
      if ((c_flags[at + k] != 0) != outside[k]) {
        if (outside_grown[k] != outside_shrunk[k]) {
          ++near_edge;
        } else {
          ++flag_mismatches;
        }
      }
    }
    const auto a = compensation::EvaluateCompensated(run, lib), b = compensation::EvaluateCompensated(run, c);
    worst_bias = std::max(worst_bias, std::abs(a.bias_after_dph - b.bias_after_dph));
    worst_stab = std::max(worst_stab, std::abs(a.stability_after.sigma - b.stability_after.sigma));
    worst_stab100 = std::max(worst_stab100, std::abs(a.stability_100s_after.sigma - b.stability_100s_after.sigma));
    at += run.size();
  }
  fmt::print("{}: {} rows of {} runs; largest |C - library| {:.3g} °/h ({})\n", model::ModelTitle(m), rows,
             trace.runs.size(), worst, worst_where);
  fmt::print("Table 2 from the C values against the library's: bias after moves by at most {:.3g} °/h, stability "
             "after by {:.3g} °/h (1 s) and {:.3g} °/h (100 s)\n",
             worst_bias, worst_stab, worst_stab100);
  int status = 0;
  fmt::print("outside_range: the library flags {} rows; the C code's flag differs on {} rows{}\n", flagged,
             flag_mismatches,
             margin > 0.0 ? fmt::format(" and, excused, on {} within {:g} of a range's edge", near_edge, margin) : "");
  if (argc == 8) {
    io::CsvReadOptions keep;
    keep.keep_columns = {"bias_comp_dph"};
    const sim::Trace written = io::ReadTraceCsv(argv[7], keep).trace;
    double worst_csv = 0.0;
    size_t i = 0;
    for (const auto& run : written.runs)
      for (double v : run.Column("bias_comp_dph")) worst_csv = std::max(worst_csv, std::abs(c_values.at(i++) - v));
    fmt::print("against compensate -o (bias_comp_dph, rounded to 1e-6 °/h): largest |C - CSV| {:.3g} °/h\n", worst_csv);
    if (i != rows || !(worst_csv <= 0.5e-6 + max_diff)) {
      fmt::print("FAILED: {} rows, or beyond the column's rounding (5e-7 °/h) plus {:g} °/h\n", i, max_diff);
      status = 1;
    }
  }
  if (!(worst <= max_diff)) {
    fmt::print("FAILED: {:.3g} °/h exceeds the bound {:g} °/h\n", worst, max_diff);
    status = 1;
  }
  if (!(std::max({worst_bias, worst_stab, worst_stab100}) <= max_table2)) {
    fmt::print("FAILED: a Table 2 number moves by more than {:g} °/h\n", max_table2);
    status = 1;
  }
  if (flag_mismatches > 0) {
    fmt::print("FAILED: outside_range disagrees with the library's on {} rows\n", flag_mismatches);
    status = 1;
  }
  return status;
}

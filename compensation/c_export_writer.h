#pragma once
/// The C export's writer (behind compensation/c_export.h, which is what callers include): what
/// the generated C of every model kind is made of. The names (prefix, its upper case for the
/// macros, the type), literals of the type, the header's preamble, macros, API and include guard,
/// and the running B0 window. The generators of the two model kinds (c_export_eq2.h,
/// c_export_poly.h) write their text with it.

#include <string>
#include <vector>

#include "compensation/c_export.h"
#include "model/compensation_model.h"

namespace rlg::compensation::c_export {

/// Text safe inside a C block comment and free of trigraphs: printable ASCII but '?' and '\', and
/// '*' only between two characters neither of which is '/' (a product's "T1*(T2-T1)": no "/*" or
/// "*/" can form, also with the text around it); anything else as '_'.
std::string CommentText(const std::string& s);

/// A C string literal of `s`: printable ASCII as itself, '"', '\' and '?' escaped, '*' (so that
/// no "*/" appears outside a comment's end) and any other byte in octal.
std::string StringLiteral(const std::string& s);

/// `s` in upper case (ASCII).
std::string Upper(const std::string& s);

/// The shared text of one model's C code, in the options' precision and names.
class Writer {
 public:
  Writer(const model::FittedModel& model, const CExportOptions& options);

  /// The prefix of every name: rlg_comp.
  const std::string& P() const { return P_; }
  /// The prefix of the macros: RLG_COMP.
  const std::string& M() const { return M_; }
  /// The type of every value: "double" or "float".
  const std::string& R() const { return R_; }
  /// The temperature channels T_C holds, in its order.
  const std::vector<std::string>& Channels() const { return channels_; }
  /// The index into T_C of a channel the model reads.
  size_t ChannelIndex(const std::string& channel) const;

  /// A literal of type R() holding v: the shortest decimal that reads back to v (double) or to v
  /// rounded to float (float, with the suffix f). InputError for a value that is not finite.
  std::string Lit(double v) const;
  bool Float() const { return options_.precision == CPrecision::kFloat; }
  /// The libm function expm1 of the precision.
  std::string Expm1() const { return Float() ? "expm1f" : "expm1"; }

  /// The first lines of the header: what it is, the units.
  std::string Preamble(const std::string& what) const;
  /// The header's macros: the type, the channels (each with its role, "" for none), the B0
  /// window (0: none).
  std::string Macros(const std::vector<std::string>& roles, double b0_window_s) const;
  /// The header's state struct (its fields "  TYPE NAME; /* what */" a line) and functions.
  std::string Api(const std::string& state_fields) const;
  /// The header: `preamble`, then `body` inside the include guard and extern "C".
  std::string Guarded(const std::string& preamble, const std::string& body) const;
  /// The update's running B0 (and, referred, G0 of the variable `model`) over the window, then
  /// frozen: the compensators' code.
  std::string B0Update(bool referred) const;

 private:
  /// " from\n *   PATH\n *" or "": the source on a line of its own in the header.
  std::string FromLine() const;

  const CExportOptions& options_;
  std::string P_, M_, R_;
  std::vector<std::string> channels_;
};

}  // namespace rlg::compensation::c_export

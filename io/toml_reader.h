#pragma once
/// Strict reading of TOML tables: every key read or asked about is recorded, and Finish()
/// rejects any key nobody asked for, naming it with its file and line and the known key it most
/// likely misspells ("unknown key 'nmae' in [nodes[1]]; did you mean 'name'?", sim/spelling.h),
/// else listing the keys the table takes. A misspelt key is named so before what it causes: a
/// required key missing, or a table or entries a file needs ([[runs]]) missing. Wrong types and
/// out-of-range values raise InputError of the form "FILE:LINE: key 'KEY' in [CONTEXT]:
/// expected ...". Every message about keys points to the page that documents them.

#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace toml {
inline namespace v3 {
class table;
class node;
class array;
}  // namespace v3
}  // namespace toml

namespace rlg::io {

class TomlReader {
 public:
  /// `docs`: the page that documents the file's keys (scenario, gyro and suite files:
  /// scenarios/README.md; plan files: docs/plan.md); readers of its tables inherit it.
  TomlReader(const toml::table& table, std::string file, std::string context,
             std::string docs = "scenarios/README.md");

  /// Whether the table has `key`; asking makes `key` one of the table's known keys.
  bool Has(const std::string& key) const;
  double Number(const std::string& key) const;
  double Number(const std::string& key, double fallback) const;
  /// A number that must be > 0 (or >= 0 when allow_zero).
  double Positive(const std::string& key, bool allow_zero = false) const;
  double Positive(const std::string& key, double fallback, bool allow_zero = false) const;
  /// A number within [lo, hi] (the caller's comment says why those limits);
  /// InputError "... expected a number in lo...hi, got v" otherwise.
  double InRange(const std::string& key, double lo, double hi) const;
  double InRange(const std::string& key, double lo, double hi, double fallback) const;
  int64_t Integer(const std::string& key, int64_t fallback) const;
  bool Bool(const std::string& key, bool fallback) const;
  std::string String(const std::string& key) const;
  std::string String(const std::string& key, const std::string& fallback) const;
  std::vector<std::string> Strings(const std::string& key) const;
  /// Array of finite numbers, e.g. [lo, hi].
  std::vector<double> Numbers(const std::string& key) const;
  /// Array of [a, b] number pairs.
  std::vector<std::pair<double, double>> Pairs(const std::string& key) const;
  TomlReader Table(const std::string& key) const;
  std::optional<TomlReader> OptionalTable(const std::string& key) const;
  std::vector<TomlReader> ArrayOfTables(const std::string& key) const;
  /// Keys of this table in the byte order of their names, not the file's: toml++ keeps a table
  /// as a sorted map (so [sensors.*] and `shares` are read sorted by name).
  std::vector<std::string> Keys() const;

  /// Throws InputError for keys not read.
  void Finish() const;
  /// Throws InputError "FILE:LINE: key 'KEY' in [CONTEXT]: MESSAGE" (line of the key, or of the table).
  [[noreturn]] void Fail(const std::string& key, const std::string& message) const;
  /// Throws InputError "FILE:LINE: [CONTEXT]: MESSAGE" (line of the table), or, when a key not
  /// read yet misspells a key asked for and absent (`[[run]]` for `[[runs]]`), the unknown key.
  [[noreturn]] void FailHere(const std::string& message) const;

  /// "FILE:LINE: key 'KEY' in [CONTEXT]" (line of the key, or of the table): for a refusal that
  /// can only be made once other files are read (a run selector that matches no run).
  std::string Where(const std::string& key) const;

  const std::string& file() const { return file_; }
  const std::string& context() const { return context_; }
  int line() const;

 private:
  const toml::node* Get(const std::string& key) const;
  /// The refusal of a required `key` that is absent ("missing; " + `expected`), or of the key
  /// not read yet that misspells it.
  [[noreturn]] void Missing(const std::string& key, const std::string& expected) const;
  /// Throws the refusal of a key of the table not read or asked for yet that misspells one of
  /// `meant`, if there is one.
  void RefuseMisspelling(const std::vector<std::string>& meant) const;
  [[noreturn]] void FailUnknown(const std::string& key, int line, const std::string& hint) const;
  const toml::table& table_;
  std::string file_;
  std::string context_;
  std::string docs_;
  mutable std::set<std::string> used_;   // keys read, or given their default
  mutable std::set<std::string> asked_;  // keys asked about with Has()
};

/// Parses a TOML file (InputError naming the file, line and column on a syntax error).
/// The returned table must outlive readers made from it.
std::unique_ptr<toml::table> ParseTomlFile(const std::string& path);

}  // namespace rlg::io

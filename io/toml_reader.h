#pragma once
/// Strict reading of TOML tables: every key read is recorded, and Finish() rejects any key
/// nobody asked for, naming it with its file and line. Wrong types and out-of-range values
/// raise InputError of the form "FILE:LINE: key 'KEY' in [CONTEXT]: expected ...".

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
  TomlReader(const toml::table& table, std::string file, std::string context);

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
  [[noreturn]] void FailHere(const std::string& message) const;

  const std::string& file() const { return file_; }
  const std::string& context() const { return context_; }
  int line() const;

 private:
  const toml::node* Get(const std::string& key) const;
  const toml::table& table_;
  std::string file_;
  std::string context_;
  mutable std::set<std::string> used_;
};

/// Parses a TOML file (InputError naming the file, line and column on a syntax error).
/// The returned table must outlive readers made from it.
std::unique_ptr<toml::table> ParseTomlFile(const std::string& path);

}  // namespace rlg::io

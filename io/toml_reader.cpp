#include "io/toml_reader.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <toml++/toml.h>

#include "io/error_context.h"
#include "sim/errors.h"
#include "sim/spelling.h"

namespace rlg::io {

TomlReader::TomlReader(const toml::table& table, std::string file, std::string context, std::string docs)
    : table_(table), file_(std::move(file)), context_(std::move(context)), docs_(std::move(docs)) {}

int TomlReader::line() const { return static_cast<int>(table_.source().begin.line); }

std::string TomlReader::Where(const std::string& key) const {
  const toml::node* n = table_.get(key);
  const int ln = n ? static_cast<int>(n->source().begin.line) : line();
  return fmt::format("{}:{}: key '{}' in [{}]", file_, ln, key, context_);
}

void TomlReader::Fail(const std::string& key, const std::string& message) const {
  throw InputError(fmt::format("{}: {}", Where(key), message));
}

void TomlReader::FailHere(const std::string& message) const {
  // What a file lacks may be there misspelt: the keys asked for and absent.
  std::vector<std::string> absent;
  for (const auto* keys : {&used_, &asked_})
    for (const auto& k : *keys)
      if (!table_.contains(k)) absent.push_back(k);
  RefuseMisspelling(absent);
  throw InputError(fmt::format("{}:{}: [{}]: {}", file_, line(), context_, message));
}

void TomlReader::Missing(const std::string& key, const std::string& expected) const {
  RefuseMisspelling({key});
  Fail(key, "missing; " + expected);
}

void TomlReader::RefuseMisspelling(const std::vector<std::string>& meant) const {
  std::string typo, nearest;
  int typo_line = 0;
  size_t distance = 0;
  for (const auto& [k, v] : table_) {
    const std::string key(k.str());
    if (used_.count(key) || asked_.count(key)) continue;  // a key the reader knows
    const std::string n = sim::NearestName(key, meant);
    if (n.empty() || (!typo.empty() && sim::EditDistance(key, n) >= distance)) continue;
    typo = key, nearest = n, typo_line = static_cast<int>(v.source().begin.line), distance = sim::EditDistance(key, n);
  }
  if (!typo.empty()) FailUnknown(typo, typo_line, fmt::format("; did you mean '{}'?", nearest));
}

void TomlReader::FailUnknown(const std::string& key, int line, const std::string& hint) const {
  throw InputError(fmt::format("{}:{}: unknown key '{}' in [{}]{} (see {} for the keys)", file_, line, key, context_, hint,
                               docs_));
}

namespace {

/// A TOML number as a double: a float as it is, an integer rounded to the nearest double.
/// toml++'s value<double>() is empty for an integer no double holds exactly (beyond 2^53, e.g.
/// 155555555555555550), which is a number all the same: its range is the caller's to check.
std::optional<double> AsDouble(const toml::node& n) {
  if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
  if (const auto* f = n.as_floating_point()) return f->get();
  return std::nullopt;
}

}  // namespace

const toml::node* TomlReader::Get(const std::string& key) const {
  used_.insert(key);
  return table_.get(key);
}

bool TomlReader::Has(const std::string& key) const {
  asked_.insert(key);
  return table_.contains(key);
}

double TomlReader::Number(const std::string& key) const {
  const toml::node* n = Get(key);
  if (!n) Missing(key, "expected a number");
  const std::optional<double> v = AsDouble(*n);
  if (!v) Fail(key, "expected a number");
  if (!std::isfinite(*v)) Fail(key, "expected a finite number");
  return *v;
}

double TomlReader::Number(const std::string& key, double fallback) const {
  return Has(key) ? Number(key) : (used_.insert(key), fallback);
}

double TomlReader::Positive(const std::string& key, bool allow_zero) const {
  const double v = Number(key);
  if (allow_zero ? !(v >= 0.0) : !(v > 0.0)) Fail(key, fmt::format("expected a number {} 0, got {}", allow_zero ? ">=" : ">", v));
  return v;
}

double TomlReader::Positive(const std::string& key, double fallback, bool allow_zero) const {
  return Has(key) ? Positive(key, allow_zero) : (used_.insert(key), fallback);
}

double TomlReader::InRange(const std::string& key, double lo, double hi) const {
  const double v = Number(key);
  if (!(v >= lo && v <= hi)) Fail(key, fmt::format("expected a number in {:g}...{:g}, got {:g}", lo, hi, v));
  return v;
}

double TomlReader::InRange(const std::string& key, double lo, double hi, double fallback) const {
  return Has(key) ? InRange(key, lo, hi) : (used_.insert(key), fallback);
}

int64_t TomlReader::Integer(const std::string& key, int64_t fallback) const {
  if (!Has(key)) return used_.insert(key), fallback;
  const toml::node* n = Get(key);
  if (!n->is_integer()) Fail(key, "expected an integer");
  return *n->value<int64_t>();
}

bool TomlReader::Bool(const std::string& key, bool fallback) const {
  if (!Has(key)) return used_.insert(key), fallback;
  const toml::node* n = Get(key);
  if (!n->is_boolean()) Fail(key, "expected true or false");
  return *n->value<bool>();
}

std::string TomlReader::String(const std::string& key) const {
  const toml::node* n = Get(key);
  if (!n) Missing(key, "expected a string");
  if (!n->is_string()) Fail(key, "expected a string");
  return *n->value<std::string>();
}

std::string TomlReader::String(const std::string& key, const std::string& fallback) const {
  return Has(key) ? String(key) : (used_.insert(key), fallback);
}

std::vector<std::string> TomlReader::Strings(const std::string& key) const {
  const toml::node* n = Get(key);
  if (!n) Missing(key, "expected an array of strings");
  if (!n->is_array()) Fail(key, "expected an array of strings");
  std::vector<std::string> out;
  for (const auto& e : *n->as_array()) {
    if (!e.is_string()) Fail(key, "expected an array of strings");
    out.push_back(*e.value<std::string>());
  }
  return out;
}

std::vector<double> TomlReader::Numbers(const std::string& key) const {
  const toml::node* n = Get(key);
  if (!n) Missing(key, "expected an array of numbers");
  if (!n->is_array()) Fail(key, "expected an array of numbers");
  std::vector<double> out;
  for (const auto& e : *n->as_array()) {
    const std::optional<double> number = AsDouble(e);
    if (!number) Fail(key, fmt::format("entry {}: expected a number", out.size() + 1));
    const double v = *number;
    if (!std::isfinite(v)) Fail(key, fmt::format("entry {}: expected a finite number", out.size() + 1));
    out.push_back(v);
  }
  return out;
}

std::vector<std::pair<double, double>> TomlReader::Pairs(const std::string& key) const {
  const toml::node* n = Get(key);
  if (!n) Missing(key, "expected an array of [t, value] pairs");
  if (!n->is_array()) Fail(key, "expected an array of [t, value] pairs");
  std::vector<std::pair<double, double>> out;
  for (const auto& e : *n->as_array()) {
    const toml::array* p = e.as_array();
    const std::optional<double> t = p && p->size() == 2 ? AsDouble((*p)[0]) : std::nullopt;
    const std::optional<double> value = p && p->size() == 2 ? AsDouble((*p)[1]) : std::nullopt;
    if (!t || !value) Fail(key, fmt::format("entry {}: expected a pair of numbers [t, value]", out.size() + 1));
    const double a = *t, b = *value;
    if (!std::isfinite(a) || !std::isfinite(b)) Fail(key, fmt::format("entry {}: expected finite numbers", out.size() + 1));
    out.emplace_back(a, b);
  }
  return out;
}

TomlReader TomlReader::Table(const std::string& key) const {
  const toml::node* n = Get(key);
  if (!n) Missing(key, "expected a table");
  if (!n->is_table()) Fail(key, "expected a table");
  return TomlReader(*n->as_table(), file_, context_.empty() ? key : context_ + "." + key, docs_);
}

std::optional<TomlReader> TomlReader::OptionalTable(const std::string& key) const {
  if (!Has(key)) return used_.insert(key), std::nullopt;
  return Table(key);
}

std::vector<TomlReader> TomlReader::ArrayOfTables(const std::string& key) const {
  std::vector<TomlReader> out;
  const toml::node* n = Get(key);
  if (!n) return out;
  if (!n->is_array_of_tables()) Fail(key, "expected an array of tables ([[" + key + "]])");
  int i = 0;
  for (const auto& e : *n->as_array()) {
    out.emplace_back(*e.as_table(), file_, fmt::format("{}[{}]", key, ++i), docs_);
  }
  return out;
}

std::vector<std::string> TomlReader::Keys() const {
  std::vector<std::string> keys;
  for (const auto& [k, v] : table_) keys.emplace_back(k.str());
  return keys;
}

void TomlReader::Finish() const {
  std::vector<std::string> known(used_.begin(), used_.end());
  for (const auto& k : asked_)
    if (!used_.count(k)) known.push_back(k);
  std::sort(known.begin(), known.end());
  RefuseMisspelling(known);  // an unknown key near a known one first
  for (const auto& [k, v] : table_) {
    if (!used_.count(std::string(k.str()))) {
      FailUnknown(std::string(k.str()), static_cast<int>(v.source().begin.line),
                  known.empty() ? "" : fmt::format("; the keys here: {}", ListForMessage(known, ", ")));
    }
  }
}

std::unique_ptr<toml::table> ParseTomlFile(const std::string& path) {
  try {
    return std::make_unique<toml::table>(toml::parse_file(path));
  } catch (const toml::parse_error& e) {
    const auto& src = e.source();
    if (src.begin.line == 0) throw InputError(fmt::format("{}: cannot read file: {}", path, e.description()));
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", path, src.begin.line, src.begin.column,
                                 e.description()));
  }
}

}  // namespace rlg::io

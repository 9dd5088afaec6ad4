// The TOML-reading layer every kerf reader uses (toml_reader.hpp): positions, messages, and the
// getters that check a value's type, range and unit.

#include "formats/scene/toml_reader.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace kerf::toml_reader {

toml::table parse_file(const std::filesystem::path& file, const std::string& cannot_open) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw TomlError(cannot_open);
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return toml::parse(text.str(), file.string());
  } catch (const toml::parse_error& e) {
    const SourceFile source{file.string()};
    throw TomlError(position(source, e.source()) + ": TOML syntax: " + std::string(e.description()));
  }
}

TableRef TableRef::root(const SourceFile& file, const toml::table& table) {
  toml::source_region top;
  top.begin = {1, 1};
  top.end = {1, 1};
  return TableRef{file, table, "", top};
}

std::string TableRef::key(std::string_view k) const {
  return path.empty() ? std::string(k) : path + "." + std::string(k);
}

// --- messages -----------------------------------------------------------------------------------

std::string type_name(const toml::node& n) {
  switch (n.type()) {
  case toml::node_type::table: return "a table";
  case toml::node_type::array: return "an array";
  case toml::node_type::string: return "a string";
  case toml::node_type::integer: return "an integer";
  case toml::node_type::floating_point: return "a floating-point number";
  case toml::node_type::boolean: return "a boolean";
  case toml::node_type::date: return "a date";
  case toml::node_type::time: return "a time of day";
  case toml::node_type::date_time: return "a date-time";
  default: return "nothing";
  }
}

std::string found(const toml::node& n) {
  if (const auto* s = n.as_string()) return "\"" + s->get() + "\"";
  if (const auto* i = n.as_integer()) return std::to_string(i->get());
  if (const auto* f = n.as_floating_point()) {
    std::ostringstream os;
    os << f->get();
    return os.str();
  }
  if (const auto* b = n.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* a = n.as_array()) {
    std::string out = "[";
    for (std::size_t k = 0; k < a->size(); ++k) {
      if (k > 0) out += ", ";
      out += found(*a->get(k));
    }
    return out + "]";
  }
  return type_name(n);
}

std::string choices_text(const std::vector<std::string_view>& choices) {
  std::string out;
  for (std::size_t k = 0; k < choices.size(); ++k) {
    if (k > 0) out += k + 1 == choices.size() ? " or " : ", ";
    out.append(1, '"').append(choices[k]).append(1, '"');
  }
  return out;
}

std::string position(const SourceFile& file, const toml::source_region& at) {
  const unsigned line = at.begin.line == 0 ? 1u : at.begin.line;
  const unsigned column = at.begin.column == 0 ? 1u : at.begin.column;
  const std::string name = at.path && !at.path->empty() ? *at.path : file.name;
  return name + ":" + std::to_string(line) + ":" + std::to_string(column);
}

toml::source_region where(const toml::node& n, const TableRef& parent) {
  return n.source().begin.line != 0 ? n.source() : parent.where;
}

void fail(const SourceFile& file, const toml::source_region& at, std::string_view key, std::string_view message) {
  throw TomlError(position(file, at) + ": " + std::string(key) + ": " + std::string(message));
}

void fail_at(const TableRef& t, std::string_view k, std::string_view message) {
  fail(t.file, where(*t.find(k), t), t.key(k), message);
}

void missing(const TableRef& t, std::string_view k, std::string_view expected) {
  fail(t.file, t.where, t.key(k), "missing required key (expected " + std::string(expected) + ")");
}

void wrong(const toml::node& n, const TableRef& t, const std::string& key, std::string_view expected) {
  fail(t.file, where(n, t), key, "expected " + std::string(expected) + ", got " + found(n));
}

void check(bool ok, const TableRef& t, std::string_view k, std::string_view range) {
  if (ok) return;
  wrong(*t.find(k), t, t.key(k), range);
}

// --- tables -------------------------------------------------------------------------------------

void allow_only(const TableRef& t, std::initializer_list<std::string_view> allowed, std::string_view what) {
  for (auto&& [k, v] : t.table) {
    bool known = false;
    for (std::string_view a : allowed) known = known || k.str() == a;
    if (known) continue;
    const bool key_first = t.file.unknown_key_at == UnknownKeyAt::key;
    const toml::source_region& first = key_first ? k.source() : v.source();
    const toml::source_region& second = key_first ? v.source() : k.source();
    const toml::source_region& at = first.begin.line != 0 ? first : second.begin.line != 0 ? second : t.where;
    std::string message = "unknown key";
    if (!what.empty()) message += " for " + std::string(what);
    std::string list;
    for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    fail(t.file, at, t.key(k.str()), message + " (expected one of: " + list + ")");
  }
}

std::optional<TableRef> optional_table(const TableRef& t, std::string_view k, std::string_view expected) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  const toml::table* sub = n->as_table();
  if (sub == nullptr) wrong(*n, t, t.key(k), expected.empty() ? "a table ([" + t.key(k) + "])" : std::string(expected));
  return TableRef{t.file, *sub, t.key(k), where(*n, t)};
}

TableRef required_table(const TableRef& t, std::string_view k) {
  auto sub = optional_table(t, k);
  if (!sub) missing(t, k, "a table [" + t.key(k) + "]");
  return *sub;
}

std::vector<TableRef> table_array(const TableRef& t, std::string_view k, ElementPaths paths) {
  std::vector<TableRef> out;
  const toml::node* n = t.find(k);
  if (n == nullptr) return out;
  const toml::array* a = n->as_array();
  if (a == nullptr) wrong(*n, t, t.key(k), "an array of tables ([[" + t.key(k) + "]])");
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& e = *a->get(i);
    const std::string path = paths == ElementPaths::indexed ? item_key(t.key(k), i) : t.key(k);
    const toml::table* sub = e.as_table();
    if (sub == nullptr) wrong(e, t, path, "a table ([[" + t.key(k) + "]])");
    out.push_back(TableRef{t.file, *sub, path, where(e, t)});
  }
  return out;
}

// --- values -------------------------------------------------------------------------------------

std::optional<std::string> optional_string(const TableRef& t, std::string_view k) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  const auto* s = n->as_string();
  if (s == nullptr) wrong(*n, t, t.key(k), "a string");
  return s->get();
}

std::string required_string(const TableRef& t, std::string_view k) {
  auto s = optional_string(t, k);
  if (!s) missing(t, k, "a string");
  if (s->empty()) fail_at(t, k, "expected a non-empty string, got \"\"");
  return *s;
}

std::optional<bool> optional_boolean(const TableRef& t, std::string_view k) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  const auto* b = n->as_boolean();
  if (b == nullptr) wrong(*n, t, t.key(k), "true or false");
  return b->get();
}

std::optional<double> optional_number(const TableRef& t, std::string_view k) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  if (!n->is_integer() && !n->is_floating_point()) wrong(*n, t, t.key(k), "a number");
  const double v = *n->value<double>();
  if (!std::isfinite(v)) wrong(*n, t, t.key(k), "a finite number");
  return v;
}

int integer_in(const toml::node& n, const TableRef& t, const std::string& key, std::int64_t lo, std::int64_t hi,
               std::string_view expected) {
  const auto* i = n.as_integer();
  if (i == nullptr || i->get() < lo || i->get() > hi) wrong(n, t, key, expected);
  return static_cast<int>(i->get());
}

std::optional<int> optional_integer_in(const TableRef& t, std::string_view k, std::int64_t lo, std::int64_t hi,
                                       std::string_view expected) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  return integer_in(*n, t, t.key(k), lo, hi, expected);
}

int required_integer_in(const TableRef& t, std::string_view k, std::int64_t lo, std::int64_t hi,
                        std::string_view expected) {
  const toml::node* n = t.find(k);
  if (n == nullptr) missing(t, k, expected);
  return integer_in(*n, t, t.key(k), lo, hi, expected);
}

double quantity(const toml::node& n, const TableRef& t, const std::string& key, Dimension d) {
  if (const auto* s = n.as_string()) {
    try {
      return parse_quantity(s->get(), d);
    } catch (const QuantityError& e) {
      fail(t.file, where(n, t), key, e.what());
    }
  }
  if (n.is_integer() || n.is_floating_point()) {
    const double v = *n.value<double>();
    if (!std::isfinite(v))
      fail(t.file, where(n, t), key, "expected " + describe(d) + ", got " + found(n) + " (not a finite number)");
    return v;
  }
  wrong(n, t, key, describe(d));
}

std::optional<double> optional_quantity(const TableRef& t, std::string_view k, Dimension d) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  return quantity(*n, t, t.key(k), d);
}

double required_quantity(const TableRef& t, std::string_view k, Dimension d) {
  auto v = optional_quantity(t, k, d);
  if (!v) missing(t, k, describe(d));
  return *v;
}

Eigen::Vector3d vector3(const TableRef& t, std::string_view k, Dimension d, bool nonzero) {
  const toml::node* n = t.find(k);
  if (n == nullptr) missing(t, k, "an array of three " + describe(d));
  const toml::array* a = n->as_array();
  const std::string path = t.key(k);
  if (a == nullptr || a->size() != 3) wrong(*n, t, path, "an array of three " + describe(d));
  Eigen::Vector3d v;
  for (std::size_t i = 0; i < 3; ++i) v[static_cast<Eigen::Index>(i)] = quantity(*a->get(i), t, item_key(path, i), d);
  if (nonzero && !(v.norm() > 0.0)) wrong(*n, t, path, "a non-zero vector");
  return v;
}

std::size_t choice_index(const toml::node& n, const TableRef& t, const std::string& key,
                         const std::vector<std::string_view>& names) {
  const auto* s = n.as_string();
  if (s == nullptr) wrong(n, t, key, "a string");
  for (std::size_t i = 0; i < names.size(); ++i)
    if (s->get() == names[i]) return i;
  wrong(n, t, key, choices_text(names));
}

std::optional<std::string> optional_one_of(const TableRef& t, std::string_view k,
                                           std::initializer_list<std::string_view> names) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  return std::string(names.begin()[choice_index(*n, t, t.key(k), std::vector<std::string_view>(names))]);
}

// --- arrays -------------------------------------------------------------------------------------

std::string item_key(const std::string& key, std::size_t k) { return key + "[" + std::to_string(k) + "]"; }

const toml::array& non_empty_array(const toml::node& n, const TableRef& t, const std::string& key,
                                   std::string_view expected) {
  const toml::array* a = n.as_array();
  if (a == nullptr || a->empty()) wrong(n, t, key, expected);
  return *a;
}

std::string string_item(const toml::node& n, const TableRef& t, const std::string& key, std::string_view expected) {
  const auto* s = n.as_string();
  if (s == nullptr || s->get().empty()) wrong(n, t, key, expected);
  return s->get();
}

std::vector<std::pair<std::string, const toml::node*>> required_strings(const TableRef& t, std::string_view k) {
  const toml::node* n = t.find(k);
  if (n == nullptr) missing(t, k, "a non-empty array of strings");
  const toml::array& a = non_empty_array(*n, t, t.key(k), "a non-empty array of strings");
  std::vector<std::pair<std::string, const toml::node*>> out;
  for (std::size_t i = 0; i < a.size(); ++i)
    out.emplace_back(string_item(*a.get(i), t, item_key(t.key(k), i), "a non-empty string"), a.get(i));
  return out;
}

std::vector<int> ascending_integers(const toml::node& n, const TableRef& t, const std::string& key, std::int64_t lo,
                                    std::int64_t hi, std::string_view expected) {
  const toml::array& a = non_empty_array(n, t, key, expected);
  std::vector<int> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const int v = integer_in(*a.get(i), t, item_key(key, i), lo, hi, expected);
    if (!out.empty() && v <= out.back()) wrong(*a.get(i), t, item_key(key, i), expected);
    out.push_back(v);
  }
  return out;
}

} // namespace kerf::toml_reader

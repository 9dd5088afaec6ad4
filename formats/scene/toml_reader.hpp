#pragma once
// Reading kerf's TOML files — scene files, the parameter files a scene includes, study files — over
// toml++: a table with its file and key path (TableRef), getters that check and convert each value,
// and one form for every error:
//
//   FILE:LINE:COLUMN: KEY: expected WHAT, got WHAT WAS WRITTEN
//
// KEY is the full key path ("tools[1].trajectory.rate", "reference.scene_degree.clay_pull"), LINE
// and COLUMN point at the offending value (or key), at the table's header for a missing key, and
// at 1:1 for a missing top-level table. The readers (scene_reader.cpp, study_spec.cpp) are short
// functions over these, one per table; the formats are described in docs/scenes.md and
// docs/studies.md ("Study file").
//
// Integers are TOML integers only (toml++'s as_integer, never value<int64_t>(), which casts a float
// such as 6.7e87 to int64_t unchecked: undefined behaviour, found by fuzz_study).

#include "formats/scene/quantity.hpp"

#include <Eigen/Core>
#include <toml++/toml.h>

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace kerf {

/// A TOML file that cannot be used; what() reads "FILE:LINE:COLUMN: KEY: expected …, got …". Each
/// reader turns it into its own error type at its entry point (SceneError, StudyError).
class TomlError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

namespace toml_reader {

/// Where an unknown key is reported: at the key itself (scene and parameter files), or at its value
/// (study files). Either falls back to the other when toml++ has no position for it (a key merged
/// in from a parameter file).
enum class UnknownKeyAt { key, value };

/// The file being read: its name as messages print it (as the caller gave it).
struct SourceFile {
  std::string name;
  UnknownKeyAt unknown_key_at = UnknownKeyAt::key;
};

/// Reads and parses `file`. Throws TomlError `cannot_open` when it cannot be read, and
/// "FILE:LINE:COLUMN: TOML syntax: …" on a syntax error. Every node's source path is `file` as given.
toml::table parse_file(const std::filesystem::path& file, const std::string& cannot_open);

/// A table of a TOML file with its key path ("tools[1].trajectory"; "" for the root) and where it
/// starts (its header, or its parent's when toml++ has no position for it).
struct TableRef {
  const SourceFile& file;
  const toml::table& table;
  std::string path;
  toml::source_region where;

  /// The root table of `file` (at 1:1).
  static TableRef root(const SourceFile& file, const toml::table& table);
  /// The key path of `k` in this table: "path.k".
  [[nodiscard]] std::string key(std::string_view k) const;
  [[nodiscard]] const toml::node* find(std::string_view k) const { return table.get(k); }
};

// --- messages ---------------------------------------------------------------------------------

/// What a node is, for messages: "a string", "an integer", "a table", …
std::string type_name(const toml::node& n);
/// What was written, for "got …": a string quoted, a number or boolean as written, an array's items.
std::string found(const toml::node& n);
/// "a", "b" or "c" (quoted): the choices of an enumeration, as messages list them.
std::string choices_text(const std::vector<std::string_view>& choices);
/// "FILE:LINE:COLUMN" of `at`; FILE is the included parameter file's when the node came from one.
std::string position(const SourceFile& file, const toml::source_region& at);
/// A node's own position, or the enclosing table's when toml++ has none for it.
toml::source_region where(const toml::node& n, const TableRef& parent);

/// Throws TomlError "FILE:LINE:COLUMN: KEY: message".
[[noreturn]] void fail(const SourceFile& file, const toml::source_region& at, std::string_view key,
                       std::string_view message);
/// Fails at the value of key `k` of `t` (which must be there), naming `t.key(k)`.
[[noreturn]] void fail_at(const TableRef& t, std::string_view k, std::string_view message);
/// "missing required key (expected …)", at the table's header.
[[noreturn]] void missing(const TableRef& t, std::string_view k, std::string_view expected);
/// "expected …, got …" at node `n` (a value of `t`, or inside one), named `key`.
[[noreturn]] void wrong(const toml::node& n, const TableRef& t, const std::string& key, std::string_view expected);
/// Fails at key `k` of `t` with "expected <range>, got <written>" unless `ok`.
void check(bool ok, const TableRef& t, std::string_view k, std::string_view range);

// --- tables -----------------------------------------------------------------------------------

/// Every key of `t` must be one of `allowed`: "unknown key[ for WHAT] (expected one of: a, b, c)".
void allow_only(const TableRef& t, std::initializer_list<std::string_view> allowed, std::string_view what = "");
/// The table at `k`, if there; anything else there is "expected `expected`" (default "a table ([KEY])").
std::optional<TableRef> optional_table(const TableRef& t, std::string_view k, std::string_view expected = "");
TableRef required_table(const TableRef& t, std::string_view k);

/// How the tables of an array of tables are named in messages: by position ("tools[1].name": the
/// order means something) or by the array's name ("calibrate.scene": each stands alone).
enum class ElementPaths { indexed, array_name };
/// The tables of an array of tables ([[k]]), none when absent.
std::vector<TableRef> table_array(const TableRef& t, std::string_view k, ElementPaths paths = ElementPaths::indexed);

// --- values -----------------------------------------------------------------------------------

std::optional<std::string> optional_string(const TableRef& t, std::string_view k);
/// A non-empty string.
std::string required_string(const TableRef& t, std::string_view k);
std::optional<bool> optional_boolean(const TableRef& t, std::string_view k);
/// A finite number written as a TOML integer or float (no unit).
std::optional<double> optional_number(const TableRef& t, std::string_view k);

/// A TOML integer in [lo, hi] at node `n` (named `key`); anything else is "expected `expected`".
int integer_in(const toml::node& n, const TableRef& t, const std::string& key, std::int64_t lo, std::int64_t hi,
               std::string_view expected);
std::optional<int> optional_integer_in(const TableRef& t, std::string_view k, std::int64_t lo, std::int64_t hi,
                                       std::string_view expected);
int required_integer_in(const TableRef& t, std::string_view k, std::int64_t lo, std::int64_t hi,
                        std::string_view expected);

/// A quantity at node `n`: a string with a unit ("15 mm", quantity.hpp) or a plain, finite SI number.
double quantity(const toml::node& n, const TableRef& t, const std::string& key, Dimension d);
std::optional<double> optional_quantity(const TableRef& t, std::string_view k, Dimension d);
double required_quantity(const TableRef& t, std::string_view k, Dimension d);
/// A 3-vector: an array of three quantities; `nonzero` rejects the zero vector.
Eigen::Vector3d vector3(const TableRef& t, std::string_view k, Dimension d, bool nonzero);

/// The index in `names` of the string at node `n`: "expected a string" for anything but a string,
/// else "expected \"a\", \"b\" or \"c\"" for a string not among them.
std::size_t choice_index(const toml::node& n, const TableRef& t, const std::string& key,
                         const std::vector<std::string_view>& names);
/// One of `names` at key `k`, if there.
std::optional<std::string> optional_one_of(const TableRef& t, std::string_view k,
                                           std::initializer_list<std::string_view> names);

/// The value named by the string at node `n` (an enumeration written by name).
template <typename Value>
Value choice(const toml::node& n, const TableRef& t, const std::string& key,
             std::initializer_list<std::pair<std::string_view, Value>> choices) {
  std::vector<std::string_view> names;
  for (const auto& c : choices) names.push_back(c.first);
  return (choices.begin() + choice_index(n, t, key, names))->second;
}

template <typename Value>
std::optional<Value> optional_choice(const TableRef& t, std::string_view k,
                                     std::initializer_list<std::pair<std::string_view, Value>> choices) {
  const toml::node* n = t.find(k);
  if (n == nullptr) return std::nullopt;
  return choice(*n, t, t.key(k), choices);
}

template <typename Value>
Value required_choice(const TableRef& t, std::string_view k,
                      std::initializer_list<std::pair<std::string_view, Value>> choices) {
  const toml::node* n = t.find(k);
  if (n == nullptr) {
    std::vector<std::string_view> names;
    for (const auto& c : choices) names.push_back(c.first);
    missing(t, k, choices_text(names));
  }
  return choice(*n, t, t.key(k), choices);
}

// --- arrays -----------------------------------------------------------------------------------

/// "KEY[k]": the key path of an array's k-th item.
std::string item_key(const std::string& key, std::size_t k);
/// The non-empty array at node `n`; anything else (an empty array too) is "expected `expected`".
const toml::array& non_empty_array(const toml::node& n, const TableRef& t, const std::string& key,
                                   std::string_view expected);
/// A non-empty string at node `n` (an array's item); anything else is "expected `expected`".
std::string string_item(const toml::node& n, const TableRef& t, const std::string& key, std::string_view expected);
/// The non-empty array of non-empty strings at `k` (required), with each string's node for
/// messages about it.
std::vector<std::pair<std::string, const toml::node*>> required_strings(const TableRef& t, std::string_view k);
/// A non-empty array of strictly ascending TOML integers in [lo, hi] at node `n` (mesh levels,
/// model resolutions); anything else is "expected `expected`", at the item that breaks it.
std::vector<int> ascending_integers(const toml::node& n, const TableRef& t, const std::string& key, std::int64_t lo,
                                    std::int64_t hi, std::string_view expected);

} // namespace toml_reader
} // namespace kerf

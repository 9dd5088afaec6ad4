#pragma once
// The one check every kerf TOML reader (scene files, study files) makes of a table: that each of
// its keys is one the reader knows. Each reader reports the unknown key with its own error type
// and place; the key and the list of allowed ones read the same everywhere.

#include <toml++/toml.h>

#include <initializer_list>
#include <string>
#include <string_view>

namespace kerf {

/// The allowed keys as a message lists them: "a, b, c".
inline std::string allowed_keys_text(std::initializer_list<std::string_view> allowed) {
  std::string out;
  for (std::string_view a : allowed) {
    if (!out.empty()) out += ", ";
    out += a;
  }
  return out;
}

/// The first key of `table` (in the file's order) that is not in `allowed`, or nullptr when every
/// key is allowed; `value` is set to its node.
inline const toml::key* first_unknown_key(const toml::table& table, std::initializer_list<std::string_view> allowed,
                                          const toml::node** value = nullptr) {
  for (auto&& [k, v] : table) {
    bool known = false;
    for (std::string_view a : allowed) known = known || k.str() == a;
    if (known) continue;
    if (value) *value = &v;
    return &k;
  }
  return nullptr;
}

} // namespace kerf

// Settings described once, used everywhere: every method's settings struct publishes a table
// of its fields (name, unit, range, description). The table validates user input with
// messages that name the parameter and value, fills settings from key/value pairs
// (Python keyword arguments, command-line options), and lists defaults for docs and the UI.
// A setting that is a choice among named alternatives is an int field whose table entry
// names them ("fixed|adaptive"): the names are what Python, the command line and the add-on
// use; the int is the first name's value (the field's minimum) plus the name's position.
#pragma once

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "core/base/check.h"

namespace aolab {

enum class SettingType { Float, Int, Bool, Choice };

/// Type-erased description of one setting, for the registry, Python and the add-on.
struct SettingDescription {
  std::string name;
  SettingType type = SettingType::Float;
  double default_value = 0;
  double min = 0;  ///< inclusive
  double max = 0;  ///< inclusive
  std::string unit;
  std::string description;
  std::vector<std::string> choices;  ///< Choice: the names of values min, min + 1, ..., max
};

/// One field of settings struct S.
template <class S>
struct SettingField {
  const char* name;
  std::variant<float S::*, int S::*, bool S::*> member;
  double min, max;  ///< inclusive range; ignored for bools
  const char* unit;
  const char* description;
  /// Only for int fields that are choices: the names of min, min + 1, ..., max, separated by
  /// '|' (e.g. "off|greedy|careful" for the range [0, 2]); nullptr for a number.
  const char* choices = nullptr;
};

/// Key/value settings as they arrive from Python or the command line.
using SettingValues = std::map<std::string, double>;

namespace detail {
// Bounds with enough digits to read back exactly (2147483647, not 2.14748e+09), so that an
// out-of-range value and the bound it breaks never print alike.
inline std::string format_range(double lo, double hi) {
  return '[' + exact_number(lo) + ", " + exact_number(hi) + ']';
}

inline std::vector<std::string> split_choices(const char* list) {
  std::vector<std::string> names(1);
  for (const char* c = list; *c; ++c) {
    if (*c == '|')
      names.emplace_back();
    else
      names.back() += *c;
  }
  return names;
}

/// "one of a, b, c" for a choice field, "in [lo, hi] unit" for a number.
template <class S>
std::string requirement(const SettingField<S>& f) {
  if (f.choices) {
    std::string names;
    for (const auto& n : split_choices(f.choices)) names += (names.empty() ? "" : ", ") + n;
    return "must be one of " + names;
  }
  return std::string("must be in ") + format_range(f.min, f.max) +
         (f.unit[0] ? std::string(" ") + f.unit : "");
}
}  // namespace detail

/// The value that names `choice` of a Choice setting; throws std::invalid_argument naming
/// the setting and listing its choices otherwise.
inline double choice_value(const SettingDescription& d, const std::string& choice) {
  CHECK_EQ(int(d.type), int(SettingType::Choice));
  std::string names;
  for (std::size_t i = 0; i < d.choices.size(); ++i) {
    if (d.choices[i] == choice) return d.min + double(i);
    names += (names.empty() ? "" : ", ") + d.choices[i];
  }
  throw_invalid(d.name, "must be one of " + names, "'" + choice + "'");
}

/// Throws std::invalid_argument unless every field of `s` is in its range.
template <class S, std::size_t N>
void validate_settings(const S& s, const SettingField<S> (&fields)[N]) {
  for (const auto& f : fields) {
    std::visit(
        [&](auto member) {
          const double v = double(s.*member);
          using T = std::remove_cvref_t<decltype(s.*member)>;
          if constexpr (std::is_same_v<T, bool>) return;
          // A float field holds its bounds rounded to float (1e30 becomes 1.0000000150e30).
          const double lo = double(T(f.min)), hi = double(T(f.max));
          if (!std::isfinite(v) || v < lo || v > hi)
            throw_invalid(f.name, detail::requirement(f), s.*member);
        },
        f.member);
  }
}

/// Sets field `name` of `s` from a double, checking type and range. Returns false if S has
/// no such field (so callers can offer the list of valid names).
template <class S, std::size_t N>
bool set_setting(S& s, const SettingField<S> (&fields)[N], const std::string& name, double value) {
  for (const auto& f : fields) {
    if (name != f.name) continue;
    std::visit(
        [&](auto member) {
          using T = std::remove_cvref_t<decltype(s.*member)>;
          if constexpr (std::is_same_v<T, bool>) {
            if (value != 0.0 && value != 1.0) throw_invalid(name, "must be a boolean", value);
            s.*member = value != 0.0;
          } else {
            if (!std::isfinite(value) || value < f.min || value > f.max)
              throw_invalid(name, detail::requirement(f), value);
            if constexpr (std::is_same_v<T, int>) {
              if (value != std::floor(value)) throw_invalid(name, "must be an integer", value);
              s.*member = int(value);
            } else {
              s.*member = T(value);
            }
          }
        },
        f.member);
    return true;
  }
  return false;
}

/// Fills a settings struct from key/value pairs; unknown keys throw std::invalid_argument
/// listing the valid names of `what` (a method name): the fields, then `also_valid` (settings
/// handled outside S, such as the registry's `power`, which callers take out first).
template <class S, std::size_t N>
S settings_from_values(const SettingValues& values, const SettingField<S> (&fields)[N],
                       const std::string& what, const std::vector<std::string>& also_valid = {}) {
  S s;
  for (const auto& [name, value] : values) {
    if (!set_setting(s, fields, name, value)) {
      std::string valid;
      for (const auto& f : fields) valid += std::string(valid.empty() ? "" : ", ") + f.name;
      for (const auto& n : also_valid) valid += ", " + n;
      throw std::invalid_argument("unknown setting '" + name + "' for " + what +
                                  "; valid settings: " + valid);
    }
  }
  validate_settings(s, fields);
  return s;
}

/// The table as type-erased descriptions, defaults taken from a default-constructed S.
template <class S, std::size_t N>
std::vector<SettingDescription> describe_settings(const SettingField<S> (&fields)[N]) {
  const S defaults{};
  std::vector<SettingDescription> out;
  for (const auto& f : fields) {
    SettingDescription d;
    d.name = f.name;
    d.unit = f.unit;
    d.description = f.description;
    std::visit(
        [&](auto member) {
          using T = std::remove_cvref_t<decltype(defaults.*member)>;
          d.type = std::is_same_v<T, bool>  ? SettingType::Bool
                   : std::is_same_v<T, int> ? SettingType::Int
                                            : SettingType::Float;
          d.default_value = double(defaults.*member);
          d.min = std::is_same_v<T, bool> ? 0.0 : f.min;
          d.max = std::is_same_v<T, bool> ? 1.0 : f.max;
          if constexpr (std::is_same_v<T, int>) {
            if (f.choices) {
              d.type = SettingType::Choice;
              d.choices = detail::split_choices(f.choices);
              CHECK_EQ(double(d.choices.size()), f.max - f.min + 1);
            }
          }
        },
        f.member);
    out.push_back(d);
  }
  return out;
}

}  // namespace aolab

// Enum <-> name conversions from one table per enum, so that a name, its value and its help text
// are written once and every lookup, both ways, goes through the same code:
//
//   inline constexpr EnumName<Mode> kModeNames[] = {
//       {Mode::kInterpolate, "interpolate", "frames between the inputs"}, ...};
//   NameOf(kModeNames, Mode::kPredict)                 // "predict"
//   ParseName(kModeNames, FLAGS_mode, "--mode")        // throws "--mode must be a, b or c"
#ifndef EVFS_CORE_ENUM_NAMES_H_
#define EVFS_CORE_ENUM_NAMES_H_

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "evfs/core/error.h"

namespace evfs {

/// One row of an enum's table: the value, its name (flags, summaries) and a one-line help.
template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
  const char* help;
};

/// The name of `value` in `table`; `unknown` when the table has no such row.
template <typename Enum, std::size_t N>
constexpr const char* NameOf(const EnumName<Enum> (&table)[N], Enum value,
                             const char* unknown = "") {
  for (const EnumName<Enum>& row : table) {
    if (row.value == value) return row.name;
  }
  return unknown;
}

/// The value named `text` in `table` into `*value`; false (and `*value` untouched) otherwise.
template <typename Enum, std::size_t N>
bool FindName(const EnumName<Enum> (&table)[N], std::string_view text, Enum* value) {
  for (const EnumName<Enum>& row : table) {
    if (text == row.name) {
      *value = row.value;
      return true;
    }
  }
  return false;
}

/// The names of `table` in order, joined by `separator`, the last two by `last_separator`:
/// NameList(t) is "a, b, c", NameList(t, ", ", " or ") is "a, b or c".
template <typename Enum, std::size_t N>
std::string NameList(const EnumName<Enum> (&table)[N], const char* separator = ", ",
                     const char* last_separator = nullptr) {
  std::string names;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) names += (i + 1 == N && last_separator != nullptr) ? last_separator : separator;
    names += table[i].name;
  }
  return names;
}

/// Every value of `table`, in order.
template <typename Enum, std::size_t N>
std::vector<Enum> AllValues(const EnumName<Enum> (&table)[N]) {
  std::vector<Enum> values;
  for (const EnumName<Enum>& row : table) values.push_back(row.value);
  return values;
}

/// The value named `text`; throws InvalidArgumentError("`flag` must be a, b or c") otherwise.
template <typename Enum, std::size_t N>
Enum ParseName(const EnumName<Enum> (&table)[N], std::string_view text, const std::string& flag) {
  Enum value{};
  if (!FindName(table, text, &value)) {
    throw InvalidArgumentError(flag + " must be " + NameList(table, ", ", " or "));
  }
  return value;
}

}  // namespace evfs

#endif  // EVFS_CORE_ENUM_NAMES_H_

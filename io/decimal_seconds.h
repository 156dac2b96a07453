// Exact conversion between decimal seconds as written in text files ("2.713584001") and the
// int64 nanoseconds used inside evfs. Going through a double would round (2.713584001 is not a
// binary fraction), so the digits are accumulated as integers instead.
#ifndef EVFS_IO_DECIMAL_SECONDS_H_
#define EVFS_IO_DECIMAL_SECONDS_H_

#include <cstdint>
#include <string>
#include <vector>

namespace evfs {

/// The most fractional digits a timestamp may have: one digit per decimal place down to 1 ns.
constexpr int kMaxFractionDigits = 9;

/// Outcome of ParseDecimalSeconds.
enum class DecimalStatus {
  kOk,
  kNotANumber,     // no digits, or a '.' without digits after it
  kTooManyDigits,  // more than kMaxFractionDigits after the '.'
  kOverflow,       // the value does not fit int64 nanoseconds (about ±292 years)
};

namespace internal {

constexpr int64_t kPowersOfTen[kMaxFractionDigits + 1] = {
    1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000, 1000000000};

inline bool IsDigit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

/// Writes `value` in decimal at `out` (room for 20 characters); returns the end.
inline char* FormatUnsigned(uint64_t value, char* out) {
  char digits[20];
  int count = 0;
  do {
    digits[count++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  while (count > 0) *out++ = digits[--count];
  return out;
}

}  // namespace internal

/// Parses `[-]digits[.digits]` starting at `p` into nanoseconds, exactly. The number ends at the
/// first character that is not part of it; the buffer must contain such a character (a space, a
/// newline or a NUL) so that no end pointer is needed in this hot loop. Returns the position
/// after the number; `*status` says whether it parsed. The caller checks what follows.
inline const char* ParseDecimalSeconds(const char* p, int64_t* t_ns, DecimalStatus* status) {
  using internal::IsDigit;
  const bool negative = (*p == '-');
  if (negative) ++p;
  const char* const integer_begin = p;
  while (*p == '0') ++p;  // leading zeros do not count towards the overflow limit
  const char* const significant_begin = p;
  uint64_t integer_part = 0;
  while (IsDigit(*p)) integer_part = integer_part * 10 + static_cast<uint64_t>(*p++ - '0');
  const bool has_integer_digits = p != integer_begin;
  // 10 significant digits keep integer_part * 1e9 below 2^64, so the check below is exact.
  const bool integer_too_long = p - significant_begin > 10;

  uint64_t fraction = 0;
  int fraction_digits = 0;
  if (*p == '.') {
    ++p;
    const char* const fraction_begin = p;
    while (IsDigit(*p)) fraction = fraction * 10 + static_cast<uint64_t>(*p++ - '0');
    fraction_digits = static_cast<int>(p - fraction_begin);
    if (fraction_digits == 0) {
      *status = DecimalStatus::kNotANumber;
      return p;
    }
  }
  if (!has_integer_digits) {
    *status = DecimalStatus::kNotANumber;
    return p;
  }
  if (fraction_digits > kMaxFractionDigits) {
    *status = DecimalStatus::kTooManyDigits;
    return p;
  }
  const uint64_t fraction_ns =
      fraction *
      static_cast<uint64_t>(internal::kPowersOfTen[kMaxFractionDigits - fraction_digits]);
  const uint64_t magnitude = integer_part * 1000000000ULL + fraction_ns;
  if (integer_too_long || magnitude > static_cast<uint64_t>(INT64_MAX)) {
    *status = DecimalStatus::kOverflow;
    return p;
  }
  *t_ns = negative ? -static_cast<int64_t>(magnitude) : static_cast<int64_t>(magnitude);
  *status = DecimalStatus::kOk;
  return p;
}

/// A short phrase saying what was wrong, for error messages ("more than 9 fractional digits").
std::string DescribeDecimalStatus(DecimalStatus status);

/// The fewest fractional digits d (0..9) such that every timestamp is a multiple of 10^(9-d) ns,
/// i.e. such that FormatDecimalSeconds(t, d) loses nothing. 0 for an empty list.
int MinimalFractionDigits(const std::vector<int64_t>& t_ns);

/// Writes `t_ns` as decimal seconds with exactly `fraction_digits` digits after the point (none
/// and no point when 0), truncating digits beyond that. Returns the number of characters
/// written to `out`, which must have room for 32.
int FormatDecimalSeconds(int64_t t_ns, int fraction_digits, char* out);

/// Same as above, as a string.
std::string FormatDecimalSeconds(int64_t t_ns, int fraction_digits);

}  // namespace evfs

#endif  // EVFS_IO_DECIMAL_SECONDS_H_

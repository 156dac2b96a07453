#include "evfs/io/decimal_seconds.h"

namespace evfs {

std::string DescribeDecimalStatus(DecimalStatus status) {
  if (status == DecimalStatus::kNotANumber) return "not a decimal number of seconds";
  if (status == DecimalStatus::kTooManyDigits) {
    return "more than " + std::to_string(kMaxFractionDigits) +
           " fractional digits (timestamps are kept in whole nanoseconds)";
  }
  if (status == DecimalStatus::kOverflow) return "too large for int64 nanoseconds";
  return "a valid number";
}

int MinimalFractionDigits(const std::vector<int64_t>& t_ns) {
  int digits = 0;
  for (const int64_t t : t_ns) {
    // Raise the digit count until this timestamp is a multiple of 10^(9 - digits) ns.
    while (digits < kMaxFractionDigits &&
           t % internal::kPowersOfTen[kMaxFractionDigits - digits] != 0) {
      ++digits;
    }
    if (digits == kMaxFractionDigits) break;
  }
  return digits;
}

int FormatDecimalSeconds(int64_t t_ns, int fraction_digits, char* out) {
  char* p = out;
  uint64_t magnitude = static_cast<uint64_t>(t_ns);
  if (t_ns < 0) {
    *p++ = '-';
    magnitude = 0 - magnitude;  // well defined for INT64_MIN as well
  }
  const uint64_t nanoseconds = magnitude % 1000000000ULL;
  p = internal::FormatUnsigned(magnitude / 1000000000ULL, p);

  if (fraction_digits > 0) {
    *p++ = '.';
    uint64_t fraction =
        nanoseconds /
        static_cast<uint64_t>(internal::kPowersOfTen[kMaxFractionDigits - fraction_digits]);
    for (int i = fraction_digits - 1; i >= 0; --i) {
      p[i] = static_cast<char>('0' + fraction % 10);
      fraction /= 10;
    }
    p += fraction_digits;
  }
  return static_cast<int>(p - out);
}

std::string FormatDecimalSeconds(int64_t t_ns, int fraction_digits) {
  char buffer[32];
  return std::string(buffer, FormatDecimalSeconds(t_ns, fraction_digits, buffer));
}

}  // namespace evfs

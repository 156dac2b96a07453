#include "evfs/io/decimal_seconds.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

namespace evfs {
namespace {

// Parses a whole string; fails the test when characters are left over after a valid number.
DecimalStatus Parse(const std::string& text, int64_t* t_ns) {
  DecimalStatus status;
  const char* end = ParseDecimalSeconds(text.c_str(), t_ns, &status);
  if (status == DecimalStatus::kOk) {
    EXPECT_EQ(end, text.c_str() + text.size()) << text;
  }
  return status;
}

TEST(ParseDecimalSecondsTest, ParsesExactlyWithoutDoubleRounding) {
  struct Case {
    const char* text;
    int64_t t_ns;
  };
  const Case cases[] = {
      {"2.713584001", 2713584001},  // not a binary fraction: via double it may come out ...000
      {"0.550024001", 550024001},
      {"3.312219", 3312219000},
      {"0", 0},
      {"7", 7000000000},
      {"0.000000001", 1},
      {"12.5", 12500000000},
      {"-1.25", -1250000000},
      {"0000000000012.5", 12500000000},  // leading zeros do not count towards overflow
      {"9223372036.854775807", INT64_MAX},
  };
  for (const Case& c : cases) {
    int64_t t_ns = -42;
    EXPECT_EQ(Parse(c.text, &t_ns), DecimalStatus::kOk) << c.text;
    EXPECT_EQ(t_ns, c.t_ns) << c.text;
  }
}

TEST(ParseDecimalSecondsTest, StopsAtTheFirstCharacterAfterTheNumber) {
  const std::string text = "1.5 23";
  int64_t t_ns = 0;
  DecimalStatus status;
  const char* end = ParseDecimalSeconds(text.c_str(), &t_ns, &status);
  EXPECT_EQ(status, DecimalStatus::kOk);
  EXPECT_EQ(end - text.c_str(), 3);
  EXPECT_EQ(t_ns, 1500000000);
}

TEST(ParseDecimalSecondsTest, RejectsWhatIsNotAnExactTimestamp) {
  struct Case {
    const char* text;
    DecimalStatus status;
  };
  const Case cases[] = {
      {"", DecimalStatus::kNotANumber},
      {"abc", DecimalStatus::kNotANumber},
      {"-", DecimalStatus::kNotANumber},
      {".5", DecimalStatus::kNotANumber},
      {"1.", DecimalStatus::kNotANumber},
      {"1.0000000001", DecimalStatus::kTooManyDigits},
      {"9223372036.854775808", DecimalStatus::kOverflow},
      {"10000000000", DecimalStatus::kOverflow},
      {"123456789012345678901234567890", DecimalStatus::kOverflow},
  };
  for (const Case& c : cases) {
    int64_t t_ns = 0;
    EXPECT_EQ(Parse(c.text, &t_ns), c.status) << c.text;
  }
  EXPECT_NE(DescribeDecimalStatus(DecimalStatus::kTooManyDigits).find("9"), std::string::npos);
}

TEST(MinimalFractionDigitsTest, FindsTheFewestDigitsThatKeepEveryValue) {
  EXPECT_EQ(MinimalFractionDigits({}), 0);
  EXPECT_EQ(MinimalFractionDigits({3000000000, 5000000000}), 0);
  EXPECT_EQ(MinimalFractionDigits({2713576000, 2752341000}), 6);
  EXPECT_EQ(MinimalFractionDigits({2713584001, 2713594000}), 9);
  EXPECT_EQ(MinimalFractionDigits({1500000000, -250000000}), 2);
}

TEST(FormatDecimalSecondsTest, WritesTheRequestedDigits) {
  EXPECT_EQ(FormatDecimalSeconds(2713584001, 9), "2.713584001");
  EXPECT_EQ(FormatDecimalSeconds(2713576000, 6), "2.713576");
  EXPECT_EQ(FormatDecimalSeconds(5000000000, 0), "5");
  EXPECT_EQ(FormatDecimalSeconds(1, 9), "0.000000001");
  EXPECT_EQ(FormatDecimalSeconds(-1250000000, 2), "-1.25");
  EXPECT_EQ(FormatDecimalSeconds(INT64_MAX, 9), "9223372036.854775807");
  EXPECT_EQ(FormatDecimalSeconds(INT64_MIN, 9), "-9223372036.854775808");
}

TEST(FormatDecimalSecondsTest, RoundTripsThroughTheParser) {
  constexpr uint32_t kSeed = 11;
  constexpr int kSamples = 10000;
  std::mt19937_64 random(kSeed);
  std::uniform_int_distribution<int64_t> value(-INT64_MAX, INT64_MAX);
  for (int i = 0; i < kSamples; ++i) {
    const int64_t t_ns = value(random);
    int64_t parsed = 0;
    ASSERT_EQ(Parse(FormatDecimalSeconds(t_ns, kMaxFractionDigits), &parsed), DecimalStatus::kOk);
    ASSERT_EQ(parsed, t_ns);
  }
}

}  // namespace
}  // namespace evfs

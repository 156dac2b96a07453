#include "evfs/io/event_text.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "evfs/io/decimal_seconds.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

constexpr int kWidth = 240;
constexpr int kHeight = 180;

// Writes `content` as events.txt in a fresh scratch folder and returns its path.
std::string EventsFile(const std::string& test_name, const std::string& content) {
  const std::string path = test::ScratchDir(test_name) + "/events.txt";
  test::WriteFile(path, content);
  return path;
}

EventStream Expected(const std::vector<std::vector<int64_t>>& rows) {
  EventStream events(kWidth, kHeight);
  for (const auto& row : rows) {
    events.push_back(row[0], static_cast<uint16_t>(row[1]), static_cast<uint16_t>(row[2]),
                     static_cast<int8_t>(row[3]));
  }
  return events;
}

TEST(EventTextReaderTest, ParsesTimestampsExactlyToTheNanosecond) {
  const std::string path = EventsFile("exact", "2.713584001 44 159 1\n2.713594000 167 164 0\n");
  const EventStream events = ReadEventsText(path, kWidth, kHeight);
  EXPECT_EQ(events, Expected({{2713584001, 44, 159, 1}, {2713594000, 167, 164, -1}}));
}

TEST(EventTextReaderTest, AcceptsTheOdditiesOfRealFiles) {
  // Comments, blank lines, CRLF, tabs, extra blanks, -1/1 polarity, integer seconds, trailing
  // blanks and a last line without a newline.
  const std::string content =
      "# t x y p\n"
      "\n"
      "0.5 1 2 1\r\n"
      "  \t\r\n"
      "0.6\t3\t4\t0\n"
      "0.7  5   6  -1  \n"
      "# another comment 1 2 3\n"
      "1 7 8 1\r\n"
      "1.000000002 9 10 -1";
  const EventStream events = ReadEventsText(EventsFile("oddities", content), kWidth, kHeight);
  EXPECT_EQ(events, Expected({{500000000, 1, 2, 1},
                              {600000000, 3, 4, -1},
                              {700000000, 5, 6, -1},
                              {1000000000, 7, 8, 1},
                              {1000000002, 9, 10, -1}}));
}

TEST(EventTextReaderTest, EmptyAndCommentOnlyFilesHoldNoEvents) {
  EXPECT_TRUE(ReadEventsText(EventsFile("empty", ""), kWidth, kHeight).empty());
  EXPECT_TRUE(ReadEventsText(EventsFile("comments", "# nothing\n\n"), kWidth, kHeight).empty());
  const EventSummary summary = EventTextReader(EventsFile("empty_summary", "")).Summarize();
  EXPECT_EQ(summary.count, 0);
  EXPECT_EQ(summary.t_first_ns, 0);
  EXPECT_EQ(summary.t_last_ns, 0);
}

TEST(EventTextReaderTest, UnknownSensorSizeComesFromTheLargestCoordinates) {
  const EventStream events = ReadEventsText(EventsFile("sizeless", "0.1 10 3 1\n0.2 4 20 0\n"));
  EXPECT_EQ(events.width(), 11);
  EXPECT_EQ(events.height(), 21);
}

// One malformed line among valid ones: the error names the file, the 1-based line and what
// was expected.
struct MalformedCase {
  const char* name;
  const char* bad_line;
  InputError::Kind kind;
  const char* message_part;
};

class MalformedLineTest : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(MalformedLineTest, ThrowsNamingFileAndLine) {
  const MalformedCase& c = GetParam();
  // Line 3 is the bad one (after a comment and a valid event); a valid line follows.
  const std::string content = std::string("# header\n0.5 1 2 1\n") + c.bad_line + "\n0.9 1 2 1\n";
  const std::string path = EventsFile(std::string("malformed_") + c.name, content);
  test::ExpectInputError([&] { ReadEventsText(path, kWidth, kHeight); }, c.kind, path, 3);
  const InputError error = test::CatchInputError([&] { ReadEventsText(path, kWidth, kHeight); });
  EXPECT_NE(std::string(error.what()).find(c.message_part), std::string::npos) << error.what();
  // The summary parses the same lines and must fail the same way.
  test::ExpectInputError([&] { EventTextReader(path, kWidth, kHeight).Summarize(); }, c.kind, path,
                         3);
}

std::string CaseName(const ::testing::TestParamInfo<MalformedCase>& info) {
  return info.param.name;
}

constexpr InputError::Kind kMalformed = InputError::Kind::kMalformed;
constexpr InputError::Kind kOutOfRange = InputError::Kind::kOutOfRange;

INSTANTIATE_TEST_SUITE_P(FieldCount, MalformedLineTest,
                         ::testing::Values(MalformedCase{"one", "0.6", kMalformed, "found 1"},
                                           MalformedCase{"two", "0.6 1", kMalformed, "found 2"},
                                           MalformedCase{"three", "0.6 1 2", kMalformed, "found 3"},
                                           MalformedCase{"five", "0.6 1 2 1 7", kMalformed, "more"},
                                           MalformedCase{"cr", "0.6 1\r2 1", kMalformed,
                                                         "found 2"}),
                         CaseName);

INSTANTIATE_TEST_SUITE_P(
    NotANumber, MalformedLineTest,
    ::testing::Values(MalformedCase{"t_word", "abc 1 2 1", kMalformed, "'t'"},
                      MalformedCase{"t_suffix", "0.6s 1 2 1", kMalformed, "'t'"},
                      MalformedCase{"t_exponent", "6e-1 1 2 1", kMalformed, "'t'"},
                      MalformedCase{"t_nan", "nan 1 2 1", kMalformed, "'t'"},
                      MalformedCase{"t_inf", "inf 1 2 1", kMalformed, "'t'"},
                      MalformedCase{"x_word", "0.6 a 2 1", kMalformed, "'x'"},
                      MalformedCase{"x_nan", "0.6 nan 2 1", kMalformed, "'x'"}),
    CaseName);

INSTANTIATE_TEST_SUITE_P(
    NotAnInteger, MalformedLineTest,
    ::testing::Values(MalformedCase{"y_negative", "0.6 1 -2 1", kMalformed, "'y'"},
                      MalformedCase{"y_decimal", "0.6 1 2.5 1", kMalformed, "'y'"},
                      MalformedCase{"p_word", "0.6 1 2 on", kMalformed, "'p'"}),
    CaseName);

INSTANTIATE_TEST_SUITE_P(
    TooLarge, MalformedLineTest,
    ::testing::Values(MalformedCase{"t_digits", "0.6000000001 1 2 1", kMalformed, "fractional"},
                      MalformedCase{"t_overflow", "99999999999 1 2 1", kMalformed, "too large"},
                      MalformedCase{"x_overflow", "0.6 99999999999999999999 2 1", kOutOfRange,
                                    "x = 99999999999999999999"}),
    CaseName);

INSTANTIATE_TEST_SUITE_P(
    OutOfRange, MalformedLineTest,
    ::testing::Values(MalformedCase{"p_2", "0.6 1 2 2", kOutOfRange, "found 2"},
                      MalformedCase{"p_10", "0.6 1 2 10", kOutOfRange, "found 10"},
                      MalformedCase{"p_minus_2", "0.6 1 2 -2", kOutOfRange, "-2"},
                      MalformedCase{"x", "0.6 240 2 1", kOutOfRange, "below 240"},
                      MalformedCase{"y", "0.6 1 180 1", kOutOfRange, "below 180"}),
    CaseName);

INSTANTIATE_TEST_SUITE_P(Order, MalformedLineTest,
                         ::testing::Values(MalformedCase{"backwards", "0.4 1 2 1",
                                                         InputError::Kind::kNotMonotonic,
                                                         "must not decrease"}),
                         CaseName);

TEST(EventTextReaderTest, ErrorOnTheLastLineWithoutNewlineNamesItsLine) {
  const std::string path = EventsFile("last_line_error", "0.5 1 2 1\n0.6 1 2\n0.7 1 2 5");
  test::ExpectInputError([&] { ReadEventsText(path, kWidth, kHeight); },
                         InputError::Kind::kMalformed, path, 2);
  const std::string tail_path = EventsFile("tail_error", "0.5 1 2 1\n0.6 1 2 1\n0.7 1 2 5");
  test::ExpectInputError([&] { ReadEventsText(tail_path, kWidth, kHeight); },
                         InputError::Kind::kOutOfRange, tail_path, 3);
}

TEST(EventTextReaderTest, TruncatedLastLineIsMalformed) {
  // A file cut short while it was written: the last line lacks fields and its newline.
  const std::string path = EventsFile("truncated", "0.5 1 2 1\n0.6 1 2 1\n0.7 1");
  test::ExpectInputError([&] { ReadEventsText(path, kWidth, kHeight); },
                         InputError::Kind::kMalformed, path, 3);
  const InputError error = test::CatchInputError([&] { ReadEventsText(path, kWidth, kHeight); });
  EXPECT_NE(std::string(error.what()).find("found 2"), std::string::npos) << error.what();
}

TEST(EventTextReaderTest, MegabyteLinesGiveShortMessages) {
  constexpr size_t kMegabyte = 1 << 20;
  const struct {
    const char* name;
    std::string bad_line;
    InputError::Kind kind;
  } cases[] = {
      {"t_digits", std::string(kMegabyte, '7') + " 1 2 1", InputError::Kind::kMalformed},
      {"x_digits", "0.6 " + std::string(kMegabyte, '9') + " 2 1", InputError::Kind::kOutOfRange},
      {"p_word", "0.6 1 2 " + std::string(kMegabyte, 'p'), InputError::Kind::kMalformed},
      {"p_digits", "0.6 1 2 " + std::string(kMegabyte, '5'), InputError::Kind::kOutOfRange},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path =
        EventsFile(std::string("megabyte_") + c.name, "0.5 1 2 1\n" + c.bad_line + "\n");
    test::ExpectInputError([&] { ReadEventsText(path, kWidth, kHeight); }, c.kind, path, 2);
    test::ExpectShortPrintableMessage(
        test::CatchInputError([&] { ReadEventsText(path, kWidth, kHeight); }));
  }
}

TEST(EventTextReaderTest, BinaryGarbageIsMalformedWithAPrintableMessage) {
  // Every byte value but '\n' (NUL and control characters included), from a seeded generator,
  // after a control character so that the line is neither a comment nor a number.
  std::mt19937 random(17);
  std::uniform_int_distribution<int> byte(0, 255);
  std::string garbage = "\x01";
  while (garbage.size() < 4096) {
    const char c = static_cast<char>(byte(random));
    if (c != '\n') garbage += c;
  }
  for (const std::string& bad_line :
       {garbage, "0.6 1 2 " + garbage, std::string("0.6\x01 1 2 1")}) {
    const std::string path = EventsFile("binary", "0.5 1 2 1\n" + bad_line + "\n0.7 1 2 1\n");
    test::ExpectInputError([&] { ReadEventsText(path, kWidth, kHeight); },
                           InputError::Kind::kMalformed, path, 2);
    test::ExpectShortPrintableMessage(
        test::CatchInputError([&] { ReadEventsText(path, kWidth, kHeight); }));
  }
}

TEST(EventTextReaderTest, BytesInMemoryParseLikeTheFile) {
  const std::string content = "# t x y p\r\n0.5 1 2 1\n0.6 3 4 -1\n0.7 5 6 0";
  const std::string path = EventsFile("from_memory", content);
  const EventTextReader from_memory(
      MappedFile::FromMemory("memory/events.txt", content.data(), content.size()), kWidth, kHeight);
  EXPECT_EQ(from_memory.path(), "memory/events.txt");
  EXPECT_EQ(from_memory.ReadAll(), ReadEventsText(path, kWidth, kHeight));
  EXPECT_EQ(from_memory.Read(600000000, 700000000).size(), 1u);
  const std::string bad = "0.5 1 2 1\n0.6 1 2\n";
  test::ExpectInputError(
      [&] {
        EventTextReader(MappedFile::FromMemory("memory/bad.txt", bad.data(), bad.size())).ReadAll();
      },
      InputError::Kind::kMalformed, "memory/bad.txt", 2);
}

TEST(EventTextReaderTest, ErrorDeepInALargeFileNamesItsLine) {
  // Far from the start, so that the fast path and the line counting on error are both used.
  constexpr int kBadLine = 150001;
  EventStream events = test::MakeRandomEvents(3, kBadLine - 1, kWidth, kHeight, 1000000000, 20000);
  const std::string dir = test::ScratchDir("deep_error");
  WriteEventsText(dir + "/events.txt", events);
  const std::string path = dir + "/events.txt";
  test::WriteFile(path, test::ReadFile(path) + "9.5 1 2 1 1\n");
  test::ExpectInputError([&] { ReadEventsText(path, kWidth, kHeight); },
                         InputError::Kind::kMalformed, path, kBadLine);
}

// A file of 200k events; windows anywhere (empty, at the ends, inside, beyond) must equal
// slicing the full read.
TEST(EventTextReaderTest, WindowedReadEqualsSlicingTheFullRead) {
  constexpr int kCount = 200000;
  constexpr uint32_t kSeed = 5;
  const EventStream events =
      test::MakeRandomEvents(kSeed, kCount, kWidth, kHeight, 1000000000, 30000);
  const std::string dir = test::ScratchDir("windowed");
  const std::string path = dir + "/events.txt";
  // A comment in the middle of the file must not confuse the binary search.
  WriteEventsText(path, events.SliceIndex(0, kCount / 2));
  WriteEventsText(dir + "/second_half.txt", events.SliceIndex(kCount / 2, kCount));
  test::WriteFile(
      path, test::ReadFile(path) + "# half way\n\n" + test::ReadFile(dir + "/second_half.txt"));

  const EventTextReader reader(path, kWidth, kHeight);
  const EventStream all = reader.ReadAll();
  ASSERT_EQ(all, events);
  const int64_t first = all.first_t_ns();
  const int64_t last = all.last_t_ns();
  const std::vector<std::pair<int64_t, int64_t>> windows = {
      {first, last + 1},
      {first - 1000, first + 1},
      {last, last + 1},
      {last + 1, last + 1000},
      {0, first},
      {first + (last - first) / 2, first + (last - first) / 2 + 100000},
      {all.t_ns(kCount / 2), all.t_ns(kCount / 2 + 10)},
      {all.t_ns(1234), all.t_ns(1234)},  // empty
      {all.t_ns(777) + 1, all.t_ns(150000)},
      {all.t_ns(kCount - 3), all.t_ns(kCount - 1)},
  };
  for (const auto& window : windows) {
    EXPECT_EQ(reader.Read(window.first, window.second), all.Slice(window.first, window.second))
        << "window [" << window.first << ", " << window.second << ")";
  }
}

TEST(EventTextReaderTest, WindowedReadKeepsWholeRunsOfEqualTimestamps) {
  const std::string path = test::ScratchDir("windowed_runs") + "/events.txt";
  test::ExpectWindowsKeepWholeRuns(
      kWidth, kHeight, [&](const EventStream& events) { WriteEventsText(path, events); },
      [&](int64_t t_begin_ns, int64_t t_end_ns) {
        return EventTextReader(path, kWidth, kHeight).Read(t_begin_ns, t_end_ns);
      });
}

TEST(EventTextReaderTest, WindowedReadStillValidatesTheLinesItParses) {
  constexpr int kCount = 50000;
  const EventStream events = test::MakeRandomEvents(9, kCount, kWidth, kHeight, 1000000000, 30000);
  const std::string dir = test::ScratchDir("windowed_validation");
  const std::string path = dir + "/events.txt";
  WriteEventsText(dir + "/a.txt", events.SliceIndex(0, kCount / 2));
  WriteEventsText(dir + "/b.txt", events.SliceIndex(kCount / 2, kCount));
  test::WriteFile(path, test::ReadFile(dir + "/a.txt") + "oops\n" + test::ReadFile(dir + "/b.txt"));
  const EventTextReader reader(path, kWidth, kHeight);
  // A window across the bad line fails, naming it; a window far from it does not.
  const int64_t t_bad = events.t_ns(kCount / 2);
  test::ExpectInputError([&] { reader.Read(t_bad - 100000, t_bad + 100000); },
                         InputError::Kind::kMalformed, path, kCount / 2 + 1);
  EXPECT_EQ(reader.Read(events.t_ns(100), events.t_ns(200)),
            events.Slice(events.t_ns(100), events.t_ns(200)));
}

TEST(EventTextReaderTest, SummaryCountsEverything) {
  const EventStream events = test::MakeRandomEvents(21, 1000, kWidth, kHeight, 5000, 1000);
  const std::string path = test::ScratchDir("summary") + "/events.txt";
  WriteEventsText(path, events);
  const EventSummary summary = EventTextReader(path, kWidth, kHeight).Summarize();
  EXPECT_EQ(summary.count, 1000);
  EXPECT_EQ(summary.positive, static_cast<int64_t>(events.CountPositive()));
  EXPECT_EQ(summary.t_first_ns, events.first_t_ns());
  EXPECT_EQ(summary.t_last_ns, events.last_t_ns());
}

TEST(WriteEventsTextTest, UsesTheFewestDigitsAndZeroOnePolarity) {
  const std::string path = test::ScratchDir("write_digits") + "/events.txt";
  WriteEventsText(path, Expected({{2713576000, 1, 2, 1}, {2713580500, 3, 4, -1}}));
  EXPECT_EQ(test::ReadFile(path), "2.7135760 1 2 1\n2.7135805 3 4 0\n");
  WriteEventsText(path, EventStream(kWidth, kHeight));
  EXPECT_EQ(test::ReadFile(path), "");
}

TEST(WriteEventsTextTest, RoundTripsRandomEvents) {
  const EventStream events = test::MakeRandomEvents(4, 20000, kWidth, kHeight, 123456789, 50000);
  const std::string path = test::ScratchDir("write_roundtrip") + "/events.txt";
  WriteEventsText(path, events);
  EXPECT_EQ(ReadEventsText(path, kWidth, kHeight), events);
}

// The same events written with tabs, -1 polarity and CRLF take the general parser instead of
// the fast path for canonical lines; both must agree.
TEST(EventTextReaderTest, GeneralAndFastParsersAgree) {
  const EventStream events = test::MakeRandomEvents(6, 5000, kWidth, kHeight, 987654321, 5000);
  const std::string dir = test::ScratchDir("general_parser");
  std::string odd;
  for (size_t i = 0; i < events.size(); ++i) {
    odd += FormatDecimalSeconds(events.t_ns(i), kMaxFractionDigits) + "\t" +
           std::to_string(events.x(i)) + "\t" + std::to_string(events.y(i)) + "\t" +
           (events.polarity(i) > 0 ? "1" : "-1") + "\r\n";
  }
  test::WriteFile(dir + "/odd.txt", odd);
  WriteEventsText(dir + "/canonical.txt", events);
  EXPECT_EQ(ReadEventsText(dir + "/odd.txt", kWidth, kHeight), events);
  EXPECT_EQ(ReadEventsText(dir + "/canonical.txt", kWidth, kHeight), events);
}

TEST(WriteEventsTextTest, UnwritablePathIsAnInputError) {
  const std::string path = test::ScratchDir("write_unwritable") + "/missing/events.txt";
  test::ExpectInputError([&] { WriteEventsText(path, EventStream()); },
                         InputError::Kind::kUnwritable, path, 0);
}

// The shared DAVIS snippets: read, windowed reads, and a byte-identical rewrite.
TEST(EventTextReaderTest, SharedDataParsesWindowsAndRewritesByteIdentically) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  struct Snippet {
    const char* folder;
    int width;
    int height;
    size_t count;
  };
  const Snippet snippets[] = {{"slider_depth_70_71", 240, 180, 16418},
                              {"shapes_rotation_13_20", 240, 180, 108406},
                              {"eslnet_cups_blur", 346, 260, 413963}};
  for (const Snippet& snippet : snippets) {
    SCOPED_TRACE(snippet.folder);
    const std::string path = data_dir + "/" + snippet.folder + "/events.txt";
    const EventTextReader reader(path, snippet.width, snippet.height);
    const EventStream all = reader.ReadAll();
    ASSERT_EQ(all.size(), snippet.count);
    const int64_t span = all.last_t_ns() - all.first_t_ns();
    for (int k = 0; k < 10; ++k) {
      const int64_t begin = all.first_t_ns() + span * k / 10;
      const int64_t end = begin + span / 7;
      ASSERT_EQ(reader.Read(begin, end), all.Slice(begin, end)) << "window " << k;
    }
    const std::string rewritten =
        test::ScratchDir(std::string("rewrite_") + snippet.folder) + "/e.txt";
    WriteEventsText(rewritten, all);
    EXPECT_TRUE(test::ReadFile(rewritten) == test::ReadFile(path))
        << "rewrite differs from " << path;
  }
}

}  // namespace
}  // namespace evfs

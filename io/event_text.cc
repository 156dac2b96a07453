#include "evfs/io/event_text.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "evfs/io/decimal_seconds.h"
#include "evfs/io/message_excerpt.h"
#include "evfs/io/text_file_writer.h"

namespace evfs {
namespace {

// Coordinates are stored as uint16.
constexpr uint32_t kCoordinateLimit = 65536;
// Below this many bytes between the binary-search bounds, parsing linearly is cheaper than
// probing further (a few hundred lines).
constexpr size_t kLinearScanBytes = 16 * 1024;
// Bytes sampled from the start of the file to estimate the line count for reserve().
constexpr size_t kLineLengthSampleBytes = 64 * 1024;

inline bool IsBlank(char c) { return c == ' ' || c == '\t'; }
inline bool IsLineEnd(char c) { return c == '\n' || c == '\r'; }
inline const char* SkipBlanks(const char* p) {
  while (IsBlank(*p)) ++p;
  return p;
}

const char* const kFieldNames[] = {"t", "x", "y", "p"};
constexpr int kFieldCount = 4;

// The fast path below handles lines of the canonical form `ddd.ddddddddd x y p\n` (single
// spaces, p in {0, 1}, optional '\r') with branch-free SWAR digit parsing: it loads 8 bytes per
// field. The longest canonical line it accepts is 7 + 1 + 9 + 1 + 5 + 1 + 5 + 1 + 1 + 2 = 33
// bytes, so 8-byte loads stay inside the buffer when a line starts this far before its end.
// Anything else (comments, blank lines, tabs, -1 polarity, errors) goes to the general parser.
constexpr size_t kFastPathMargin = 48;

inline uint64_t Load8(const char* p) {
  uint64_t chunk;
  std::memcpy(&chunk, p, sizeof(chunk));
  return chunk;
}

// Number of leading ASCII digits among the 8 bytes of `chunk` (memory order, little endian).
inline int LeadingDigits(uint64_t chunk) {
  constexpr uint64_t kHighNibbles = 0xF0F0F0F0F0F0F0F0ULL;
  constexpr uint64_t kZeros = 0x3030303030303030ULL;
  // A byte is a digit when its high nibble is 3 and adding 6 keeps it there (low nibble <= 9).
  // The +6 can carry only out of a non-digit byte, which only disturbs bytes after it.
  const uint64_t not_digit = ((chunk & kHighNibbles) ^ kZeros) |
                             (((chunk + 0x0606060606060606ULL) & kHighNibbles) ^ kZeros);
  return not_digit == 0 ? 8 : __builtin_ctzll(not_digit) >> 3;
}

// Value of the first `count` (1..8) digits of `chunk`.
inline uint64_t DigitsValue(uint64_t chunk, int count) {
  // Shift the digits to the top bytes; the zero bytes shifted in act as leading zeros.
  chunk <<= 8 * (8 - count);
  chunk = ((chunk & 0x0F0F0F0F0F0F0F0FULL) * 2561) >> 8;
  chunk = ((chunk & 0x00FF00FF00FF00FFULL) * 6553601) >> 16;
  return ((chunk & 0x0000FFFF0000FFFFULL) * 42949672960001ULL) >> 32;
}

// Parses an unsigned field of 1..max_digits digits followed by one space; false otherwise.
inline bool ParseCanonicalUnsigned(const char** p, int max_digits, uint64_t* value) {
  const uint64_t chunk = Load8(*p);
  const int digits = LeadingDigits(chunk);
  if (digits == 0 || digits > max_digits || (*p)[digits] != ' ') return false;
  *value = DigitsValue(chunk, digits);
  *p += digits + 1;
  return true;
}

}  // namespace

struct EventTextReader::Segment {
  const char* begin;
  const char* end;     // one past a '\n'
  size_t file_offset;  // where `begin` lies in the file
};

struct EventTextReader::ParsedEvent {
  int64_t t_ns;
  uint32_t x;
  uint32_t y;
  int polarity;
};

inline bool EventTextReader::ParseCanonicalLine(const char** line, uint32_t x_limit,
                                                uint32_t y_limit, ParsedEvent* event) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  const char* p = *line;
  // Seconds: at most 7 integer digits (115 days), so seconds * 1e9 stays far below int64 max.
  uint64_t seconds;
  uint64_t chunk = Load8(p);
  int digits = LeadingDigits(chunk);
  if (digits == 0 || digits > 7 || p[digits] != '.') return false;
  seconds = DigitsValue(chunk, digits);
  p += digits + 1;
  chunk = Load8(p);
  digits = LeadingDigits(chunk);
  if (digits == 0) return false;
  uint64_t fraction = DigitsValue(chunk, digits);
  p += digits;
  if (digits == 8 && internal::IsDigit(*p)) {
    fraction = fraction * 10 + static_cast<uint64_t>(*p++ - '0');
    ++digits;
  }
  if (*p++ != ' ') return false;  // also rejects a 10th fractional digit
  event->t_ns = static_cast<int64_t>(
      seconds * 1000000000ULL +
      fraction * static_cast<uint64_t>(internal::kPowersOfTen[kMaxFractionDigits - digits]));

  uint64_t x;
  uint64_t y;
  if (!ParseCanonicalUnsigned(&p, 5, &x) || !ParseCanonicalUnsigned(&p, 5, &y)) return false;
  if (x >= x_limit || y >= y_limit) return false;
  event->x = static_cast<uint32_t>(x);
  event->y = static_cast<uint32_t>(y);

  if (*p != '0' && *p != '1') return false;
  event->polarity = *p == '1' ? 1 : -1;
  ++p;
  if (*p == '\r') ++p;
  if (*p != '\n') return false;
  *line = p + 1;
  return true;
#else
  (void)line;
  (void)x_limit;
  (void)y_limit;
  (void)event;
  return false;
#endif
}

EventTextReader::EventTextReader(const std::string& path, int width, int height)
    : EventTextReader(MappedFile(path), width, height) {}

EventTextReader::EventTextReader(MappedFile file, int width, int height)
    : file_(std::move(file)), width_(width), height_(height) {
  const char* data = file_.data();
  size_t size = file_.size();
  while (size > 0 && data[size - 1] != '\n') --size;
  body_size_ = size;
  if (body_size_ < file_.size()) {
    tail_.assign(data + body_size_, file_.size() - body_size_);
    tail_.push_back('\n');
  }
}

void EventTextReader::Fail(InputError::Kind kind, size_t line_offset,
                           const std::string& expected) const {
  // Line numbers are only needed here, so they are counted here rather than while parsing.
  const size_t counted = std::min(line_offset, body_size_);
  const int64_t line = 1 + std::count(file_.data(), file_.data() + counted, '\n');
  throw InputError(kind, file_.path(), line, expected);
}

void EventTextReader::FailPolarity(size_t line_offset, const char* polarity_begin) const {
  const char* token_end = polarity_begin;
  while (!IsBlank(*token_end) && !IsLineEnd(*token_end)) ++token_end;
  const std::string token(polarity_begin, token_end);
  const std::string excerpt = MessageExcerpt(token);
  if (token == "1" || token == "0" || token == "-1") {
    Fail(InputError::Kind::kMalformed, line_offset,
         "expected " + std::to_string(kFieldCount) + " fields 't x y p', found more");
  }
  const size_t sign = token[0] == '-' ? 1 : 0;
  const bool is_integer =
      token.size() > sign && std::all_of(token.begin() + sign, token.end(), internal::IsDigit);
  if (is_integer) {
    Fail(InputError::Kind::kOutOfRange, line_offset,
         "polarity must be -1, 0 or 1, found " + excerpt);
  }
  Fail(InputError::Kind::kMalformed, line_offset,
       "field 'p': expected -1, 0 or 1, found '" + excerpt + "'");
}

const char* EventTextReader::ParseLine(const char* p, size_t line_offset, uint32_t x_limit,
                                       uint32_t y_limit, ParsedEvent* event, bool* is_event) const {
  const auto fail_count = [&](int found) {
    Fail(InputError::Kind::kMalformed, line_offset,
         "expected " + std::to_string(kFieldCount) + " fields 't x y p', found " +
             std::to_string(found));
  };
  const auto fail_value = [&](int field, const std::string& what) {
    Fail(InputError::Kind::kMalformed, line_offset,
         std::string("field '") + kFieldNames[field] + "': " + what);
  };

  *is_event = false;
  p = SkipBlanks(p);
  if (*p == '#') {
    while (*p != '\n') ++p;  // every buffer parsed ends with '\n'
    return p + 1;
  }
  if (*p == '\r' && p[1] == '\n') ++p;
  if (*p == '\n') return p + 1;

  DecimalStatus status;
  p = ParseDecimalSeconds(p, &event->t_ns, &status);
  if (status != DecimalStatus::kOk) fail_value(0, DescribeDecimalStatus(status));
  if (!IsBlank(*p)) {
    if (IsLineEnd(*p)) fail_count(1);
    fail_value(0, DescribeDecimalStatus(DecimalStatus::kNotANumber));
  }

  uint32_t* const coordinates[] = {&event->x, &event->y};
  const uint32_t limits[] = {x_limit, y_limit};
  for (int i = 0; i < 2; ++i) {
    const int field = 1 + i;
    p = SkipBlanks(p);
    if (IsLineEnd(*p)) fail_count(field);
    const char* const digits = p;
    uint64_t value = 0;
    while (internal::IsDigit(*p)) value = value * 10 + static_cast<uint64_t>(*p++ - '0');
    if (p == digits || !IsBlank(*p)) {
      if (p != digits && IsLineEnd(*p)) fail_count(field + 1);
      fail_value(field, "expected a non-negative integer");
    }
    // More than 9 digits could overflow `value`; such a number is out of range anyway.
    if (p - digits > 9 || value >= limits[i]) {
      Fail(InputError::Kind::kOutOfRange, line_offset,
           std::string(kFieldNames[field]) + " = " + MessageExcerpt(digits, p) +
               " is outside the sensor (" + kFieldNames[field] + " must be below " +
               std::to_string(limits[i]) + ")");
    }
    *coordinates[i] = static_cast<uint32_t>(value);
  }

  p = SkipBlanks(p);
  if (IsLineEnd(*p)) fail_count(3);
  const char* const polarity_begin = p;
  if (*p == '1') {
    event->polarity = 1;
    ++p;
  } else if (*p == '0') {
    event->polarity = -1;
    ++p;
  } else if (*p == '-' && p[1] == '1') {
    event->polarity = -1;
    p += 2;
  }
  const bool ends_field = p != polarity_begin && (IsBlank(*p) || IsLineEnd(*p));
  p = SkipBlanks(p);
  if (*p == '\r') ++p;
  if (!ends_field || *p != '\n') FailPolarity(line_offset, polarity_begin);
  *is_event = true;
  return p + 1;
}

template <typename Visitor>
void EventTextReader::Scan(size_t start_offset, Visitor&& visit) const {
  const Segment segments[] = {
      {file_.data(), file_.data() + body_size_, 0},
      {tail_.data(), tail_.data() + tail_.size(), body_size_},
  };
  const uint32_t x_limit = width_ > 0 ? static_cast<uint32_t>(width_) : kCoordinateLimit;
  const uint32_t y_limit = height_ > 0 ? static_cast<uint32_t>(height_) : kCoordinateLimit;
  bool has_previous = false;
  int64_t previous_t_ns = 0;

  for (const Segment& segment : segments) {
    const size_t segment_size = static_cast<size_t>(segment.end - segment.begin);
    if (start_offset >= segment.file_offset + segment_size) continue;
    const char* p = segment.begin +
                    (start_offset > segment.file_offset ? start_offset - segment.file_offset : 0);
    // The fast path reads 8 bytes at a time up to kCanonicalLineBytes past a line start.
    const char* const fast_end =
        segment_size > kFastPathMargin ? segment.end - kFastPathMargin : segment.begin;
    while (p < segment.end) {
      const char* const line = p;
      ParsedEvent event;
      if (!(p < fast_end && ParseCanonicalLine(&p, x_limit, y_limit, &event))) {
        bool is_event;
        p = ParseLine(line, segment.file_offset + static_cast<size_t>(line - segment.begin),
                      x_limit, y_limit, &event, &is_event);
        if (!is_event) continue;
      }
      if (has_previous && event.t_ns < previous_t_ns) {
        Fail(InputError::Kind::kNotMonotonic,
             segment.file_offset + static_cast<size_t>(line - segment.begin),
             "timestamps must not decrease: " +
                 FormatDecimalSeconds(event.t_ns, kMaxFractionDigits) + " s follows " +
                 FormatDecimalSeconds(previous_t_ns, kMaxFractionDigits) + " s");
      }
      has_previous = true;
      previous_t_ns = event.t_ns;
      if (!visit(event)) return;
    }
  }
}

size_t EventTextReader::FindScanStart(int64_t t_ns) const {
  // Invariant: the first event with t >= t_ns starts at or after `low`, and either before `high`
  // or at the first event line starting at or after `high`.
  size_t low = 0;
  size_t high = body_size_;
  while (high - low > kLinearScanBytes) {
    const size_t middle = low + (high - low) / 2;
    const char* newline = static_cast<const char*>(
        std::memchr(file_.data() + middle - 1, '\n', body_size_ - (middle - 1)));
    const size_t line_start = static_cast<size_t>(newline - file_.data()) + 1;
    bool found = false;
    int64_t probe_t_ns = 0;
    if (line_start < body_size_) {
      Scan(line_start, [&](const ParsedEvent& event) {
        found = true;
        probe_t_ns = event.t_ns;
        return false;
      });
    }
    if (found && probe_t_ns < t_ns) {
      low = line_start;  // every event before the probe is earlier still
    } else {
      high = middle;
    }
  }
  return low;
}

EventStream EventTextReader::Collect(size_t start_offset, bool windowed, int64_t t_begin_ns,
                                     int64_t t_end_ns, size_t expected_count) const {
  EventStream events(width_, height_);
  events.reserve(expected_count);
  int max_x = -1;
  int max_y = -1;
  Scan(start_offset, [&](const ParsedEvent& event) {
    if (windowed && event.t_ns < t_begin_ns) return true;
    if (windowed && event.t_ns >= t_end_ns) return false;
    events.push_back(event.t_ns, static_cast<uint16_t>(event.x), static_cast<uint16_t>(event.y),
                     static_cast<int8_t>(event.polarity));
    max_x = std::max(max_x, static_cast<int>(event.x));
    max_y = std::max(max_y, static_cast<int>(event.y));
    return true;
  });
  if (width_ <= 0 || height_ <= 0) events.set_sensor_size(max_x + 1, max_y + 1);
  return events;
}

EventStream EventTextReader::ReadAll() const {
  // Reserve for the line count estimated from the first bytes, with 5% headroom: lines further
  // down are rarely much shorter than the first ones.
  const size_t sample = std::min(body_size_, kLineLengthSampleBytes);
  const int64_t sample_lines = std::count(file_.data(), file_.data() + sample, '\n');
  const size_t expected_count =
      sample_lines > 0
          ? static_cast<size_t>(1.05 * static_cast<double>(body_size_) * sample_lines / sample) + 1
          : 0;
  return Collect(0, /*windowed=*/false, 0, 0, expected_count);
}

EventStream EventTextReader::Read(int64_t t_begin_ns, int64_t t_end_ns) const {
  // An empty window stops at the first event at or after t_begin_ns, as it should.
  return Collect(FindScanStart(t_begin_ns), /*windowed=*/true, t_begin_ns, t_end_ns, 0);
}

EventSummary EventTextReader::Summarize() const {
  EventSummary summary;
  Scan(0, [&](const ParsedEvent& event) {
    summary.Add(event.t_ns, static_cast<int>(event.x), static_cast<int>(event.y), event.polarity);
    return true;
  });
  return summary;
}

EventStream ReadEventsText(const std::string& path, int width, int height) {
  return EventTextReader(path, width, height).ReadAll();
}

void WriteEventsText(const std::string& path, const EventStream& events) {
  const int fraction_digits = MinimalFractionDigits(events.t_ns());
  TextFileWriter writer(path);
  for (size_t i = 0; i < events.size(); ++i) {
    char* const line = writer.Reserve();
    char* p = line + FormatDecimalSeconds(events.t_ns(i), fraction_digits, line);
    *p++ = ' ';
    p = internal::FormatUnsigned(events.x(i), p);
    *p++ = ' ';
    p = internal::FormatUnsigned(events.y(i), p);
    *p++ = ' ';
    *p++ = events.polarity(i) > 0 ? '1' : '0';
    *p++ = '\n';
    writer.Commit(static_cast<size_t>(p - line));
  }
  writer.Close();
}

}  // namespace evfs

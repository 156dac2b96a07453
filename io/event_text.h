// events.txt of the Event Camera Dataset layout: one event per line, `t x y p`, with t in
// decimal seconds, x and y in pixels and p in {0, 1} (or {-1, 1}); 0 and -1 both mean darker.
// Blank lines and lines starting with '#' are skipped, CRLF line ends and a last line without a
// newline are accepted; anything else that does not parse is an InputError naming the line.
#ifndef EVFS_IO_EVENT_TEXT_H_
#define EVFS_IO_EVENT_TEXT_H_

#include <cstdint>
#include <string>

#include "evfs/core/error.h"
#include "evfs/core/event_stream.h"
#include "evfs/io/data_source.h"
#include "evfs/io/mapped_file.h"

namespace evfs {

/// Reads events.txt from a memory-mapped file with a hand-written parser (tens of millions of
/// events per second on one core). Every line parsed is validated: field count, numbers,
/// polarity, coordinates inside the sensor and non-decreasing timestamps.
class EventTextReader {
 public:
  /// Maps `path`. A sensor size of 0 x 0 means unknown: coordinates are then only checked
  /// against the uint16 range, and the streams returned are sized to the largest coordinate
  /// they hold plus one. Throws InputError(kMissingFile).
  explicit EventTextReader(const std::string& path, int width = 0, int height = 0);
  /// Reads the bytes of `file` (see MappedFile::FromMemory), which it keeps.
  explicit EventTextReader(MappedFile file, int width = 0, int height = 0);

  const std::string& path() const { return file_.path(); }

  /// Every event in the file.
  EventStream ReadAll() const;
  /// The events with t_begin_ns <= t < t_end_ns. Finds the first one by binary search over
  /// byte offsets, so only the lines near the window are parsed (and validated).
  EventStream Read(int64_t t_begin_ns, int64_t t_end_ns) const;
  /// Counts and ranges of every event in the file, keeping none of them.
  EventSummary Summarize() const;

 private:
  struct Segment;
  struct ParsedEvent;

  // Parses one line of the canonical form (see event_text.cc) starting at *line and moves
  // *line past it; false, leaving *line alone, for any other line.
  static bool ParseCanonicalLine(const char** line, uint32_t x_limit, uint32_t y_limit,
                                 ParsedEvent* event);
  // Parses any line starting at `line` (lying at byte `line_offset` of the file), throwing
  // InputError when it is malformed; *is_event is false for blank and comment lines. Returns
  // the start of the next line.
  const char* ParseLine(const char* line, size_t line_offset, uint32_t x_limit, uint32_t y_limit,
                        ParsedEvent* event, bool* is_event) const;
  // Parses the event lines from the line starting at byte `start_offset` on, calling
  // `visit(event)` for each until it returns false or the file ends.
  template <typename Visitor>
  void Scan(size_t start_offset, Visitor&& visit) const;
  // A line start from which scanning finds the first event with t >= t_ns (binary search).
  size_t FindScanStart(int64_t t_ns) const;
  // The events parsed from `start_offset` on (only those in [t_begin_ns, t_end_ns) when
  // `windowed`), in a stream of the sensor size or, when that is unknown, of the largest
  // coordinates plus one.
  EventStream Collect(size_t start_offset, bool windowed, int64_t t_begin_ns, int64_t t_end_ns,
                      size_t expected_count) const;
  [[noreturn]] void Fail(InputError::Kind kind, size_t line_offset,
                         const std::string& expected) const;
  // Says why the polarity field at `polarity_begin` (or what follows it) is not accepted.
  [[noreturn]] void FailPolarity(size_t line_offset, const char* polarity_begin) const;

  MappedFile file_;
  int width_;
  int height_;
  // The file up to and including its last '\n' is parsed in place; whatever follows (a last
  // line without a newline) is copied here with a '\n' appended, so that the parser never
  // needs an end-of-buffer check inside a line.
  size_t body_size_ = 0;
  std::string tail_;
};

/// Reads a whole events.txt; see EventTextReader.
EventStream ReadEventsText(const std::string& path, int width = 0, int height = 0);

/// Writes `events` as events.txt with polarity as 0/1 and t printed with the fewest fractional
/// digits that keep every timestamp exact (MinimalFractionDigits), so that a file written with
/// a uniform digit count comes back byte-identical. Throws InputError(kUnwritable).
void WriteEventsText(const std::string& path, const EventStream& events);

}  // namespace evfs

#endif  // EVFS_IO_EVENT_TEXT_H_

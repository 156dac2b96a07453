// libFuzzer target: events.txt through EventTextReader (io/event_text.h), the parser with the
// hand-written fast path. The reader is handed the input bytes themselves (MappedFile::
// FromMemory), so AddressSanitizer sees any read past their end. Every input must give events
// or an evfs::Error whose message is one short line. When the whole file parses, the reader's
// other answers must agree with it: the summary, windowed reads (which binary-search the file
// instead of parsing it whole) and a rewrite with WriteEventsText read back.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/io/event_text.h"
#include "evfs/io/mapped_file.h"
#include "evfs/tests/fuzz/fuzz_util.h"

namespace evfs {
namespace fuzzing {
namespace {

// The name errors give the input.
constexpr char kInputName[] = "fuzz/events.txt";

// Both ways the CLI reads: with the sensor size of the seeds' DAVIS 240x180 (coordinates
// checked against it) and with an unknown size (taken from the events).
constexpr int kSensorSizes[][2] = {{240, 180}, {0, 0}};

void CheckWindows(const EventTextReader& reader, const EventStream& all) {
  // Windows between the events at 0, 1/4, ..., 4/4 of the file, starting at an event or 1 ns
  // after it, the last ones ending just after the last event.
  const size_t last = all.size() - 1;
  for (size_t i = 0; i <= 4; ++i) {
    for (size_t j = i; j <= 4; ++j) {
      const int64_t begin = all.t_ns(i * last / 4);
      const int64_t end = j == 4 ? After(all.last_t_ns()) : all.t_ns(j * last / 4);
      for (const int64_t from : {begin, After(begin)}) {
        EventStream window = reader.Read(from, end);
        // Without a sensor size, each read is sized to its own events (event_text.h).
        window.set_sensor_size(all.width(), all.height());
        Require(window == all.Slice(from, end),
                "a windowed read differs from slicing the full read");
      }
    }
  }
}

// Reads the input with one sensor size; true, with the events in *all, when it parses.
bool ReadWithSensorSize(const uint8_t* data, size_t size, int width, int height, EventStream* all) {
  const EventTextReader reader(
      MappedFile::FromMemory(kInputName, reinterpret_cast<const char*>(data), size), width, height);
  try {
    *all = reader.ReadAll();
  } catch (const Error& error) {
    CheckMessage(error, kInputName);
    // The summary parses the same lines, so it must fail as well.
    bool summary_failed = false;
    try {
      reader.Summarize();
    } catch (const Error&) {
      summary_failed = true;
    }
    Require(summary_failed, "the summary accepts a file the full read rejects");
    return false;
  }
  Require(reader.Summarize().count == static_cast<int64_t>(all->size()),
          "the summary counts other events than the full read");
  if (!all->empty()) CheckWindows(reader, *all);
  return true;
}

void FuzzEventsText(const uint8_t* data, size_t size) {
  static const FuzzInputFile rewritten("rewritten_events.txt");
  EventStream parsed;
  bool any_parsed = false;
  for (const auto& sensor : kSensorSizes) {
    EventStream events;
    if (ReadWithSensorSize(data, size, sensor[0], sensor[1], &events) && !any_parsed) {
      parsed = std::move(events);
      any_parsed = true;
    }
  }
  if (!any_parsed) return;
  WriteEventsText(rewritten.path(), parsed);
  Require(ReadEventsText(rewritten.path(), parsed.width(), parsed.height()) == parsed,
          "events written by WriteEventsText read back differently");
}

}  // namespace
}  // namespace fuzzing
}  // namespace evfs

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  evfs::fuzzing::FuzzEventsText(data, size);
  return 0;
}

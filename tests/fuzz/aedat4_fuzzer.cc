// libFuzzer target: AEDAT 4.0 recordings through Aedat4DataSource (io/aedat4.h). The reader is
// handed the input bytes themselves (FromMemory), so AddressSanitizer sees any read past their
// end. Every input must give a recording or an evfs::Error whose message is one short line. For
// a recording that opens, every frame and all events are read (each either works or is an
// evfs::Error); when all events read, the summary and windowed reads (a binary search over the
// packets' time spans, decompressing only some of them) must agree with them, and a rewrite
// with WriteAedat4 must read back the same.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/aedat4.h"
#include "evfs/tests/fuzz/fuzz_util.h"

namespace evfs {
namespace fuzzing {
namespace {

// The name errors give the input.
constexpr char kInputName[] = "fuzz/recording.aedat4";

// Writes what was read and reads it back: the writer must take any recording the reader gives
// (8-bit frames with distinct microsecond times, events on whole microseconds).
void CheckRewrite(const Aedat4DataSource& source, const EventStream& all,
                  const std::vector<Image>& images) {
  static const FuzzInputFile rewritten("rewritten.aedat4");
  try {
    WriteAedat4(rewritten.path(), all, source.frames(), images);
  } catch (const Error& error) {
    std::fprintf(stderr, "WriteAedat4 refused: %s\n", error.what());
    Require(false, "WriteAedat4 refuses a recording the reader gave");
  }
  const Aedat4DataSource again(rewritten.path());
  Require(again.ReadAllEvents() == all, "events written by WriteAedat4 read back differently");
  Require(again.frames().size() == source.frames().size(),
          "frames written by WriteAedat4 read back differently");
  for (size_t i = 0; i < images.size(); ++i) {
    const FrameInfo& a = again.frames()[i];
    const FrameInfo& b = source.frames()[i];
    Require(a.t_ns == b.t_ns && a.has_exposure == b.has_exposure &&
                a.exposure_begin_ns == b.exposure_begin_ns &&
                a.exposure_end_ns == b.exposure_end_ns,
            "frame times written by WriteAedat4 read back differently");
    Require((again.ReadImage(static_cast<int>(i)) == images[i]).all(),
            "frame pixels written by WriteAedat4 read back differently");
  }
}

void FuzzRecording(const uint8_t* data, size_t size) {
  try {
    const auto source =
        Aedat4DataSource::FromMemory(kInputName, reinterpret_cast<const char*>(data), size);
    std::vector<Image> images;
    bool all_images = true;
    for (int i = 0; i < static_cast<int>(source->frames().size()); ++i) {
      try {
        images.push_back(source->ReadImage(i));
      } catch (const Error& error) {
        CheckMessage(error, kInputName);
        all_images = false;
      }
    }
    if (!source->has_events()) return;
    const EventStream all = source->ReadAllEvents();
    CheckSummaryAndWindows(*source, all);
    if (all_images) CheckRewrite(*source, all, images);
  } catch (const Error& error) {
    CheckMessage(error, kInputName);
  }
}

}  // namespace
}  // namespace fuzzing
}  // namespace evfs

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  evfs::fuzzing::FuzzRecording(data, size);
  return 0;
}

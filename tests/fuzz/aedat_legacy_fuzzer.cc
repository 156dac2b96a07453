// libFuzzer target: AEDAT 2.0 and 3.1 recordings through AedatLegacyDataSource
// (io/aedat_legacy.h). The reader is handed the input bytes themselves (FromMemory), so
// AddressSanitizer sees any read past their end. Every input must give a recording or an
// evfs::Error whose message is one short line. For a recording that opens, every frame and all
// events are read (each either works or is an evfs::Error); when all events read, the summary
// and windowed reads (a binary search over the records, or over the packets' time spans) must
// agree with them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "evfs/core/error.h"
#include "evfs/io/aedat_legacy.h"
#include "evfs/tests/fuzz/fuzz_util.h"

namespace evfs {
namespace fuzzing {
namespace {

// The name errors give the input.
constexpr char kInputName[] = "fuzz/recording.aedat";

void FuzzRecording(const uint8_t* data, size_t size) {
  try {
    const auto source =
        AedatLegacyDataSource::FromMemory(kInputName, reinterpret_cast<const char*>(data), size);
    for (int i = 0; i < static_cast<int>(source->frames().size()); ++i) {
      try {
        const Image image = source->ReadImage(i);
        Require(image.rows() == source->height() && image.cols() == source->width(),
                "a frame of another size than the sensor");
      } catch (const Error& error) {
        CheckMessage(error, kInputName);
      }
    }
    CheckSummaryAndWindows(*source, source->ReadAllEvents());
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

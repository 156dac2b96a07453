// libFuzzer target: ROS 1 bags through RosbagDataSource (io/rosbag.h). rosbag_storage opens
// bags by path, so the input is written to a tmpfs file first. Every input must give a
// recording or an evfs::Error whose message is one short line, never a crash inside
// rosbag_storage (CheckBagStructure and the chunk checks stand before it). For a bag that opens,
// every frame and all events are read (each either works or is an evfs::Error); when all events
// read, the summary and windowed reads (a query on receive times, widened until complete) must
// agree with them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "evfs/core/error.h"
#include "evfs/io/rosbag.h"
#include "evfs/tests/fuzz/fuzz_util.h"

namespace evfs {
namespace fuzzing {
namespace {

void FuzzBag(const uint8_t* data, size_t size) {
  static const FuzzInputFile input("recording.bag");
  const std::string& path = input.Write(data, size);
  try {
    const RosbagDataSource source(path);
    for (int i = 0; i < static_cast<int>(source.frames().size()); ++i) {
      try {
        const Image image = source.ReadImage(i);
        Require(image.rows() == source.height() && image.cols() == source.width(),
                "a frame of another size than the sensor");
      } catch (const Error& error) {
        CheckMessage(error, path);
      }
    }
    CheckSummaryAndWindows(source, source.ReadAllEvents());
  } catch (const Error& error) {
    CheckMessage(error, path);
  }
}

}  // namespace
}  // namespace fuzzing
}  // namespace evfs

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  evfs::fuzzing::FuzzBag(data, size);
  return 0;
}

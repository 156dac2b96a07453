// libFuzzer target: images.txt and exposures.txt through ReadFrameList and ReadExposures
// (io/frame_list.h), read from memory. An input is images.txt, a NUL byte and exposures.txt
// (without a NUL, the whole input is read as both). Every input must give frames or an
// evfs::Error whose message is one short line, and what is read must survive being written
// with WriteFrameList and WriteExposures and read back.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/frame_list.h"
#include "evfs/tests/fuzz/fuzz_util.h"

namespace evfs {
namespace fuzzing {
namespace {

// The names errors give the inputs.
constexpr char kImagesName[] = "fuzz/images.txt";
constexpr char kExposuresName[] = "fuzz/exposures.txt";

// Frames named as in the Event Camera Dataset, for exposures.txt inputs to refer to.
std::vector<FrameInfo> DatasetFrames() {
  constexpr int kFrames = 16;
  std::vector<FrameInfo> frames(kFrames);
  for (int i = 0; i < kFrames; ++i) {
    char path[48];
    std::snprintf(path, sizeof(path), "images/frame_%08d.png", i);
    frames[i].t_ns = 1000000000LL * (i + 1);
    frames[i].path = path;
  }
  return frames;
}

// Reads images.txt; the frames read, or DatasetFrames() when it is rejected.
std::vector<FrameInfo> FuzzFrameList(const std::string& images_txt,
                                     const FuzzInputFile& rewritten) {
  std::vector<FrameInfo> frames;
  try {
    std::istringstream stream(images_txt);
    frames = ReadFrameList(stream, kImagesName);
  } catch (const Error& error) {
    CheckMessage(error, kImagesName);
    return DatasetFrames();
  }
  WriteFrameList(rewritten.path(), frames);
  Require(ReadFrameList(rewritten.path()) == frames,
          "frames written by WriteFrameList read back differently");
  return frames;
}

void FuzzExposures(const std::string& exposures_txt, const FuzzInputFile& rewritten,
                   std::vector<FrameInfo> frames) {
  const std::vector<FrameInfo> without_exposures = frames;
  try {
    std::istringstream stream(exposures_txt);
    ReadExposures(stream, kExposuresName, &frames);
  } catch (const Error& error) {
    CheckMessage(error, kExposuresName);
    return;
  }
  WriteExposures(rewritten.path(), frames);
  std::vector<FrameInfo> read_back = without_exposures;
  ReadExposures(rewritten.path(), &read_back);
  Require(read_back == frames, "exposures written by WriteExposures read back differently");
}

void FuzzFrameLists(const uint8_t* data, size_t size) {
  static const FuzzInputFile rewritten("rewritten_list.txt");
  const char* const text = reinterpret_cast<const char*>(data);
  const char* const separator = static_cast<const char*>(std::memchr(text, 0, size));
  const std::string images_txt(text, separator != nullptr ? separator : text + size);
  const std::string exposures_txt =
      separator != nullptr ? std::string(separator + 1, text + size) : images_txt;
  FuzzExposures(exposures_txt, rewritten, FuzzFrameList(images_txt, rewritten));
}

}  // namespace
}  // namespace fuzzing
}  // namespace evfs

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  evfs::fuzzing::FuzzFrameLists(data, size);
  return 0;
}

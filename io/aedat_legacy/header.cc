#include "evfs/io/aedat_legacy/header.h"

#include <algorithm>
#include <cctype>
#include <cstring>

#include "evfs/core/error.h"
#include "evfs/io/aedat_legacy/format.h"

namespace evfs {
namespace aedat_legacy {
namespace {

struct Chip {
  const char* name;  // as it appears, lower case, in jAER's AEChip class or cAER's source line
  int width;
  int height;
  bool davis_address_layout;  // AEDAT 2.0 addresses in the DAVIS layout (format.h)
};

// DVS128 and DVS640 (and the DVXplorer jAER reads as one) pack their AEDAT 2.0 addresses
// differently (x from bit 1, y from bit 8 or 11, polarity in bit 0); their AEDAT 3.1 polarity
// events are the same as every chip's.
constexpr Chip kChips[] = {
    {"davis346", 346, 260, true},    {"davis240", 240, 180, true}, {"davis208", 208, 192, true},
    {"davis128", 128, 128, true},    {"davis640", 640, 480, true}, {"dvs128", 128, 128, false},
    {"tmpdiff128", 128, 128, false}, {"dvs640", 640, 480, false},  {"dvxplorer", 640, 480, false},
};

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

bool StartsWith(const uint8_t* data, size_t size, const char* prefix) {
  const size_t length = std::strlen(prefix);
  return size >= length && std::memcmp(data, prefix, length) == 0;
}

}  // namespace

Header ParseHeader(const std::string& path, const uint8_t* data, size_t size) {
  Header header;
  if (StartsWith(data, size, kVersion2Line)) {
    header.major_version = 2;
  } else if (StartsWith(data, size, kVersion3Line)) {
    header.major_version = 3;
  } else {
    throw InputError(InputError::Kind::kMalformed, path, 1,
                     "expected the version line '#!AER-DAT2.0' or '#!AER-DAT3.1'");
  }
  // AEDAT 2.0: the header is every line that starts with '#' (jAER reads it so). AEDAT 3.1: the
  // lines up to and including "#!END-HEADER\r\n".
  size_t offset = 0;
  int64_t line_number = 0;
  bool ended = false;
  while (offset < size && data[offset] == '#') {
    ++line_number;
    const uint8_t* newline =
        static_cast<const uint8_t*>(std::memchr(data + offset, '\n', size - offset));
    if (newline == nullptr) {
      throw InputError(InputError::Kind::kMalformed, path, line_number,
                       "a header line without its line end (truncated file?)");
    }
    const size_t end = static_cast<size_t>(newline - data) + 1;
    const std::string line(reinterpret_cast<const char*>(data + offset), end - offset);
    offset = end;
    if (header.major_version == 3 && line == kEndOfHeader3) {
      ended = true;
      break;
    }
    if (header.width > 0 || line_number == 1) continue;
    const std::string lower = Lower(line);
    for (const Chip& chip : kChips) {
      const size_t position = lower.find(chip.name);
      if (position == std::string::npos) continue;
      header.width = chip.width;
      header.height = chip.height;
      // As the line spells it ("DAVIS240C" gives "DAVIS240"): letters and digits only.
      header.chip = line.substr(position, std::strlen(chip.name));
      if (!chip.davis_address_layout) header.other_address_layout = chip.name;
      break;
    }
  }
  if (header.major_version == 3 && !ended) {
    throw InputError(InputError::Kind::kMalformed, path, line_number + 1,
                     "expected the AEDAT 3.1 header's end line '#!END-HEADER' (truncated file?)");
  }
  header.data_start = offset;
  return header;
}

}  // namespace aedat_legacy
}  // namespace evfs

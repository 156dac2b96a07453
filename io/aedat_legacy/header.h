// The text header of AEDAT 2.0 and 3.1 files: the version line, '#' comment lines (3.1: up to
// "#!END-HEADER"), and the sensor the lines name.
#ifndef EVFS_IO_AEDAT_LEGACY_HEADER_H_
#define EVFS_IO_AEDAT_LEGACY_HEADER_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace evfs {
namespace aedat_legacy {

struct Header {
  int major_version = 0;  // 2 or 3
  size_t data_start = 0;  // first byte after the header
  // The sensor the header names (0 when it names none) and the chip's name as the header spells
  // it ("DAVIS240", "Davis346").
  int width = 0;
  int height = 0;
  std::string chip;
  // AEDAT 2.0 only: the name of a chip whose addresses are not in the DAVIS layout ("DVS128"),
  // "" for a DAVIS or an unnamed chip.
  std::string other_address_layout;
};

/// Parses the header of the `size` bytes at `data` (the file `path`, for messages). Throws
/// InputError when they do not start with an AEDAT 2.0 or 3.1 version line or a 3.1 header has
/// no end line.
Header ParseHeader(const std::string& path, const uint8_t* data, size_t size);

}  // namespace aedat_legacy
}  // namespace evfs

#endif  // EVFS_IO_AEDAT_LEGACY_HEADER_H_

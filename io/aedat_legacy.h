// AEDAT 2.0 and 3.1 recordings, the formats of jAER and cAER that older DAVIS recordings and
// v2e's output come in (docs.inivation.com, "AEDAT 2.0" and "AEDAT 3.1"; io/aedat_legacy/format.h
// gives the layouts).
//
// AEDAT 2.0: '#' header lines, then big-endian 8-byte records (int32 address, int32 time in us).
// Polarity events are read in the DAVIS240/DAVIS346 address layout; APS samples are read when
// they form global-shutter frames (every pixel's reset read, then every pixel's signal read),
// each frame's pixel value being (reset - signal) / 1023. The format has no index: a windowed
// read binary-searches the records by time, which opening checks never decrease.
//
// AEDAT 3.1: '#' header lines up to "#!END-HEADER", then packets with a 28-byte header (type,
// source, event size, counts). Polarity packets (type 1) give the events and frame packets
// (type 2) the frames; every other packet is skipped by its header. Opening reads the packet
// headers and each packet's first and last event only; a windowed read decodes only the packets
// whose time span overlaps the window.
//
// The sensor size comes from the header (a chip name or a sizeX/sizeY attribute) or, when the
// header names none, from the largest address (sensor_size_source() says which). Layouts evfs
// does not read (DVS128 or DVS640 addresses, CP-reset or rolling-shutter APS readouts, regions
// of interest) are refused by name with an InputError, as is a malformed or truncated file.
#ifndef EVFS_IO_AEDAT_LEGACY_H_
#define EVFS_IO_AEDAT_LEGACY_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "evfs/io/data_source.h"

namespace evfs {

/// An AEDAT 2.0 or 3.1 file opened for reading (see above). Not thread-safe.
class AedatLegacyDataSource : public DataSource {
 public:
  /// Opens and indexes `path`. Throws InputError for a missing, truncated or corrupt file, one of
  /// another version, or one in a layout evfs does not read (named in the message).
  explicit AedatLegacyDataSource(const std::string& path);
  /// The same for `size` bytes at `data`, named `path` in messages; the bytes must outlive the
  /// source (the fuzz target hands in its input this way).
  static std::unique_ptr<AedatLegacyDataSource> FromMemory(const std::string& path,
                                                           const char* data, size_t size);
  ~AedatLegacyDataSource() override;

  Image ReadImage(int index) const override;
  EventStream ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const override;
  EventStream ReadAllEvents() const override;
  EventSummary Summarize() const override;

  /// 2 for AEDAT 2.0, 3 for AEDAT 3.1.
  int major_version() const;
  /// Where the sensor size came from, for `evfs info` ("header: AEChip ...Davis346B").
  const std::string& sensor_size_source() const;
  /// Records (AEDAT 2.0) or packets (AEDAT 3.1) whose events were decoded since the file was
  /// opened, opening excluded: lets a test see that a windowed read reads only a few.
  int64_t units_decoded() const;

 private:
  class File;
  explicit AedatLegacyDataSource(std::unique_ptr<File> file);

  std::unique_ptr<File> file_;
};

/// True when the file at `path` starts with the version line of AEDAT 2.0 or 3.1
/// ("#!AER-DAT2.0" or "#!AER-DAT3.1"), so that DataSource::Open hands it to this reader.
bool StartsWithAedatLegacyVersionLine(const std::string& path);

}  // namespace evfs

#endif  // EVFS_IO_AEDAT_LEGACY_H_

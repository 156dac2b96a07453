// AEDAT 4.0 recordings, the format of iniVation's DV software (docs.inivation.com, "AEDAT 4.0"):
//   "#!AER-DAT4.0\r\n"
//   uint32 size, IOHeader        flatbuffer (io/aedat4/io_header.fbs): compression, the
//                                position of the file data table, and an XML description of
//                                the streams (id, type "EVTS"/"FRME"/..., sizeX, sizeY, tsOffset)
//   packets                      int32 stream id, int32 size, then the body: one LZ4 or Zstd
//                                frame (or raw bytes) holding a size-prefixed flatbuffer, an
//                                EventPacket (events.fbs) or one Frame (frame.fbs)
//   FileDataTable (optional)     at the header's data_table_position: every packet's offset,
//                                stream, element count and time span (file_data_table.fbs)
// Times in the file are Unix microseconds; evfs keeps them as they are (in ns), so a recording
// from DV reads with times like 1605537493.718345 s.
//
// The first EVTS stream gives the events and the first FRME stream the frames; every other
// stream (IMU, triggers, a second camera) is skipped. When the file has a data table, opening
// reads only it (and the frame packets, for their times and exposures): a windowed read then
// binary-searches the packets' time spans and decompresses only the packets that overlap the
// window. A file without one (a recording that was cut short), or with one that does not give
// every event packet's count and time span (tools that cut recordings write tables of offsets
// alone), is indexed in one pass over its packets, decompressing each event packet once.
//
// Every flatbuffer (the IOHeader, packets, the data table) is read whether its fields are aligned
// from its size prefix, as DV writes them, or from the flatbuffer itself, as other writers do.
//
// Every size and offset the file declares is checked before use, decompressed packets are
// verified as flatbuffers before they are read, and every event is checked against the sensor,
// the time order and its packet's entry in the data table: a malformed file is an InputError.
#ifndef EVFS_IO_AEDAT4_H_
#define EVFS_IO_AEDAT4_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evfs/io/data_source.h"

namespace evfs {

/// How the packets of a file are compressed (IOHeader.compression). The "high" variants are
/// the same formats at a higher compression level.
enum class Aedat4Compression { kNone, kLz4, kLz4High, kZstd, kZstdHigh };

/// The name DV gives `compression` ("NONE", "LZ4", "LZ4_HIGH", "ZSTD", "ZSTD_HIGH").
const char* Aedat4CompressionName(Aedat4Compression compression);

struct Aedat4WriteOptions {
  /// Compression of every packet and of the data table (DV records with LZ4 by default).
  Aedat4Compression compression = Aedat4Compression::kLz4;
  /// Most events in one packet: a windowed read decompresses whole packets, so this is the
  /// granularity of seeking (8192 events are 128 KB decompressed).
  int max_events_per_packet = 8192;
  /// false: a recording of frames only, without an event stream (`events` must be empty).
  bool with_events = true;

  bool IsValid(std::string* error) const;
};

/// An AEDAT 4.0 file opened for reading (see above). Not thread-safe.
class Aedat4DataSource : public DataSource {
 public:
  /// Opens and indexes `path`. Throws InputError for a missing, truncated or corrupt file, one
  /// of another AEDAT version, or one with neither an EVTS nor an FRME stream.
  explicit Aedat4DataSource(const std::string& path);
  /// The same for `size` bytes at `data`, named `path` in messages; the bytes must outlive the
  /// source (the fuzz target hands in its input this way).
  static std::unique_ptr<Aedat4DataSource> FromMemory(const std::string& path, const char* data,
                                                      size_t size);
  ~Aedat4DataSource() override;

  /// False for a file without an EVTS stream: Summarize() counts nothing and reading events
  /// throws InputError.
  bool has_events() const override;

  Image ReadImage(int index) const override;
  EventStream ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const override;
  EventStream ReadAllEvents() const override;
  EventSummary Summarize() const override;

  Aedat4Compression compression() const;
  /// tsOffset of the events stream (of the frames stream without one), in microseconds: the
  /// offset DV added to the camera's clock to make the stored times Unix times; 0 when absent.
  int64_t ts_offset_us() const;
  /// True when the packets were indexed from the file's data table, false when by a pass over
  /// the file (it has no table, or one without event counts).
  bool indexed_by_data_table() const;
  /// Number of packets of the events stream that hold events.
  int num_event_packets() const;
  /// Packets decompressed and decoded since the file was opened (events and frames, the
  /// indexing included): lets a test see that a windowed read reads only a few.
  int64_t packets_decoded() const;

 private:
  class File;
  explicit Aedat4DataSource(std::unique_ptr<File> file);

  std::unique_ptr<File> file_;
};

/// Writes a recording as AEDAT 4.0: an EVTS stream (id 0) and, when there are frames, an FRME
/// stream (id 1), packets interleaved in time order (compressed ones with a content checksum, so
/// that a reader sees a corrupt byte), and a data table. Times are rounded to the
/// nearest microsecond (the format's resolution); a frame without an exposure is written with
/// a zero-length one (start = end = its time), which reads back as no exposure. The images.txt
/// paths of the frames are kept in an "evfs" node of the stream description, which also marks
/// the file as evfs's (IsAedat4WrittenByEvfs). `images[i]` is the pixel data of `frames[i]`.
/// Throws InvalidArgumentError when the sizes disagree, a frame holds finer than 8-bit values,
/// two frame times or an exposure's ends fall on the same microsecond, or a side exceeds 32767
/// pixels; InputError(kUnwritable) when the file cannot be written.
void WriteAedat4(const std::string& path, const EventStream& events,
                 const std::vector<FrameInfo>& frames, const std::vector<Image>& images,
                 const Aedat4WriteOptions& options = Aedat4WriteOptions());

/// True when `path` is an AEDAT 4.0 file WriteAedat4 wrote (its header's stream description
/// has the "evfs" node): the only kind of .aedat4 file `evfs convert --overwrite` replaces.
/// Reads only the header.
bool IsAedat4WrittenByEvfs(const std::string& path);

/// True when `path` names an AEDAT 4 file by its extension (.aedat4, any case).
bool IsAedat4Path(const std::string& path);

/// True when the file at `path` starts like an AEDAT file of any version ("#!AER-DAT"), so
/// that DataSource::Open recognises a recording whatever its name ends in.
bool StartsWithAedatVersionLine(const std::string& path);

}  // namespace evfs

#endif  // EVFS_IO_AEDAT4_H_

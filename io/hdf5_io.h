// HDF5 event files in the layout common event-camera tools use:
//   /events/xs  uint16 [N]      /events/ys  uint16 [N]
//   /events/ts  float64 [N] seconds (or an integer type with attribute ts_unit "ns" or "us";
//               integers without it are microseconds)
//   /events/ps  int8 [N] with 0/1 (bool, uint8 and -1/1 are accepted too)
//   root attribute sensor_resolution = [height, width]
//   /images/image000000000 ...  uint8 or uint16 [height, width], attributes timestamp (float64
//               seconds), exposure_start / exposure_end (float64 seconds, when known) and path
//               (the images.txt path, so that text -> HDF5 -> text is lossless).
// Windowed reads binary-search /events/ts with single-element hyperslab reads and then read
// only the window, so a large file is never loaded whole.
#ifndef EVFS_IO_HDF5_IO_H_
#define EVFS_IO_HDF5_IO_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evfs/core/input_library.h"
#include "evfs/io/data_source.h"

namespace evfs {

/// An HDF5 recording opened for reading. Throws InputError for a missing, truncated or
/// corrupt file, a missing dataset or attribute, or events that break the layout's rules
/// (coordinates outside the sensor, polarity not in {-1, 0, 1}, decreasing timestamps).
class Hdf5DataSource : public DataSource {
 public:
  explicit Hdf5DataSource(const std::string& path);
  ~Hdf5DataSource() override;

  /// Number of events in the file.
  int64_t num_events() const;

  Image ReadImage(int index) const override;
  EventStream ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const override;
  EventStream ReadAllEvents() const override;
  EventSummary Summarize() const override;

  /// Index of the first event with t >= t_ns (binary search over /events/ts).
  int64_t LowerBound(int64_t t_ns) const;
  /// The events with index in [first, last), validated.
  EventStream ReadEventRange(int64_t first, int64_t last) const;

 private:
  class File;
  explicit Hdf5DataSource(std::unique_ptr<File> file);

  std::unique_ptr<File> file_;
};

/// Writes a recording as HDF5 (layout above). Frames are stored as uint8 when the image holds
/// exactly 8-bit values (MinimalBitDepth), else uint16. Event times go to float64 seconds when
/// that is exact for every event (it is below ~50 days), else to int64 with ts_unit "ns".
/// `images[i]` is the pixel data of `frames[i]`. Throws InputError(kUnwritable), or
/// InvalidArgumentError when the sizes disagree.
void WriteHdf5(const std::string& path, const EventStream& events,
               const std::vector<FrameInfo>& frames, const std::vector<Image>& images);

/// True when `path` is an HDF5 file WriteHdf5 wrote (its root attribute "written_by" is
/// "evfs"): the only kind of file `evfs convert --overwrite` replaces.
bool IsHdf5WrittenByEvfs(const std::string& path);

/// libhdf5 as the library reading a user's file (core/input_library.h): libhdf5 1.10 crashes on
/// some corrupt files (docs/robustness.md). Every stretch of libhdf5 calls that reads a file
/// runs inside a ScopedInputLibraryRead of it; writing does not (a crash there is not the
/// input's doing).
extern const InputLibrary kLibhdf5;

}  // namespace evfs

#endif  // EVFS_IO_HDF5_IO_H_

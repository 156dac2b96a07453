// A recording: events plus intensity frames, read either from a folder in the Event Camera
// Dataset text layout (events.txt, images.txt, images/, optional exposures.txt) or from an HDF5
// event file (docs/guide.md). Everything downstream reads data through this interface.
#ifndef EVFS_IO_DATA_SOURCE_H_
#define EVFS_IO_DATA_SOURCE_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"

namespace evfs {

/// One intensity frame of a recording: one line of images.txt (plus exposures.txt).
struct FrameInfo {
  /// Timestamp as written in images.txt; in DAVIS data with exposures this is the exposure
  /// midpoint.
  int64_t t_ns = 0;
  /// As written in images.txt, relative to the data folder (text layout), or the original
  /// images.txt path stored with the frame (HDF5; the dataset name when there is none).
  std::string path;
  /// Whether exposure_begin_ns / exposure_end_ns are known (exposures.txt or HDF5 attributes).
  bool has_exposure = false;
  int64_t exposure_begin_ns = 0;
  int64_t exposure_end_ns = 0;

  bool operator==(const FrameInfo& other) const;
  bool operator!=(const FrameInfo& other) const { return !(*this == other); }
};

/// Statistics of all events of a recording, gathered without keeping the events.
struct EventSummary {
  int64_t count = 0;
  int64_t positive = 0;    // events with polarity +1
  int64_t t_first_ns = 0;  // 0 when count is 0
  int64_t t_last_ns = 0;   // 0 when count is 0
  int max_x = -1;          // largest x seen, -1 when count is 0
  int max_y = -1;          // largest y seen, -1 when count is 0

  /// Adds one event (events arrive in time order).
  void Add(int64_t t_ns, int x, int y, int polarity) {
    if (count == 0) t_first_ns = t_ns;
    t_last_ns = t_ns;
    ++count;
    positive += polarity > 0 ? 1 : 0;
    max_x = x > max_x ? x : max_x;
    max_y = y > max_y ? y : max_y;
  }
};

/// Options of a source that only some formats use (the flags --events_topic, --frames_topic).
struct DataSourceOptions {
  /// ROS bags: the dvs_msgs/EventArray topic to read; "": the first one in the bag.
  std::string events_topic;
  /// ROS bags: the sensor_msgs/Image topic to read; "": the first one in the bag.
  std::string frames_topic;

  bool empty() const { return events_topic.empty() && frames_topic.empty(); }
};

/// A recording opened for reading. Not thread-safe (HDF5 is built serial).
class DataSource {
 public:
  /// Opens a data folder (text layout), an .h5/.hdf5 file, an AEDAT file (.aedat4, or any file
  /// starting with an AEDAT version line; io/aedat4.h, io/aedat_legacy.h) or a ROS 1 bag (.bag,
  /// or any file starting with "#ROSBAG V"; io/rosbag.h), with the topics `options` names.
  /// Throws InputError when the path is missing, of an unknown kind, or malformed, and
  /// InvalidArgumentError when `options` names topics for a recording that is no bag.
  static std::unique_ptr<DataSource> Open(const std::string& path,
                                          const DataSourceOptions& options = DataSourceOptions());

  virtual ~DataSource();

  /// The folder or file this source was opened from.
  const std::string& path() const { return path_; }
  /// Sensor size in pixels; every event and frame fits it.
  int width() const { return width_; }
  int height() const { return height_; }
  /// The frames in images.txt order (strictly increasing timestamps).
  const std::vector<FrameInfo>& frames() const { return frames_; }
  /// Why frames() is empty, for messages ("there is no DIR/images.txt"); "" when it is not.
  const std::string& no_frames_reason() const { return no_frames_reason_; }

  /// Frame `index` (0-based, as in frames()) as grey values in [0, 1]. Throws InputError when
  /// the image is missing, unreadable or not of the sensor size, InvalidArgumentError for an
  /// index outside frames().
  virtual Image ReadImage(int index) const = 0;
  /// The events with t_begin_ns <= t < t_end_ns, sized to the sensor. Large files are not read
  /// whole: the start is found by binary search.
  virtual EventStream ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const = 0;
  /// Every event of the recording.
  virtual EventStream ReadAllEvents() const = 0;
  /// False for a folder of frames without events.txt.
  virtual bool has_events() const { return true; }
  /// Counts and time range of all events (reads them all once, keeping none).
  virtual EventSummary Summarize() const = 0;

 protected:
  DataSource(std::string path, int width, int height, std::vector<FrameInfo> frames);
  /// Throws InvalidArgumentError unless `index` names a frame of frames() (ReadImage's check).
  void CheckFrameIndex(int index) const;

  std::string path_;
  int width_ = 0;
  int height_ = 0;
  std::vector<FrameInfo> frames_;
  std::string no_frames_reason_;  // set by the subclass when frames_ is empty
};

/// True when `path` names an HDF5 file by its extension (.h5 or .hdf5, any case).
bool IsHdf5Path(const std::string& path);

/// Copies a recording from `input` (folder, HDF5, AEDAT or ROS bag, opened with `options`) to
/// `output` (an .h5/.hdf5
/// path gives HDF5, an .aedat4 path AEDAT 4, anything else a data folder), losslessly: events to
/// the nanosecond, frames with their pixel values and bit depth, timestamps, exposures and
/// images.txt paths. AEDAT 4 keeps times to the microsecond and 8-bit frames only (WriteAedat4
/// rounds the times and refuses finer pixels). A recording of frames only (has_events() false)
/// stays one in a data folder or an AEDAT 4 file; HDF5 refuses it, as it holds events.
void ConvertRecording(const std::string& input, const std::string& output,
                      const DataSourceOptions& options = DataSourceOptions());

}  // namespace evfs

#endif  // EVFS_IO_DATA_SOURCE_H_

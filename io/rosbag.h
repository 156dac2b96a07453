// ROS 1 bags (.bag, format 2.0) of an event camera driver (rpg_dvs_ros, and the drivers that
// publish its messages): events from a dvs_msgs/EventArray topic and frames from a
// sensor_msgs/Image topic (io/rosbag/format.h gives both layouts). Debian's rosbag_storage reads
// the container (chunks, bz2 and LZ4 compression, the index); evfs decodes the two messages
// itself. Other topics (IMU, camera info) are skipped.
//
// Topics: DataSourceOptions names them (--events_topic, --frames_topic); by default the first
// topic of each datatype in the bag's connection order is taken, and one line on stderr says
// which. A topic must carry the published definition (its md5sum is checked).
//
// Times: every event keeps its own ts and every frame its header stamp. The bag's receive times
// (when the recorder got each message) are used only to find messages: a windowed read asks
// rosbag_storage for the messages received in the window shifted by the first event array's
// delays (its receive time minus its last event's ts for the start, minus its first event's ts
// for the end), widened by a margin, and widens the query until the events at both of its ends
// lie outside the window. This is exact as long as the
// recorder received the event arrays in the order of their events, which evfs checks on every
// array it reads; only the chunks the query touches are decompressed, so a long recording is
// read window by window in bounded memory.
//
// Frames carry no exposure (sensor_msgs/Image has none); the pixels are converted to grey
// (mono8, mono16, rgb8, bgr8, rgba8, bgra8; any other encoding is refused by name).
//
// Before rosbag_storage sees a file, evfs walks its record structure (CheckBagStructure), and
// before a compressed chunk is first read it decompresses and checks the chunk: rosbag_storage
// trusts the sizes and offsets a file declares. An unindexed bag (a recording cut short) is
// refused with the advice to run 'rosbag reindex'. Every failure is an InputError.
#ifndef EVFS_IO_ROSBAG_H_
#define EVFS_IO_ROSBAG_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evfs/io/data_source.h"

namespace evfs {

/// One topic of a bag, for `evfs info`.
struct RosbagTopic {
  std::string name;
  std::string datatype;
  int64_t messages = 0;
};

/// A ROS 1 bag opened for reading (see above). Not thread-safe.
class RosbagDataSource : public DataSource {
 public:
  /// Opens `path` with the topics `options` names (empty: the first of each type). Throws
  /// InputError for a missing, truncated or corrupt bag, a named topic that is not in it or is
  /// of another type, or a bag without either type.
  explicit RosbagDataSource(const std::string& path,
                            const DataSourceOptions& options = DataSourceOptions());
  ~RosbagDataSource() override;

  /// False for a bag without an EventArray topic.
  bool has_events() const override;

  Image ReadImage(int index) const override;
  EventStream ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const override;
  EventStream ReadAllEvents() const override;
  EventSummary Summarize() const override;

  /// The topics read ("" when the bag has none of that type).
  const std::string& events_topic() const;
  const std::string& frames_topic() const;
  /// Which topics were taken and why, one line ("events from /dvs/events (the first
  /// dvs_msgs/EventArray topic), frames from ...").
  const std::string& topic_choice() const;
  /// Every topic of the bag, in connection order.
  const std::vector<RosbagTopic>& topics() const;
  /// Event array messages decoded since the bag was opened (opening excluded): lets a test see
  /// that a windowed read reads only a few.
  int64_t messages_decoded() const;

 private:
  class File;
  explicit RosbagDataSource(std::unique_ptr<File> file);

  std::unique_ptr<File> file_;
};

/// True when `path` names a ROS bag by its extension (.bag, any case).
bool IsRosbagPath(const std::string& path);

/// True when the file at `path` starts with "#ROSBAG V" (a bag of any version; the reader names
/// versions other than 2.0 in its error).
bool StartsWithRosbagMagic(const std::string& path);

}  // namespace evfs

#endif  // EVFS_IO_ROSBAG_H_

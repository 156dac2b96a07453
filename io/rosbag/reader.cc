// Reading ROS 1 bags: RosbagDataSource (io/rosbag.h).
#include <console_bridge/console.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <set>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/mapped_file.h"
#include "evfs/io/message_excerpt.h"
#include "evfs/io/rosbag.h"
#include "evfs/io/rosbag/format.h"
#include "evfs/io/visited_events.h"

namespace evfs {
namespace {

namespace rf = rosbag_format;

// md5sums of the published definitions (ROS's rule: the text with nested types replaced by
// their own md5sums): a topic with another one carries another layout.
constexpr char kEventArrayMd5[] = "5e8beee5a6c107e504c2e78903c224b8";
constexpr char kImageMd5[] = "060021388200f6f0f447d0fcd9c64743";

// First margin of a windowed query around the window shifted by the receive delays: the
// driver publishes an array every few ms to tens of ms, so this often finds the messages
// at both ends in one query; it is doubled until it does.
constexpr int64_t kFirstQueryMarginNs = 10000000;

std::string DefaultFramePath(size_t index) {
  char name[40];
  std::snprintf(name, sizeof(name), "images/frame_%08zu.png", index);
  return name;
}

// ns (any int64) as a ros::Time, clamped to the range ros::Time holds.
ros::Time ToRosTime(int64_t t_ns) {
  const int64_t max_ns = static_cast<int64_t>(ros::TIME_MAX.toNSec());
  ros::Time time;
  time.fromNSec(static_cast<uint64_t>(std::clamp<int64_t>(t_ns, 0, max_ns)));
  return time;
}

int64_t SaturatingAdd(int64_t a, int64_t b) {
  if (b > 0 && a > std::numeric_limits<int64_t>::max() - b) {
    return std::numeric_limits<int64_t>::max();
  }
  if (b < 0 && a < std::numeric_limits<int64_t>::min() - b) {
    return std::numeric_limits<int64_t>::min();
  }
  return a + b;
}

// pluginlib loads rosbag's encryption plugin library (dlopen, relocations, static initialisers)
// with every rosbag::Bag and unloads it (dlclose, finalisers) with the last one alive, which
// costs more than checking and opening a small bag. A Bag held for the rest of the process, never
// opened, keeps the library loaded, so each bag after the first costs neither. It lives in
// static storage and is never destroyed (no finaliser order to get wrong at exit); what it
// allocates stays reachable from it, so leak checkers do not count it.
void KeepBagPluginsLoaded() {
  alignas(rosbag::Bag) static unsigned char storage[sizeof(rosbag::Bag)];
  static const rosbag::Bag* const keeper = new (storage) rosbag::Bag();
  (void)keeper;
}

}  // namespace

bool IsRosbagPath(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".bag";
}

bool StartsWithRosbagMagic(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  std::ifstream stream(path, std::ios::binary);
  constexpr char kAnyVersion[] = "#ROSBAG V";
  char start[sizeof(kAnyVersion) - 1] = {};
  stream.read(start, sizeof(start));
  return stream.gcount() == static_cast<std::streamsize>(sizeof(start)) &&
         std::memcmp(start, kAnyVersion, sizeof(start)) == 0;
}

class RosbagDataSource::File {
 public:
  File(const std::string& path, const DataSourceOptions& options) : path_(path), file_(path) {
    // rosbag_storage logs through console_bridge; evfs reports its errors itself, in one line.
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
    // The walk touches a page or more per record; the pages it is done with leave memory as it
    // goes, so that opening a bag holds a few megabytes of it, not a share of the file.
    layout_ =
        rf::CheckBagStructure(path, bytes(), file_.size(),
                              [this](size_t offset, size_t size) { file_.Release(offset, size); });
    file_.Release(0, file_.size());
    chunk_checked_.assign(layout_.chunks.size(), false);
    Guard([&] {
      KeepBagPluginsLoaded();
      bag_ = std::make_unique<rosbag::Bag>();
      bag_->open(path, rosbag::bagmode::Read);
    });
    Guard([&] { ListTopics(); });
    events_topic_ =
        ChooseTopic(options.events_topic, "--events_topic", rf::kEventArrayType, kEventArrayMd5);
    frames_topic_ = ChooseTopic(options.frames_topic, "--frames_topic", rf::kImageType, kImageMd5);
    if (events_topic_.empty() && frames_topic_.empty()) {
      Fail(InputError::Kind::kMalformed, "no " + std::string(rf::kEventArrayType) + " or " +
                                             rf::kImageType + " topic in the bag");
    }
    topic_choice_ =
        (events_topic_.empty() ? "no events" : "events from " + MessageExcerpt(events_topic_)) +
        events_reason_ + ", " +
        (frames_topic_.empty() ? "no frames" : "frames from " + MessageExcerpt(frames_topic_)) +
        frames_reason_;
    Guard([&] {
      IndexFrames();
      IndexEvents();
    });
  }

  const std::string& path() const { return path_; }
  int width() const { return width_; }
  int height() const { return height_; }
  std::vector<FrameInfo>& frames() { return frames_; }
  const std::string& no_frames_reason() const { return no_frames_reason_; }
  const std::string& events_topic() const { return events_topic_; }
  const std::string& frames_topic() const { return frames_topic_; }
  const std::string& topic_choice() const { return topic_choice_; }
  const std::vector<RosbagTopic>& topics() const { return topics_; }
  int64_t messages_decoded() const { return messages_decoded_; }

  [[noreturn]] void Fail(InputError::Kind kind, const std::string& what) const {
    throw InputError(kind, path_, 0, what);
  }

  // Runs `read`, turning rosbag_storage's exceptions (and ROS serialisation's) into InputError.
  template <typename Function>
  void Guard(Function&& read) const {
    try {
      read();
    } catch (const Error&) {
      throw;
    } catch (const std::exception& error) {
      Fail(InputError::Kind::kMalformed, "rosbag_storage: " + MessageExcerpt(error.what()));
    }
  }

  Image ReadImage(int index) const {
    const FrameMessage& frame = frame_messages_[static_cast<size_t>(index)];
    Image image;
    Guard([&] {
      CheckChunks(frames_topic_, frame.receive_time, frame.receive_time);
      rosbag::View view(*bag_, rosbag::TopicQuery(frames_topic_), frame.receive_time,
                        frame.receive_time);
      int ordinal = 0;
      for (const rosbag::MessageInstance& message : view) {
        if (message.getTime() != frame.receive_time || ordinal++ != frame.ordinal) continue;
        const std::string where = MessageName(frames_topic_, frame.receive_time);
        const std::vector<uint8_t>& bytes = Bytes(message);
        const rf::ImageMessage decoded = rf::DecodeImage(bytes.data(), bytes.size(), where);
        if (decoded.width != static_cast<uint32_t>(width_) ||
            decoded.height != static_cast<uint32_t>(height_)) {
          throw InputError(InputError::Kind::kSizeMismatch, where, 0,
                           "a " + std::to_string(decoded.width) + "x" +
                               std::to_string(decoded.height) + " image, expected the " +
                               std::to_string(width_) + "x" + std::to_string(height_) + " sensor");
        }
        image = rf::ImageToGrey(decoded, where);
        return;
      }
      Fail(InputError::Kind::kMalformed, "frame " + std::to_string(index) + " is gone from " +
                                             MessageExcerpt(frames_topic_) +
                                             " (the index changed?)");
    });
    return image;
  }

  // Calls visit(t_ns, x, y, polarity) for every event with t_begin_ns <= t < t_end_ns.
  template <typename Visitor>
  void ForEachEvent(int64_t t_begin_ns, int64_t t_end_ns, Visitor&& visit) const {
    if (events_topic_.empty() || t_end_ns <= t_begin_ns) return;
    int64_t before_ns = kFirstQueryMarginNs, after_ns = kFirstQueryMarginNs;
    const bool whole = t_begin_ns == kAllEventsBeginNs && t_end_ns == kAllEventsEndNs;
    for (;;) {
      const ros::Time from =
          whole ? ros::TIME_MIN
                : ToRosTime(
                      SaturatingAdd(SaturatingAdd(t_begin_ns, receive_after_last_ns_), -before_ns));
      const ros::Time to = whole ? ros::TIME_MAX
                                 : ToRosTime(SaturatingAdd(
                                       SaturatingAdd(t_end_ns, receive_after_first_ns_), after_ns));
      // The events of the window the query gives, kept until the query proves complete; a
      // whole read needs no proof and hands them on at once.
      struct Event {
        int64_t t_ns;
        int x, y, polarity;
      };
      std::vector<Event> window;
      bool any = false;
      int64_t first_t_ns = 0, last_t_ns = 0;
      Guard([&] {
        CheckChunks(events_topic_, from, to);
        rosbag::View view(*bag_, rosbag::TopicQuery(events_topic_), from, to);
        int64_t previous_t_ns = std::numeric_limits<int64_t>::min();
        for (const rosbag::MessageInstance& message : view) {
          ++messages_decoded_;
          const std::string where = MessageName(events_topic_, message.getTime());
          const std::vector<uint8_t>& bytes = Bytes(message);
          const rf::EventArray array = rf::DecodeEventArray(bytes.data(), bytes.size(), where);
          for (uint32_t i = 0; i < array.count; ++i) {
            const int64_t t_ns = array.t_ns(i);
            if (t_ns < previous_t_ns) {
              throw InputError(InputError::Kind::kNotMonotonic, where, 0,
                               "event " + std::to_string(i) +
                                   ": timestamps must not decrease (the bag must hold the event "
                                   "arrays in the order of their events)");
            }
            previous_t_ns = t_ns;
            if (!any) first_t_ns = t_ns;
            any = true;
            last_t_ns = t_ns;
            const int x = array.x(i), y = array.y(i);
            if (x >= width_ || y >= height_) {
              throw InputError(InputError::Kind::kOutOfRange, where, 0,
                               "event " + std::to_string(i) + ": (" + std::to_string(x) + ", " +
                                   std::to_string(y) + ") is outside the " +
                                   std::to_string(width_) + "x" + std::to_string(height_) +
                                   " sensor");
            }
            if (t_ns < t_begin_ns || t_ns >= t_end_ns) continue;
            if (whole) {
              visit(t_ns, x, y, array.polarity(i));
            } else {
              window.push_back({t_ns, x, y, array.polarity(i)});
            }
          }
        }
      });
      // Complete when the query reaches the topic's ends or its first and last events lie
      // outside the window on either side.
      const bool begin_ok = from <= events_begin_ || (any && first_t_ns < t_begin_ns);
      const bool end_ok = to >= events_end_ || (any && last_t_ns >= t_end_ns);
      if (begin_ok && end_ok) {
        for (const Event& event : window) visit(event.t_ns, event.x, event.y, event.polarity);
        return;
      }
      if (!begin_ok) before_ns = SaturatingAdd(before_ns, before_ns);
      if (!end_ok) after_ns = SaturatingAdd(after_ns, after_ns);
    }
  }

 private:
  // Where frame i's message is: its receive time, and which of the messages received at that
  // time on the topic it is.
  struct FrameMessage {
    ros::Time receive_time;
    int ordinal = 0;
  };

  const uint8_t* bytes() const { return reinterpret_cast<const uint8_t*>(file_.data()); }

  // Checks, once each, the chunks holding messages of `topic` received in [from, to] (the
  // messages a rosbag::View on them reads), decompressing them: rosbag_storage trusts the record
  // lengths inside a chunk.
  void CheckChunks(const std::string& topic, const ros::Time& from, const ros::Time& to) const {
    const std::set<uint32_t>& connections = topic_connections_.at(topic);
    bool checked_any = false;
    for (size_t i = 0; i < layout_.chunks.size(); ++i) {
      const rf::BagChunk& chunk = layout_.chunks[i];
      if (chunk_checked_[i]) continue;
      const bool read = std::any_of(
          chunk.entries.begin(), chunk.entries.end(), [&](const rf::BagChunk::Entry& entry) {
            return connections.count(entry.connection) == 1 && entry.time_ns >= from.toNSec() &&
                   entry.time_ns <= to.toNSec();
          });
      if (!read) continue;
      if (chunk.compression == "none") {
        rf::CheckChunkRecords(path_, chunk, bytes() + chunk.data_begin, chunk.data_size);
      } else {
        const rf::ChunkBytes uncompressed = rf::DecompressChunk(path_, chunk, bytes());
        rf::CheckChunkRecords(path_, chunk, uncompressed.data.get(), uncompressed.size);
      }
      // rosbag_storage reads the chunk again through its own buffer: the mapped pages are done
      // with, and a pass over every chunk then holds one chunk's pages, not the file's.
      file_.Release(chunk.data_begin, chunk.data_size);
      chunk_checked_[i] = true;
      checked_any = true;
    }
    // What each chunk's release leaves, the pages at its edges and those the kernel mapped in
    // around each page read, goes once the pass is done: a pass over every chunk of a large bag
    // would otherwise keep a few pages per chunk.
    if (checked_any) file_.Release(0, file_.size());
  }

  std::string MessageName(const std::string& topic, const ros::Time& time) const {
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%u.%09u", time.sec, time.nsec);
    return path_ + " (" + MessageExcerpt(topic) + ", message received at " + seconds + " s)";
  }

  // The serialised message, copied into buffer_.
  const std::vector<uint8_t>& Bytes(const rosbag::MessageInstance& message) const {
    buffer_.resize(message.size());
    ros::serialization::OStream stream(buffer_.data(), static_cast<uint32_t>(buffer_.size()));
    message.write(stream);
    return buffer_;
  }

  void ListTopics() {
    rosbag::View view(*bag_);
    for (const rosbag::ConnectionInfo* connection : view.getConnections()) {
      topic_connections_[connection->topic].insert(connection->id);
      const bool known = std::any_of(topics_.begin(), topics_.end(), [&](const RosbagTopic& t) {
        return t.name == connection->topic;
      });
      if (known) continue;
      RosbagTopic topic;
      topic.name = connection->topic;
      topic.datatype = connection->datatype;
      topic.messages = rosbag::View(*bag_, rosbag::TopicQuery(topic.name)).size();
      topics_.push_back(topic);
      md5sums_.push_back(connection->md5sum);
    }
  }

  // The topic `named` (by `flag`), or the first of `datatype`; "" when there is none.
  std::string ChooseTopic(const std::string& named, const char* flag, const char* datatype,
                          const char* md5sum) {
    std::string& reason =
        std::strcmp(datatype, rf::kImageType) == 0 ? frames_reason_ : events_reason_;
    for (size_t i = 0; i < topics_.size(); ++i) {
      const RosbagTopic& topic = topics_[i];
      if (named.empty() ? topic.datatype != datatype : topic.name != named) continue;
      if (topic.datatype != datatype || md5sums_[i] != md5sum) {
        Fail(InputError::Kind::kMalformed,
             (named.empty() ? std::string("topic ") : std::string(flag) + "=") +
                 MessageExcerpt(topic.name) + ": of type " + MessageExcerpt(topic.datatype) +
                 " (md5sum " + MessageExcerpt(md5sums_[i]) + "), expected " + datatype +
                 " (md5sum " + md5sum + ")");
      }
      reason = named.empty() ? std::string(" (the first ") + datatype + " topic; " + flag +
                                   " chooses another)"
                             : std::string(" (") + flag + ")";
      return topic.name;
    }
    if (!named.empty()) {
      // A few of the bag's topics: a message stays one short line.
      constexpr size_t kTopicsNamed = 4;
      std::string names;
      for (size_t i = 0; i < topics_.size() && i < kTopicsNamed; ++i) {
        names += (i == 0 ? "" : ", ") + MessageExcerpt(topics_[i].name);
      }
      if (topics_.size() > kTopicsNamed) {
        names += " and " + std::to_string(topics_.size() - kTopicsNamed) + " more";
      }
      Fail(InputError::Kind::kMalformed, std::string(flag) + "=" + MessageExcerpt(named) +
                                             ": no such topic; the bag has " + names);
    }
    return "";
  }

  // Reads every image header (the frames' stamps and the sensor size); the pixels are read
  // again by ReadImage.
  void IndexFrames() {
    if (frames_topic_.empty()) {
      no_frames_reason_ = "the bag has no " + std::string(rf::kImageType) + " topic";
      return;
    }
    struct Stamped {
      int64_t stamp_ns;
      FrameMessage message;
    };
    std::vector<Stamped> stamped;
    CheckChunks(frames_topic_, ros::TIME_MIN, ros::TIME_MAX);
    rosbag::View view(*bag_, rosbag::TopicQuery(frames_topic_));
    ros::Time previous_time;
    int ordinal = 0;
    for (const rosbag::MessageInstance& message : view) {
      const std::string where = MessageName(frames_topic_, message.getTime());
      const std::vector<uint8_t>& bytes = Bytes(message);
      const rf::ImageMessage image = rf::DecodeImage(bytes.data(), bytes.size(), where);
      if (stamped.empty()) {
        frame_width_ = static_cast<int>(std::min<uint32_t>(image.width, 65535));
        frame_height_ = static_cast<int>(std::min<uint32_t>(image.height, 65535));
      }
      ordinal = !stamped.empty() && message.getTime() == previous_time ? ordinal + 1 : 0;
      previous_time = message.getTime();
      stamped.push_back({image.stamp_ns, {message.getTime(), ordinal}});
    }
    // Receive order need not be stamp order (frames may wait in a queue): the stamps decide.
    std::stable_sort(stamped.begin(), stamped.end(),
                     [](const Stamped& a, const Stamped& b) { return a.stamp_ns < b.stamp_ns; });
    for (size_t i = 0; i < stamped.size(); ++i) {
      if (i > 0 && stamped[i].stamp_ns == stamped[i - 1].stamp_ns) {
        Fail(InputError::Kind::kNotMonotonic,
             "two images on " + MessageExcerpt(frames_topic_) + " have the same header stamp");
      }
      FrameInfo frame;
      frame.t_ns = stamped[i].stamp_ns;
      frame.path = DefaultFramePath(i);
      frames_.push_back(frame);
      frame_messages_.push_back(stamped[i].message);
    }
    if (frames_.empty())
      no_frames_reason_ = "the topic " + MessageExcerpt(frames_topic_) + " holds no images";
  }

  // The sensor size and receive delays, from the first event array; the topic's time span.
  void IndexEvents() {
    if (!events_topic_.empty()) {
      rosbag::View view(*bag_, rosbag::TopicQuery(events_topic_));
      events_begin_ = view.getBeginTime();
      events_end_ = view.getEndTime();
      CheckChunks(events_topic_, ros::TIME_MIN, events_begin_);
      for (const rosbag::MessageInstance& message : view) {
        const std::string where = MessageName(events_topic_, message.getTime());
        const std::vector<uint8_t>& bytes = Bytes(message);
        const rf::EventArray array = rf::DecodeEventArray(bytes.data(), bytes.size(), where);
        const int64_t received_ns = static_cast<int64_t>(message.getTime().toNSec());
        const int64_t first_ns = array.count > 0 ? array.t_ns(0) : array.stamp_ns;
        const int64_t last_ns = array.count > 0 ? array.t_ns(array.count - 1) : array.stamp_ns;
        receive_after_first_ns_ = SaturatingAdd(received_ns, -first_ns);
        receive_after_last_ns_ = SaturatingAdd(received_ns, -last_ns);
        width_ = static_cast<int>(std::min<uint32_t>(array.width, 65535));
        height_ = static_cast<int>(std::min<uint32_t>(array.height, 65535));
        break;
      }
    }
    if (width_ == 0 || height_ == 0) {
      width_ = frame_width_;
      height_ = frame_height_;
    }
    if (width_ == 0 || height_ == 0) {
      Fail(InputError::Kind::kMalformed,
           "no sensor size: the first event array gives none and there are no images");
    }
  }

  std::string path_;
  MappedFile file_;  // the bag, for the checks of its structure and its chunks
  rf::BagLayout layout_;
  mutable std::vector<bool> chunk_checked_;  // as layout_.chunks
  // Made once the structure is checked: its constructor sets up pluginlib's loader of
  // encryption plugins, which costs far more than checking a malformed file.
  std::unique_ptr<rosbag::Bag> bag_;
  std::vector<RosbagTopic> topics_;
  std::map<std::string, std::set<uint32_t>> topic_connections_;
  std::vector<std::string> md5sums_;  // of the first connection of each topic
  std::string events_topic_, frames_topic_;
  std::string events_reason_, frames_reason_;
  std::string topic_choice_;
  int width_ = 0, height_ = 0;
  int frame_width_ = 0, frame_height_ = 0;
  std::vector<FrameInfo> frames_;
  std::vector<FrameMessage> frame_messages_;  // as frames_
  std::string no_frames_reason_;
  ros::Time events_begin_, events_end_;  // receive times of the first and last event array
  // The first event array's receive time minus its first and its last event's time: a message
  // holding events of [t0, t1) is received about within [t0 + after_last, t1 + after_first].
  int64_t receive_after_first_ns_ = 0;
  int64_t receive_after_last_ns_ = 0;
  mutable std::vector<uint8_t> buffer_;
  mutable int64_t messages_decoded_ = 0;
};

RosbagDataSource::RosbagDataSource(const std::string& path, const DataSourceOptions& options)
    : RosbagDataSource(std::make_unique<File>(path, options)) {}

RosbagDataSource::RosbagDataSource(std::unique_ptr<File> file)
    : DataSource(file->path(), file->width(), file->height(), std::move(file->frames())),
      file_(std::move(file)) {
  no_frames_reason_ = file_->no_frames_reason();
}

RosbagDataSource::~RosbagDataSource() = default;

bool RosbagDataSource::has_events() const { return !file_->events_topic().empty(); }

const std::string& RosbagDataSource::events_topic() const { return file_->events_topic(); }
const std::string& RosbagDataSource::frames_topic() const { return file_->frames_topic(); }
const std::string& RosbagDataSource::topic_choice() const { return file_->topic_choice(); }
const std::vector<RosbagTopic>& RosbagDataSource::topics() const { return file_->topics(); }
int64_t RosbagDataSource::messages_decoded() const { return file_->messages_decoded(); }

Image RosbagDataSource::ReadImage(int index) const {
  CheckFrameIndex(index);
  return file_->ReadImage(index);
}

EventStream RosbagDataSource::ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const {
  return CollectVisitedEvents(
      width_, height_, [&](auto&& visit) { file_->ForEachEvent(t_begin_ns, t_end_ns, visit); });
}

EventStream RosbagDataSource::ReadAllEvents() const {
  return ReadEvents(kAllEventsBeginNs, kAllEventsEndNs);
}

EventSummary RosbagDataSource::Summarize() const {
  return SummarizeVisitedEvents(
      [&](auto&& visit) { file_->ForEachEvent(kAllEventsBeginNs, kAllEventsEndNs, visit); });
}

}  // namespace evfs

#include "evfs/io/text_folder.h"

#include <cstdio>
#include <filesystem>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/io/frame_list.h"
#include "evfs/io/image_io.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

constexpr char kEventsFile[] = "events.txt";
constexpr char kImagesFile[] = "images.txt";
constexpr char kExposuresFile[] = "exposures.txt";

bool IsFile(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

// Throws when `path` exists but is no regular file (a folder, a FIFO, a device): reading it
// would fail or block, and calling it missing would mislead. `expected` says what it should be.
void CheckRegularFileIfPresent(const fs::path& path, const char* expected) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status) || fs::is_regular_file(status)) return;
  throw InputError(InputError::Kind::kMalformed, path.string(), 0,
                   std::string(fs::is_directory(status) ? "a folder" : "a FIFO, socket or device") +
                       ", not " + expected);
}

std::vector<FrameInfo> ReadFolderFrames(const std::string& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) {
    throw InputError(InputError::Kind::kMissingFile, folder, 0, "data folder does not exist");
  }
  const fs::path images_txt = fs::path(folder) / kImagesFile;
  CheckRegularFileIfPresent(images_txt, "a file of frames ('t path' lines)");
  if (!IsFile(images_txt)) return {};
  std::vector<FrameInfo> frames = ReadFrameList(images_txt.string());
  const fs::path exposures_txt = fs::path(folder) / kExposuresFile;
  CheckRegularFileIfPresent(exposures_txt, "a file of exposures ('path t_start t_end' lines)");
  if (IsFile(exposures_txt)) ReadExposures(exposures_txt.string(), &frames);
  return frames;
}

// A path that stays inside the folder and names a PNG can be written as given.
bool IsWritableFramePath(const std::string& path) {
  const fs::path relative(path);
  if (relative.empty() || relative.is_absolute() || relative.extension() != ".png") return false;
  for (const fs::path& part : relative) {
    if (part == "..") return false;
  }
  return true;
}

std::string DefaultFramePath(size_t index) {
  char name[48];
  std::snprintf(name, sizeof(name), "images/frame_%08zu.png", index);
  return name;
}

// The sensor's size from the first frame's header, so that the limits on it (max_latent_voxels)
// are checked before a frame of that size is decoded; decoded when the header does not say or
// declares more than a frame may have (ReadGreyImage's error names the file).
void FirstFrameSize(const std::string& path, int* width, int* height) {
  int64_t header_width = 0, header_height = 0;
  if (ReadImageHeaderSize(path, &header_width, &header_height) && header_width > 0 &&
      header_height > 0 && header_width * header_height <= kMaxSensorPixels) {
    *width = static_cast<int>(header_width);
    *height = static_cast<int>(header_height);
    return;
  }
  const Image first = ReadGreyImage(path);
  *width = static_cast<int>(first.cols());
  *height = static_cast<int>(first.rows());
}

}  // namespace

TextFolderDataSource::TextFolderDataSource(const std::string& folder)
    : TextFolderDataSource(folder, ReadFolderFrames(folder)) {}

TextFolderDataSource::TextFolderDataSource(const std::string& folder, std::vector<FrameInfo> frames)
    : DataSource(folder, 0, 0, std::move(frames)) {
  const std::string events_txt = (fs::path(folder) / kEventsFile).string();
  const std::string images_txt = (fs::path(folder) / kImagesFile).string();
  CheckRegularFileIfPresent(events_txt, "a file of events ('t x y p' lines)");
  if (frames_.empty()) {
    no_frames_reason_ =
        IsFile(images_txt) ? images_txt + " lists none" : "there is no " + images_txt;
  }
  if (!IsFile(events_txt)) {
    // A folder of frames alone (a ground-truth clip to simulate events from) is a recording
    // without events: it can be described and simulated, and reading its events says why not.
    if (frames_.empty()) {
      throw InputError(InputError::Kind::kMissingFile, events_txt, 0,
                       "does not exist, and " + no_frames_reason_ + ": not a data folder");
    }
    FirstFrameSize((fs::path(folder) / frames_.front().path).string(), &width_, &height_);
    return;
  }
  if (!frames_.empty()) {
    FirstFrameSize((fs::path(folder) / frames_.front().path).string(), &width_, &height_);
  } else {
    const EventSummary summary = EventTextReader(events_txt).Summarize();
    width_ = summary.max_x + 1;
    height_ = summary.max_y + 1;
  }
  events_ = std::make_unique<EventTextReader>(events_txt, width_, height_);
}

TextFolderDataSource::~TextFolderDataSource() = default;

Image TextFolderDataSource::ReadImage(int index) const {
  CheckFrameIndex(index);
  const std::string image_path = (fs::path(path_) / frames_[index].path).string();
  const std::string expected = "the sensor size " + std::to_string(width_) + "x" +
                               std::to_string(height_) + " of the first image";
  Image image = ReadGreyImage(image_path, width_, height_, expected);
  if (image.cols() != width_ || image.rows() != height_) {
    throw InputError(InputError::Kind::kSizeMismatch, image_path, 0,
                     "image is " + std::to_string(image.cols()) + "x" +
                         std::to_string(image.rows()) + ", expected " + expected);
  }
  return image;
}

const EventTextReader& TextFolderDataSource::events() const {
  if (!events_) {
    throw InputError(InputError::Kind::kMissingFile, (fs::path(path_) / kEventsFile).string(), 0,
                     "this folder holds frames only; make events for it with "
                     "'evfs simulate --frames=" +
                         path_ + " --out=DIR'");
  }
  return *events_;
}

EventStream TextFolderDataSource::ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const {
  return events().Read(t_begin_ns, t_end_ns);
}

EventStream TextFolderDataSource::ReadAllEvents() const { return events().ReadAll(); }

EventSummary TextFolderDataSource::Summarize() const {
  return events_ ? events_->Summarize() : EventSummary();
}

void WriteDataFolder(const std::string& folder, const EventStream& events,
                     const std::vector<FrameInfo>& frames, const std::vector<Image>& images,
                     bool with_events) {
  if (frames.size() != images.size()) {
    throw InvalidArgumentError("WriteDataFolder: " + std::to_string(frames.size()) +
                               " frames but " + std::to_string(images.size()) + " images");
  }
  if (!with_events && !events.empty()) {
    throw InvalidArgumentError("WriteDataFolder: a folder of frames only cannot hold " +
                               std::to_string(events.size()) + " events");
  }
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) {
    throw InputError(InputError::Kind::kUnwritable, folder, 0,
                     "cannot create the folder: " + error.message());
  }
  if (with_events) WriteEventsText((fs::path(folder) / kEventsFile).string(), events);

  std::vector<FrameInfo> written = frames;
  bool any_exposure = false;
  for (size_t i = 0; i < written.size(); ++i) {
    if (!IsWritableFramePath(written[i].path)) written[i].path = DefaultFramePath(i);
    const fs::path image_path = fs::path(folder) / written[i].path;
    fs::create_directories(image_path.parent_path(), error);
    if (error) {
      throw InputError(InputError::Kind::kUnwritable, image_path.parent_path().string(), 0,
                       "cannot create the folder: " + error.message());
    }
    WriteGreyPngLossless(image_path.string(), images[i]);
    any_exposure = any_exposure || written[i].has_exposure;
  }
  if (!frames.empty()) WriteFrameList((fs::path(folder) / kImagesFile).string(), written);
  if (any_exposure) WriteExposures((fs::path(folder) / kExposuresFile).string(), written);
}

}  // namespace evfs

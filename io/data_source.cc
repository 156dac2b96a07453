#include "evfs/io/data_source.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/io/aedat4.h"
#include "evfs/io/aedat_legacy.h"
#include "evfs/io/hdf5_io.h"
#include "evfs/io/rosbag.h"
#include "evfs/io/text_folder.h"

namespace evfs {

bool FrameInfo::operator==(const FrameInfo& other) const {
  return t_ns == other.t_ns && path == other.path && has_exposure == other.has_exposure &&
         exposure_begin_ns == other.exposure_begin_ns && exposure_end_ns == other.exposure_end_ns;
}

DataSource::DataSource(std::string path, int width, int height, std::vector<FrameInfo> frames)
    : path_(std::move(path)), width_(width), height_(height), frames_(std::move(frames)) {}

DataSource::~DataSource() = default;

void DataSource::CheckFrameIndex(int index) const {
  if (index < 0 || index >= static_cast<int>(frames_.size())) {
    throw InvalidArgumentError("frame index " + std::to_string(index) + " is outside [0, " +
                               std::to_string(frames_.size()) + ")");
  }
}

bool IsHdf5Path(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".h5" || extension == ".hdf5";
}

std::unique_ptr<DataSource> DataSource::Open(const std::string& path,
                                             const DataSourceOptions& options) {
  std::error_code error;
  if (IsRosbagPath(path) || StartsWithRosbagMagic(path)) {
    auto bag = std::make_unique<RosbagDataSource>(path, options);
    // Which topics a bag gives is not obvious from its name: say it when evfs chose.
    if (options.events_topic.empty() || options.frames_topic.empty()) {
      std::fprintf(stderr, "evfs: %s: %s\n", path.c_str(), bag->topic_choice().c_str());
    }
    return bag;
  }
  if (!options.empty()) {
    throw InvalidArgumentError("--events_topic and --frames_topic apply to ROS bags (.bag), not " +
                               path);
  }
  if (std::filesystem::is_directory(path, error)) {
    return std::make_unique<TextFolderDataSource>(path);
  }
  if (IsHdf5Path(path)) return std::make_unique<Hdf5DataSource>(path);
  if (StartsWithAedatLegacyVersionLine(path)) {
    return std::make_unique<AedatLegacyDataSource>(path);
  }
  // An AEDAT file by its name, or by its version line whatever its name (DV's .aedat4, an older
  // version, which the reader names in its error).
  if (IsAedat4Path(path) || StartsWithAedatVersionLine(path)) {
    return std::make_unique<Aedat4DataSource>(path);
  }
  if (!std::filesystem::exists(path, error)) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "no such data folder, HDF5, AEDAT or ROS bag file");
  }
  throw InputError(InputError::Kind::kMalformed, path, 0,
                   "expected a data folder, an .h5/.hdf5, an .aedat4 or a .bag file");
}

void ConvertRecording(const std::string& input, const std::string& output,
                      const DataSourceOptions& options) {
  const std::unique_ptr<DataSource> source = DataSource::Open(input, options);
  // A recording of frames only stays one in a data folder or an AEDAT 4 file; the HDF5 layout
  // holds events, so there ReadAllEvents refuses it (naming `evfs simulate`).
  const bool with_events = source->has_events() || IsHdf5Path(output);
  const EventStream events =
      with_events ? source->ReadAllEvents() : EventStream(source->width(), source->height());
  std::vector<Image> images;
  for (int i = 0; i < static_cast<int>(source->frames().size()); ++i) {
    images.push_back(source->ReadImage(i));
  }
  if (IsHdf5Path(output)) {
    WriteHdf5(output, events, source->frames(), images);
  } else if (IsAedat4Path(output)) {
    Aedat4WriteOptions options;
    options.with_events = with_events;
    WriteAedat4(output, events, source->frames(), images, options);
  } else {
    WriteDataFolder(output, events, source->frames(), images, with_events);
  }
}

}  // namespace evfs

#include "evfs/app/simulate_job.h"

#include <memory>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/video.h"
#include "evfs/io/data_source.h"
#include "evfs/io/text_folder.h"

namespace evfs {

SimulateSummary SimulateRecording(const std::string& frames_path, const SimulatorOptions& options,
                                  const std::string& out_folder, const FlickerOptions& flicker,
                                  const FrameEffectsOptions& frame_effects) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("simulator: " + error);
  if (!flicker.IsValid(&error)) throw InvalidArgumentError("light sources: " + error);
  if (!frame_effects.IsValid(&error)) throw InvalidArgumentError("frame effects: " + error);
  const std::unique_ptr<DataSource> source = DataSource::Open(frames_path);
  const std::vector<FrameInfo>& frames = source->frames();
  if (frames.size() < 2) {
    std::string reason = std::to_string(frames.size()) + " found";
    if (!source->no_frames_reason().empty()) reason += ": " + source->no_frames_reason();
    throw InputError(InputError::Kind::kMalformed, source->path(), 0,
                     "simulate needs at least 2 frames (" + reason + ")");
  }
  Video video;
  std::vector<Image> images;
  images.reserve(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    images.push_back(source->ReadImage(static_cast<int>(i)));
    video.AppendFrame(images.back(), frames[i].t_ns);
  }
  const EventStream events = SimulateEvents(video, options, flicker);
  std::vector<FrameInfo> written = frames;
  if (flicker.enabled() || frame_effects.enabled()) {
    std::vector<RecordedFrame> recorded = RecordFrames(video, flicker, frame_effects);
    for (size_t i = 0; i < frames.size(); ++i) {
      images[i] = std::move(recorded[i].image);
      if (recorded[i].has_exposure) {
        written[i].has_exposure = true;
        written[i].exposure_begin_ns = recorded[i].exposure_begin_ns;
        written[i].exposure_end_ns = recorded[i].exposure_end_ns;
      }
    }
  }
  WriteDataFolder(out_folder, events, written, images);

  SimulateSummary summary;
  summary.events = static_cast<int64_t>(events.size());
  summary.frames = static_cast<int>(frames.size());
  summary.width = video.width();
  summary.height = video.height();
  return summary;
}

}  // namespace evfs

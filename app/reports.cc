#include "evfs/app/reports.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "evfs/app/frame_lag.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/io/aedat_legacy.h"
#include "evfs/io/rosbag.h"

namespace evfs {

void PrintRecording(const DataSource& source, std::FILE* out) {
  const EventSummary events = source.Summarize();
  std::fprintf(out, "data        %s\n", source.path().c_str());
  std::fprintf(out, "resolution  %dx%d\n", source.width(), source.height());
  // AEDAT 2.0 files of v2e name no chip: the reader then infers the sensor, and says so.
  if (const auto* legacy = dynamic_cast<const AedatLegacyDataSource*>(&source)) {
    std::fprintf(out, "format      AEDAT %s (sensor size from %s)\n",
                 legacy->major_version() == 2 ? "2.0" : "3.1",
                 legacy->sensor_size_source().c_str());
  }
  if (const auto* bag = dynamic_cast<const RosbagDataSource*>(&source)) {
    std::fprintf(out, "format      ROS bag: %s\n", bag->topic_choice().c_str());
    for (const RosbagTopic& topic : bag->topics()) {
      std::fprintf(out, "  topic     %s  %s  %lld messages\n", topic.name.c_str(),
                   topic.datatype.c_str(), static_cast<long long>(topic.messages));
    }
    if (!bag->frames_topic().empty()) {
      std::fprintf(out,
                   "frame time  the image header stamps; exposure unknown (sensor_msgs/Image "
                   "holds none: --exposure_s gives one)\n");
    }
  }
  if (source.has_events()) {
    std::fprintf(out, "events      %lld (%lld ON, %lld OFF)\n",
                 static_cast<long long>(events.count), static_cast<long long>(events.positive),
                 static_cast<long long>(events.count - events.positive));
  } else {
    std::fprintf(out,
                 "events      none: frames only (make events with 'evfs simulate --frames=%s "
                 "--out=DIR')\n",
                 source.path().c_str());
  }
  if (events.count > 0) {
    const double span_s = NanosecondsToSeconds(events.t_last_ns - events.t_first_ns);
    std::fprintf(out, "time span   %.6f s .. %.6f s (%.6f s)\n",
                 NanosecondsToSeconds(events.t_first_ns), NanosecondsToSeconds(events.t_last_ns),
                 span_s);
    if (span_s > 0) std::fprintf(out, "event rate  %.3f Mev/s\n", events.count / span_s / 1e6);
  }
  const auto& frames = source.frames();
  if (frames.empty()) {
    std::fprintf(out, "frames      0 (%s)\n", source.no_frames_reason().c_str());
  } else {
    std::fprintf(out, "frames      %zu\n", frames.size());
  }
  for (size_t i = 0; i < frames.size(); ++i) {
    std::fprintf(out, "  %3zu  t=%.6f s  %s", i, NanosecondsToSeconds(frames[i].t_ns),
                 frames[i].path.c_str());
    if (frames[i].has_exposure) {
      std::fprintf(
          out, "  exposure %.6f .. %.6f s (%.1f ms)",
          NanosecondsToSeconds(frames[i].exposure_begin_ns),
          NanosecondsToSeconds(frames[i].exposure_end_ns),
          1e3 * NanosecondsToSeconds(frames[i].exposure_end_ns - frames[i].exposure_begin_ns));
    }
    std::fprintf(out, "\n");
  }
}

void PrintWindow(const DataSource& source, int first, int last, const BinningOptions& binning,
                 const std::string& binning_flag, std::FILE* out) {
  const int count = static_cast<int>(source.frames().size());
  if (count == 0) {
    throw InvalidArgumentError(source.path() + " has 0 frames (" + source.no_frames_reason() +
                               "): --first/--last name frames");
  }
  if (first < 0 || first >= count || last >= count || last <= first) {
    throw InvalidArgumentError("--first/--last must be frame indices with first < last < " +
                               std::to_string(count));
  }
  const int64_t begin_ns = source.frames()[first].t_ns, end_ns = source.frames()[last].t_ns;
  const EventStream window = source.ReadEvents(begin_ns, end_ns);
  const Image first_image = source.ReadImage(first);
  const Image last_image = source.ReadImage(last);
  const BinningPlan plan =
      PlanBinning(window, begin_ns, end_ns, binning, {&first_image, &last_image});
  const PixelActivity& activity = plan.activity;
  const size_t positive = window.CountPositive();
  std::string left_out;  // what the binning leaves out
  if (!activity.hot_pixels.empty()) {
    left_out = " without " + std::to_string(activity.hot_pixels.size()) + " hot pixel" +
               (activity.hot_pixels.size() == 1 ? "" : "s") + " (" +
               std::to_string(activity.hot_pixel_events) + " events left out)";
  }
  if (plan.noise_events > 0) {
    left_out += ", " + std::to_string(plan.noise_events) + " unsupported events left out as noise";
  }
  std::fprintf(
      out,
      "window      frames %d..%d, %.6f s: %zu events (%zu ON, %zu OFF) at %lld pixels "
      "(%.1f %%), %lld collision frames%s\n",
      first, last, NanosecondsToSeconds(end_ns - begin_ns), window.size(), positive,
      window.size() - positive, static_cast<long long>(activity.pixels_fired),
      100.0 * static_cast<double>(activity.pixels_fired) / static_cast<double>(plan.pixels),
      static_cast<long long>(plan.collision_frames), left_out.c_str());
  // Where the frames govern: pixels whose events the window leaves out, rule by rule.
  std::fprintf(out,
               "frames rule hot %zu pixels (%lld events), saturated %zu (%lld), flickering %zu "
               "(%lld)\n",
               activity.hot_pixels.size(), static_cast<long long>(activity.hot_pixel_events),
               plan.saturated_pixels.size(), static_cast<long long>(plan.saturated_pixel_events),
               plan.flickering_pixels.size(), static_cast<long long>(plan.flickering_pixel_events));
  const bool split = plan.method == BinningOptions::Method::kCollision &&
                     plan.num_event_frames > plan.collision_frames;
  std::fprintf(out,
               "binning     %s: %s%s, %d event frames, %d latent frames (%lld of %lld voxels)\n",
               binning_flag.c_str(), NameOf(kBinningMethodNames, plan.method),
               split ? " split in time (--min_latent_steps)" : "", plan.num_event_frames,
               plan.num_latent_frames, static_cast<long long>(plan.latent_voxels()),
               static_cast<long long>(binning.max_latent_voxels));
  // A change of overall brightness between the frames (flicker, exposure or gain) that no
  // event records is outside the per-pixel event model; this line shows it.
  const double first_mean = first_image.mean();
  const double last_mean = last_image.mean();
  std::fprintf(out, "brightness  frame %d mean %.3f, frame %d mean %.3f (%+.1f %%)\n", first,
               first_mean, last, last_mean, 100.0 * (last_mean / first_mean - 1.0));
  // When the frames show the scene relative to their timestamps, from the events between each
  // pair of consecutive frames of the window (reconstruct's --frame_time=auto).
  std::vector<int> indices;
  for (int i = first; i <= last; ++i) indices.push_back(i);
  std::fprintf(out, "frame time  %s\n",
               EstimateRecordingFrameLag(source, indices, FrameLagOptions()).description.c_str());
}

namespace {

// The denoiser's line: its mode, weights, work and time; what frame consistency took out; the
// truth score before it. Nothing for mode none.
void PrintDenoise(const DenoiseRecord& record, std::FILE* out) {
  if (record.mode == DenoiseMode::kNone) return;
  std::string line = std::string("denoise: ") + NameOf(kDenoiseModeNames, record.mode) + " (" +
                     std::filesystem::path(record.weights_path).filename().string() + ", sha256 " +
                     record.weights_sha256.substr(0, 12) + "…)";
  char buffer[160];
  if (record.mode == DenoiseMode::kPnp) {
    std::snprintf(buffer, sizeof(buffer), ", %d ADMM iterations, solve %.2f s + denoise %.2f s",
                  record.pnp.iterations, record.pnp.solve_time_s, record.pnp.denoise_time_s);
  } else {
    std::snprintf(buffer, sizeof(buffer), ", %d frames in %.2f s", record.stats.frames,
                  record.stats.time_s);
  }
  line += buffer;
  if (record.consistent) {
    std::snprintf(buffer, sizeof(buffer),
                  "; %.0f %% of its correction taken out to keep the frames",
                  100.0 * record.consistency.RemovedFraction());
    line += buffer;
  }
  if (record.scored) {
    std::snprintf(buffer, sizeof(buffer), "; before it: %.2f dB, %.4f", record.psnr_before,
                  record.ssim_before);
    line += buffer;
  }
  std::fprintf(out, "%s\n", line.c_str());
}

}  // namespace

void PrintReconstruction(const ReconstructRequest& request, const ReconstructResult& result,
                         const std::string& out_path, std::FILE* out) {
  const MethodResult& run = result.run;
  std::fprintf(out, "%s: %dx%d, %lld events, %d event frames, %d latent frames\n",
               ModeName(result.mode), result.width, result.height,
               static_cast<long long>(result.events), result.event_frames, run.video.num_frames());
  if (result.hot_pixels > 0) {
    std::fprintf(out, "hot pixels: %d, their %lld events left out (--hot_pixel_factor)\n",
                 result.hot_pixels, static_cast<long long>(result.hot_pixel_events));
  }
  if (result.saturated_pixels > 0) {
    std::fprintf(out, "saturated pixels: %d, their %lld events left out (--saturation_level)\n",
                 result.saturated_pixels, static_cast<long long>(result.saturated_pixel_events));
  }
  if (result.flickering_pixels > 0) {
    std::fprintf(out,
                 "flickering pixels: %d, their %lld events left out (--flicker_min_reversals)\n",
                 result.flickering_pixels, static_cast<long long>(result.flickering_pixel_events));
  }
  if (result.noise_events > 0) {
    std::fprintf(out, "noise: %lld unsupported events left out (--noise_filter_ms)\n",
                 static_cast<long long>(result.noise_events));
  }
  if (result.mode != Mode::kDeblur && request.frame_time != FrameTime::kInstant) {
    std::fprintf(
        out, "frame time: sharp frames shifted by %+.2f ms%s%s\n",
        1e3 * NanosecondsToSeconds(result.frame_shift_ns),
        request.frame_time == FrameTime::kAuto ? ": " : "",
        request.frame_time == FrameTime::kAuto ? result.frame_lag.description.c_str() : "");
  }
  if (IsIterative(request.method.method)) {
    if (result.log_offset_choice) {
      std::fprintf(out, "log offset: %s\n", result.log_offset_choice->description.c_str());
    }
    std::fprintf(out, "model: %s\n", run.reconstruction.model.description.c_str());
    if (run.solved) {
      std::fprintf(out, "solve: %s from %s, %d iterations, cost %.6g -> %.6g (%s)\n",
                   run.method.c_str(), run.initialization.c_str(), run.iterations, run.initial_cost,
                   run.final_cost, run.message.c_str());
    } else {
      std::fprintf(out, "solve: skipped (%s)\n", run.message.c_str());
    }
  } else {
    std::fprintf(out, "method: %s%s%s\n", run.method.c_str(),
                 run.threshold_source.empty() ? "" : ", ", run.threshold_source.c_str());
  }
  PrintDenoise(result.denoise, out);
  if (result.has_truth) {
    std::fprintf(out, "truth: frame %d vs latent %d: PSNR %.2f dB, SSIM %.4f (%s: %.2f dB, %.4f)\n",
                 result.truth.index, result.truth.latent_index, result.truth.psnr,
                 result.truth.ssim, result.mode == Mode::kInterpolate ? "blend" : "copy",
                 result.truth.baseline_psnr, result.truth.baseline_ssim);
  }
  std::fprintf(out,
               "time: read %.2f s, bin %.3f s, build %.2f s, solve %.2f s, write %.2f s, "
               "total %.2f s\n",
               result.time.read_s, result.time.bin_s, result.time.build_s, result.time.solve_s,
               result.time.write_s, result.time.total_s);
  std::fprintf(out, "wrote %d frames to %s\n", result.output.num_frames(), out_path.c_str());
}

}  // namespace evfs

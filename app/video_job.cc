#include "evfs/app/video_job.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "evfs/app/run_report.h"
#include "evfs/app/summary_json.h"
#include "evfs/app/video_steps.h"
#include "evfs/app/video_work_folder.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/parallel.h"
#include "evfs/core/time.h"
#include "evfs/denoiser/frame_consistency.h"
#include "evfs/io/data_source.h"
#include "evfs/io/image_io.h"
#include "evfs/io/video_writer.h"
#include "evfs/scene/confidence.h"
#include "evfs/scene/scene.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

std::string FrameName(int64_t n) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06lld", static_cast<long long>(n));
  return name;
}

// Serialises reads of the recording (DataSource is not thread-safe) and names bad frames.
class SharedSource {
 public:
  SharedSource(const std::string& path, const DataSourceOptions& options)
      : source_(DataSource::Open(path, options)) {}

  const DataSource& unlocked() const { return *source_; }

  Image ReadImage(int index) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return ReadVideoFrame(*source_, index);
  }
  EventStream ReadEvents(int64_t begin_ns, int64_t end_ns) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return source_->ReadEvents(begin_ns, end_ns);
  }

 private:
  std::unique_ptr<DataSource> source_;
  mutable std::mutex mutex_;
};

struct WindowContext {
  const VideoRequest* request = nullptr;
  const SharedSource* source = nullptr;
  const OutputClock* clock = nullptr;
  MethodOptions method;  // with the per-window thread count
  /// b of the interpolation windows (VideoRequest::log_offset_search); <= 0: method's.
  double interpolation_log_offset = 0.0;
  const Denoiser* denoiser = nullptr;
  fs::path work;
};

// The latent frames of `latent` that the window's output frames [begin, end) and its truth
// scores read (the two around each time), with what frame consistency needs besides
// (FramesToDenoise): the only frames the denoiser has to run on. At 240 fps from 48 latent steps
// per window that is a few frames of each window's dozens.
std::vector<uint8_t> FramesTheOutputNeeds(const VideoWindow& window, const Scene& scene,
                                          const Video& latent, const WindowContext& context,
                                          int64_t begin, int64_t end) {
  std::vector<uint8_t> read(latent.num_frames(), 0);
  const auto mark = [&latent, &read](int64_t t_ns) {
    int before = 0, after = 0;
    double weight_after = 0.0;
    latent.InterpolationFrames(t_ns, &before, &after, &weight_after);
    read[before] = 1;
    if (weight_after > 0.0) read[after] = 1;
  };
  for (int64_t n = begin; n < end; ++n) mark(context.clock->TimeNs(n));
  for (const int index : window.truth_frames) mark(context.source->unlocked().frames()[index].t_ns);
  return context.request->denoise.consistency ? FramesToDenoise(scene, read) : read;
}

// A fingerprint of what a window read: its observed frames' pixels and its events, FNV-1a over
// their bytes. --resume reuses a window only when the recording still gives it the same input;
// this notices a changed recording, it is no defence against a made-up collision.
class WindowInputHash {
 public:
  void Add(const void* bytes, size_t size) {
    const auto* byte = static_cast<const unsigned char*>(bytes);
    for (size_t i = 0; i < size; ++i) hash_ = (hash_ ^ byte[i]) * kPrime;
  }
  template <typename T>
  void AddAll(const std::vector<T>& values) {
    const uint64_t count = values.size();
    Add(&count, sizeof(count));
    if (!values.empty()) Add(values.data(), values.size() * sizeof(T));
  }
  void AddImage(const Image& image) {
    const int64_t size[2] = {image.rows(), image.cols()};
    Add(size, sizeof(size));
    Add(image.data(), static_cast<size_t>(image.size()) * sizeof(double));
  }
  void AddEvents(const EventStream& events) {
    AddAll(events.t_ns());
    AddAll(events.x());
    AddAll(events.y());
    AddAll(events.polarity());
  }
  std::string Hex() const {
    char text[17];
    std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash_));
    return text;
  }

 private:
  static constexpr uint64_t kPrime = 1099511628211ull;
  uint64_t hash_ = 14695981039346656037ull;
};

// The fingerprint of what `window` reads from the recording now.
std::string ReadWindowInputHash(const VideoWindow& window, const SharedSource& source) {
  WindowInputHash hash;
  for (const VideoWindowFrame& observed : window.frames) {
    hash.AddImage(source.ReadImage(observed.index));
  }
  hash.AddEvents(source.ReadEvents(window.begin_ns, window.end_ns));
  return hash.Hex();
}

// A window's frame as the scene takes it: its image, exposure and file name.
TimedFrame ReadWindowFrame(const SharedSource& source, const VideoWindowFrame& observed) {
  TimedFrame frame;
  frame.image = source.ReadImage(observed.index);
  frame.exposure_begin_ns = observed.exposure_begin_ns;
  frame.exposure_end_ns = observed.exposure_end_ns;
  frame.label = source.unlocked().frames()[observed.index].path;
  return frame;
}

// Solves one window, writes the output frames it owns into the work folder and returns its
// record (written last).
Json RunWindow(const VideoWindow& window, const WindowContext& context) {
  const auto start = Clock::now();
  const VideoRequest& request = *context.request;
  std::vector<TimedFrame> frames;
  for (const VideoWindowFrame& observed : window.frames) {
    frames.push_back(ReadWindowFrame(*context.source, observed));
  }
  const EventStream events = context.source->ReadEvents(window.begin_ns, window.end_ns);
  WindowInputHash input_hash;
  for (const TimedFrame& frame : frames) input_hash.AddImage(frame.image);
  input_hash.AddEvents(events);
  const double read_s = SecondsSince(start);

  const auto bin_start = Clock::now();
  const Scene scene = MakeScene(frames, events, window.begin_ns, window.end_ns, request.binning);
  const double bin_s = SecondsSince(bin_start);
  MethodOptions window_method = context.method;
  if (window.kind == VideoWindowKind::kInterpolate && context.interpolation_log_offset > 0.0) {
    window_method.reconstruction.objective.event_model.log_offset =
        context.interpolation_log_offset;
  }
  CheckMethodSupports(window_method.method, scene, "window " + std::to_string(window.index));
  MethodOptions method = window_method;  // --max_time_s bounds each window's solve
  StartSolveClock(&method);
  MethodResult run = RunMethod(scene, method, IterationCallback(), false, nullptr);
  // An interrupted window is not recorded: --resume solves it again.
  if (method.reconstruction.stop.Interrupted()) {
    throw InterruptedError("interrupted in window " + std::to_string(window.index));
  }
  int64_t begin = 0, end = 0;
  context.clock->FramesOf(window, &begin, &end);
  double denoise_s = 0.0;
  DenoiseRecord denoise_record;
  if (context.denoiser != nullptr) {
    const auto denoise_start = Clock::now();
    const std::vector<uint8_t> frames_read =
        FramesTheOutputNeeds(window, scene, run.video, context, begin, end);
    denoise_record = DenoiseSolution(*context.denoiser, request.denoise, scene, window_method,
                                     method, nullptr, 0, &frames_read, &run);
    denoise_s = SecondsSince(denoise_start);
  }
  ApplySharpFrameSeams(scene, window_method, &run);
  // A sharp observed frame is the output at its own time, unchanged.
  Video& latent = run.video;
  for (size_t k = 0; k < window.frames.size(); ++k) {
    if (window.frames[k].blurred) continue;
    const int at = latent.NearestFrame(window.frames[k].t_ns);
    if (latent.timestamp_ns(at) == window.frames[k].t_ns) latent.frame(at) = frames[k].image;
  }

  const Video sigma = PredictErrorSigma(scene, latent, ConfidenceFor(window_method, run));

  const auto write_start = Clock::now();
  // Written in place: --resume trusts a window only through its record, written last and
  // atomically (below), and solves a window without one again, rewriting its frames.
  for (const auto& [folder, video] :
       {std::pair<const char*, const Video*>{"confidence", &sigma}, {"frames", &latent}}) {
    for (int64_t n = begin; n < end; ++n) {
      WriteGreyPng16((context.work / folder / (FrameName(n) + ".png")).string(),
                     video->InterpolateAt(context.clock->TimeNs(n)));
    }
  }
  const double write_s = SecondsSince(write_start);

  Json record;
  record["index"] = window.index;
  record["mode"] = NameOf(kVideoWindowKindNames, window.kind);
  Json observed = Json::array();
  for (const VideoWindowFrame& frame : window.frames) {
    observed.push_back({{"index", frame.index},
                        {"timestamp_s", NanosecondsToSeconds(frame.t_ns)},
                        {"blurred", frame.blurred}});
  }
  record["frames"] = std::move(observed);
  record["t_begin_s"] = NanosecondsToSeconds(window.begin_ns);
  record["t_end_s"] = NanosecondsToSeconds(window.end_ns);
  record["output_frames"] = {begin, end};
  record["events"] = scene.num_events;
  record["input_hash"] = input_hash.Hex();
  record["hot_pixels"] = scene.hot_pixels.size();
  record["saturated_pixels"] = scene.saturated_pixels.size();
  record["flickering_pixels"] = scene.flickering_pixels.size();
  record["noise_events"] = scene.noise_events;
  record["event_frames"] = scene.events.num_frames();
  record["latent_frames"] = latent.num_frames();
  record["solved"] = run.solved;
  record["message"] = run.message;
  record["iterations"] = run.iterations;
  record["linear_solver_iterations"] = run.reconstruction.linear_solver_iterations;
  if (context.method.method == Method::kCeresLm && run.solved) {
    record["ceres"] = CeresWorkJson(run.reconstruction.ceres);
  }
  if (!run.reconstruction.model.description.empty())
    record["model"] = run.reconstruction.model.description;
  record["initial_cost"] = Number(run.initial_cost);
  record["final_cost"] = Number(run.final_cost);
  // With --denoise=once: the fraction of the denoiser's correction this window's frames had
  // observed (taken out to keep them as the solve left them).
  if (denoise_record.consistent) {
    record["consistency_removed"] = Number(denoise_record.consistency.RemovedFraction());
  }
  if (context.denoiser != nullptr) record["denoised_frames"] = denoise_record.stats.frames;
  if (!window.truth_frames.empty()) {
    const Video blend = InitializeLatentVideo(scene);
    Json scores = Json::array();
    for (const int index : window.truth_frames) {
      const Image truth = context.source->ReadImage(index);
      const int64_t t_ns = context.source->unlocked().frames()[index].t_ns;
      const Image estimate = latent.InterpolateAt(t_ns);
      const Image blended = blend.InterpolateAt(t_ns);
      scores.push_back({{"index", index},
                        {"psnr", Number(Psnr(estimate, truth))},
                        {"ssim", Number(Ssim(estimate, truth))},
                        {"within_predicted_sigma",
                         Number(ShareWithinSigma(estimate, truth, sigma.InterpolateAt(t_ns)))},
                        {"blend_psnr", Number(Psnr(blended, truth))},
                        {"blend_ssim", Number(Ssim(blended, truth))}});
    }
    record["truth"] = std::move(scores);
  }
  record["time_s"] = {{"read", Number(read_s)},
                      {"bin", Number(bin_s)},
                      {"build", Number(run.build_time_s)},
                      {"solve", Number(run.solve_time_s)},
                      {"denoise", Number(denoise_s)},
                      {"write", Number(write_s)},
                      {"total", Number(SecondsSince(start))}};
  WriteFileAtomically(context.work / "windows" / (FrameName(window.index) + ".json"),
                      record.dump(2) + "\n");
  return record;
}

void LinkFrame(const fs::path& from, const fs::path& to) {
  std::error_code error;
  fs::create_hard_link(from, to, error);
  if (error) {
    error.clear();
    fs::copy_file(from, to, error);
  }
  if (error) throw InputError(InputError::Kind::kUnwritable, to.string(), 0, error.message());
}

// preview.mp4: the last observed frame | the reconstruction | the step's events (red: brighter,
// blue: darker, on grey).
void WritePreview(const std::vector<VideoWindow>& windows, const SharedSource& source,
                  const OutputClock& clock, double fps, const fs::path& work,
                  const fs::path& path) {
  const int width = source.unlocked().width(), height = source.unlocked().height();
  Mp4Writer writer(path.string(), fps, 3 * width, height);
  std::vector<unsigned char> pixels(static_cast<size_t>(3) * 3 * width * height);
  const auto put_grey = [&](int panel, const Image& image) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const auto byte =
            static_cast<unsigned char>(std::lround(std::clamp(image(y, x), 0.0, 1.0) * 255.0));
        unsigned char* pixel =
            &pixels[3 * (static_cast<size_t>(y) * 3 * width + panel * width + x)];
        pixel[0] = pixel[1] = pixel[2] = byte;
      }
    }
  };
  const int64_t step_ns = SecondsToNanoseconds(1.0 / fps);
  for (const VideoWindow& window : windows) {
    int64_t begin = 0, end = 0;
    clock.FramesOf(window, &begin, &end);
    if (begin == end) continue;
    const int64_t events_begin_ns = clock.TimeNs(begin) - step_ns;
    const EventStream events = source.ReadEvents(events_begin_ns, clock.TimeNs(end - 1) + 1);
    std::vector<Image> observed;
    for (const VideoWindowFrame& frame : window.frames)
      observed.push_back(source.ReadImage(frame.index));
    size_t next_event = 0;
    for (int64_t n = begin; n < end; ++n) {
      const int64_t t_ns = clock.TimeNs(n);
      const size_t shown = window.frames.size() > 1 && t_ns >= window.frames[1].t_ns ? 1 : 0;
      put_grey(0, observed[shown]);
      put_grey(1, ReadGreyImage((work / "frames" / (FrameName(n) + ".png")).string()));
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          unsigned char* pixel = &pixels[3 * (static_cast<size_t>(y) * 3 * width + 2 * width + x)];
          pixel[0] = pixel[1] = pixel[2] = 128;
        }
      }
      const int64_t previous_ns = n > 0 ? clock.TimeNs(n - 1) : t_ns - step_ns;
      while (next_event < events.size() && events.t_ns(next_event) <= t_ns) {
        if (events.t_ns(next_event) > previous_ns) {
          unsigned char* pixel =
              &pixels[3 * (static_cast<size_t>(events.y(next_event)) * 3 * width + 2 * width +
                           events.x(next_event))];
          const bool brighter = events.polarity(next_event) > 0;  // BGR order
          pixel[0] = brighter ? 0 : 255;
          pixel[1] = 0;
          pixel[2] = brighter ? 255 : 0;
        }
        ++next_event;
      }
      writer.WriteBgr(pixels.data());
    }
  }
  writer.Close();
}

// The records of the windows an interrupted run finished that this run reuses: those whose
// every output frame is still in the work folder and whose recording still gives them the same
// frames and events. The fingerprint does not see a recording edited in place, so each
// window's input is read again (no solve, a small part of solving it). Sets `changed` to the
// windows left out because their input changed.
std::map<int, Json> ReusableWindows(std::map<int, Json> records,
                                    const std::vector<VideoWindow>& windows,
                                    const OutputClock& clock, const fs::path& work,
                                    const SharedSource& source, int* changed) {
  for (auto it = records.begin(); it != records.end();) {
    bool complete = it->first >= 0 && it->first < static_cast<int>(windows.size());
    if (complete) {
      int64_t begin = 0, end = 0;
      clock.FramesOf(windows[it->first], &begin, &end);
      for (int64_t n = begin; n < end && complete; ++n) {
        complete = fs::is_regular_file(work / "frames" / (FrameName(n) + ".png"));
      }
    }
    it = complete ? std::next(it) : records.erase(it);
  }
  const int recorded = static_cast<int>(records.size());
  *changed = 0;
  for (auto it = records.begin(); it != records.end();) {
    const bool same = it->second.contains("input_hash") && it->second["input_hash"].is_string() &&
                      it->second["input_hash"].get<std::string>() ==
                          ReadWindowInputHash(windows[it->first], source);
    if (!same) ++*changed;
    it = same ? std::next(it) : records.erase(it);
  }
  if (*changed > 0) {
    std::fprintf(stderr,
                 "evfs: --resume: the recording changed since the interrupted run: recomputing "
                 "%d of the %d windows it had finished\n",
                 *changed, recorded);
  }
  return records;
}

// Solves the windows of `pending` and adds their records to `records`; returns how many were
// solved. In one process (or a worker) each of `jobs` threads takes the next window as it
// becomes free, from `pending` or, in a worker, from its coordinator; a coordinator hands them
// out and reads back the records its workers wrote. Ends early, leaving the finished windows
// recorded, when a window fails (its error is rethrown) or a stop is requested.
int SolveWindows(const std::vector<VideoWindow>& windows, const std::vector<int>& pending, int jobs,
                 const WindowContext& context, const std::string& fingerprint,
                 VideoProgress* progress, std::map<int, Json>* records) {
  const VideoRequest& request = *context.request;
  const VideoDistribution* distribution = request.distribution;
  if (distribution != nullptr && distribution->coordinator) {
    distribution->serve(pending);
    *records = PrepareVideoWorkFolder(context.work, fingerprint, /*resume=*/true);
    for (const int index : pending) {
      if (records->count(index) != 0)
        progress->events_done += (*records)[index]["events"].get<int64_t>();
    }
    return static_cast<int>(pending.size());
  }
  const bool worker = distribution != nullptr;
  const auto solve_start = Clock::now();
  std::mutex take_mutex, progress_mutex;
  size_t next_pending = 0;
  int solved = 0;
  std::atomic<bool> failed(false);
  const auto take = [&]() -> int {
    const std::lock_guard<std::mutex> lock(take_mutex);
    if (failed) return -1;  // an earlier window failed: the run ends with its error
    if (request.method.interrupt != nullptr && request.method.interrupt->load()) {
      failed = true;
      return -1;
    }
    if (worker) return distribution->next();
    return next_pending < pending.size() ? pending[next_pending++] : -1;
  };
  ParallelForEach(jobs, jobs, [&](int) {
    for (int index = take(); index >= 0; index = take()) {
      try {
        Json record = RunWindow(windows[index], context);
        const std::lock_guard<std::mutex> lock(progress_mutex);
        progress->events_done += record["events"].get<int64_t>();
        ++progress->windows_done;
        ++solved;
        progress->elapsed_s = SecondsSince(solve_start);
        (*records)[index] = std::move(record);
        if (request.progress) request.progress(*progress);
      } catch (const InterruptedError&) {
        // Not a failure of the run: the work folder stays for resume (the caller checks).
        failed = true;
      } catch (...) {
        failed = true;
        throw;
      }
    }
  });
  return solved;
}

// Writes the output into `out` (the OutputTarget's staging folder): frames/ and confidence/
// (hard links into the work folder, so an interrupted assembly loses nothing), timestamps.txt,
// video.mp4 and, with `preview`, preview.mp4. Returns video.mp4's codec. `stop_if_requested`
// runs before each frame.
std::string AssembleVideo(const std::vector<VideoWindow>& windows, const SharedSource& source,
                          const OutputClock& clock, double fps, int64_t output_frames, bool preview,
                          const fs::path& work, const fs::path& out,
                          const std::function<void()>& stop_if_requested) {
  fs::create_directories(out / "frames");
  fs::create_directories(out / "confidence");
  std::vector<int64_t> times;
  for (int64_t n = 0; n < output_frames; ++n) {
    stop_if_requested();
    for (const char* folder : {"frames", "confidence"}) {
      LinkFrame(work / folder / (FrameName(n) + ".png"), out / folder / (FrameName(n) + ".png"));
    }
    times.push_back(clock.TimeNs(n));
  }
  WriteTimestampsTxt((out / "timestamps.txt").string(), times);
  std::string codec;
  {
    Mp4Writer video((out / "video.mp4").string(), fps, source.unlocked().width(),
                    source.unlocked().height());
    for (int64_t n = 0; n < output_frames; ++n) {
      stop_if_requested();
      video.WriteGrey(ReadGreyImage((work / "frames" / (FrameName(n) + ".png")).string()));
    }
    video.Close();
    codec = video.codec();
  }
  if (preview) WritePreview(windows, source, clock, fps, work, out / "preview.mp4");
  return codec;
}

// Every withheld frame's score in the windows' records, in window order.
std::vector<VideoTruthScore> TruthScores(const std::vector<Json>& records) {
  const auto number = [](const Json& score, const char* key) {
    return score[key].is_number() ? score[key].get<double>() : 0.0;
  };
  std::vector<VideoTruthScore> scores;
  for (const Json& record : records) {
    if (!record.contains("truth")) continue;
    for (const Json& score : record["truth"]) {
      VideoTruthScore truth;
      truth.psnr = number(score, "psnr");
      truth.ssim = number(score, "ssim");
      truth.blend_psnr = number(score, "blend_psnr");
      truth.blend_ssim = number(score, "blend_ssim");
      truth.has_within_sigma =
          score.contains("within_predicted_sigma") && score["within_predicted_sigma"].is_number();
      if (truth.has_within_sigma)
        truth.within_sigma = score["within_predicted_sigma"].get<double>();
      scores.push_back(truth);
    }
  }
  return scores;
}

// summary.json of a finished run.
Json VideoSummary(const VideoRequest& request, const VideoResult& result, const OutputClock& clock,
                  const std::string& denoiser, std::vector<Json> window_records) {
  Json summary;
  summary["command"] = "video";
  summary["data"] = request.data_label.empty() ? request.data_path : request.data_label;
  summary["width"] = result.width;
  summary["height"] = result.height;
  summary["fps"] = Number(result.fps);
  summary["output_frames"] = result.output_frames;
  summary["t_begin_s"] = NanosecondsToSeconds(clock.TimeNs(0));
  summary["resampling"] =
      "linear between the two latent frames around each output time; sharp observed frames "
      "exact at their own times";
  summary["confidence"] = {
      {"folder", "confidence"},
      {"meaning",
       "predicted one-sigma error of each output pixel's intensity (scene/confidence.h)"},
      {"scale", "sigma = png value / 65535, intensities in [0, 1]"}};
  summary["video"] = {{"file", "video.mp4"}, {"codec", result.codec}};
  if (request.preview) summary["preview"] = "preview.mp4";
  summary["solver"] = MethodName(request.method.method);
  if (result.log_offset_choice) {
    summary["log_offset_search"] = LogOffsetChoiceJson(*result.log_offset_choice);
  }
  summary["settings"] = request.settings;
  summary["denoiser"] = denoiser;
  summary["events"] = result.events;
  summary["skipped_frames"] = result.skipped_frames;
  if (!result.exposure_tests.empty()) {
    // Whether each exposure blurred its frame, decided from the frame and its events.
    Json tests = Json::array();
    for (const auto& [index, estimate] : result.exposure_tests) {
      tests.push_back({{"frame", index},
                       {"blurred", estimate.blurred},
                       {"predicted_blur_rms", Number(estimate.predicted_blur_rms)},
                       {"noise_sigma", Number(estimate.noise_sigma)}});
    }
    summary["exposures"] = std::move(tests);
  }
  if (result.truth_frames > 0) {
    summary["truth"] = {{"frames", result.truth_frames},
                        {"mean_psnr", Number(result.mean_psnr)},
                        {"worst_psnr", Number(result.worst_psnr)},
                        {"mean_ssim", Number(result.mean_ssim)},
                        {"worst_ssim", Number(result.worst_ssim)},
                        {"blend_mean_psnr", Number(result.mean_blend_psnr)},
                        {"blend_mean_ssim", Number(result.mean_blend_ssim)},
                        {"mean_within_predicted_sigma", Number(result.mean_within_sigma)}};
  }
  summary["run"] = {{"jobs", result.jobs},
                    {"threads_per_window", result.threads_per_window},
                    {"windows_resumed", result.windows_resumed},
                    {"windows_changed", result.windows_changed},
                    {"solve_wall_s", Number(result.solve_wall_s)},
                    {"total_wall_s", Number(result.total_wall_s)},
                    {"windows_per_s", Number(result.windows_per_s)},
                    {"events_per_s", Number(result.events_per_s)}};
  summary["windows"] = std::move(window_records);
  return summary;
}

}  // namespace

bool VideoRequest::IsValid(std::string* error) const {
  OptionChecker check;
  check.Valid(windows)
      .Require(std::isfinite(fps) && (fps == 0.0 || fps >= kMinVideoFps), "--fps",
               "0 (derived) or at least 1 frame per second")
      .Require(!(fps > kMaxVideoFps), "--fps",
               "at most 1e9 frames per second (output times are whole nanoseconds)")
      .InRange("--jobs", jobs, 0, kMaxThreads)
      .InRange("--threads", threads_per_window, 0, kMaxThreads)
      .Valid(method.reconstruction)
      .Valid(binning);
  return check.Passed(error);
}

std::string VideoProgressLine(const VideoProgress& progress) {
  constexpr int kBarWidth = 20;
  const int total = std::max(progress.windows_total, 1);
  const int filled = kBarWidth * progress.windows_done / total;
  std::string line = "[" + std::string(filled, '#') + std::string(kBarWidth - filled, '.') + "] ";
  char text[160];
  const int solved = progress.windows_done - progress.windows_resumed;
  const int left = progress.windows_total - progress.windows_done;
  const double eta_s = solved > 0 ? progress.elapsed_s / solved * left : 0.0;
  const double events_per_s = progress.elapsed_s > 0.0
                                  ? static_cast<double>(progress.events_done) / progress.elapsed_s
                                  : 0.0;
  std::snprintf(
      text, sizeof(text), "%d/%d windows, %.1f s, ETA %s, %.1f k events/s", progress.windows_done,
      progress.windows_total, progress.elapsed_s,
      solved > 0 ? (std::to_string(static_cast<int>(std::ceil(eta_s))) + " s").c_str() : "?",
      events_per_s / 1000.0);
  return line + text;
}

namespace {

// VideoRequest::log_offset_search: each candidate b interpolates, on pairs of neighbouring
// interpolation windows spread over the video, their shared frame from the two outer ones; the
// best b serves every interpolation window (app/log_offset_search.h). One pair per
// kWindowsPerValidationTriplet windows, at least one and at most kLogOffsetSearchTriplets: a
// triplet's solves cost about a tenth of a short video's (shapes_rotation_13_20 at 500 fps, seven
// windows).
constexpr size_t kWindowsPerValidationTriplet = 10;

void SearchLogOffset(const std::vector<VideoWindow>& windows, const SharedSource& source,
                     const VideoRequest& request, int threads, VideoResult* result) {
  if (request.log_offset_search.empty() || !SearchesLogOffset(request.method)) return;
  const auto start = Clock::now();
  // Neighbouring interpolation windows that share a frame, all three frames sharp.
  std::vector<size_t> pairs;
  for (size_t i = 0; i + 1 < windows.size(); ++i) {
    const VideoWindow& a = windows[i];
    const VideoWindow& b = windows[i + 1];
    if (a.kind != VideoWindowKind::kInterpolate || b.kind != VideoWindowKind::kInterpolate ||
        a.frames[1].index != b.frames[0].index) {
      continue;
    }
    if (a.frames[0].blurred || a.frames[1].blurred || b.frames[1].blurred) continue;
    pairs.push_back(i);
  }
  const size_t count =
      std::min({pairs.size(), static_cast<size_t>(kLogOffsetSearchTriplets),
                std::max<size_t>(1, windows.size() / kWindowsPerValidationTriplet)});
  std::vector<ValidationTriplet> triplets;
  std::vector<ValidationScene> scenes;
  for (size_t k = 0; k < count; ++k) {
    const size_t i = pairs[(2 * k + 1) * pairs.size() / (2 * count)];
    const VideoWindow& a = windows[i];
    const VideoWindow& b = windows[i + 1];
    triplets.push_back({a.frames[0].index, a.frames[1].index, b.frames[1].index});
    scenes.push_back(MakeValidationScene(ReadWindowFrame(source, a.frames[0]),
                                         ReadWindowFrame(source, b.frames[1]),
                                         source.ReadImage(a.frames[1].index), a.frames[1].t_ns,
                                         source.ReadEvents(a.begin_ns, b.end_ns), a.begin_ns,
                                         b.end_ns, request.binning, kValidationSquarePx));
  }
  LogOffsetChoice choice =
      ChooseLogOffsetOn(request.log_offset_search, triplets, scenes, request.method, threads,
                        "no two neighbouring interpolation windows between sharp frames");
  choice.seconds = SecondsSince(start);
  result->log_offset_choice = std::move(choice);
}

}  // namespace

VideoResult RunVideo(const VideoRequest& request, const std::string& out_path,
                     const std::string& staging) {
  const auto total_start = Clock::now();
  std::string error;
  if (!request.IsValid(&error)) throw InvalidArgumentError("invalid options: " + error);
  if (request.denoise.mode == DenoiseMode::kPnp) {
    throw InvalidArgumentError("evfs video denoises with --denoise=once or none, not pnp");
  }
  // Loaded before any input is read: a bad weights file fails in milliseconds.
  const std::unique_ptr<Denoiser> denoiser = LoadDenoiser(request.denoise);
  const SharedSource source(request.data_path, request.data_options);
  const DataSource& data = source.unlocked();
  CheckWholeTextRecording(data);

  VideoResult result;
  result.width = data.width();
  result.height = data.height();
  // From the declared size, before a frame is decoded (each window needs two latent frames).
  CheckSensorFitsLatentVoxels(result.width, result.height, request.binning);

  // Plan: which frames, which of them blurred, the windows, the output clock.
  VideoWindowOptions window_options = request.windows;
  if (request.skip_bad_frames) {
    result.skipped_frames = FindUnreadableFrames(data, window_options);
    window_options.excluded_frames.insert(window_options.excluded_frames.end(),
                                          result.skipped_frames.begin(),
                                          result.skipped_frames.end());
  }
  result.exposure_tests = TestExposures(data, window_options);
  for (const auto& [index, estimate] : result.exposure_tests) {
    if (!estimate.blurred) window_options.sharp_frames.push_back(index);
  }
  const std::vector<VideoWindow> windows = PlanVideo(data, window_options);
  result.windows = static_cast<int>(windows.size());
  result.fps = VideoOutputFps(request.fps, windows);
  const OutputClock clock(windows.front().output_begin_ns, result.fps);
  result.output_frames = CheckVideoOutput(windows, clock, result.fps, result.width, result.height);

  // The work folder: the windows an interrupted run finished, and those left to solve.
  const std::string fingerprint =
      WorkFolderFingerprint(request.data_path, result.fps, request.settings, windows, clock);
  const fs::path work = VideoWorkFolder(out_path);
  const bool worker = request.distribution != nullptr && !request.distribution->coordinator;
  // A worker process writes into the work folder its coordinator prepared.
  std::map<int, Json> records =
      worker ? std::map<int, Json>() : PrepareVideoWorkFolder(work, fingerprint, request.resume);
  // The work folder outlives a signal (that is what --resume is for), not an error: a run that
  // failed leaves nothing behind.
  struct RemoveOnError {
    fs::path folder;
    bool armed = true;
    ~RemoveOnError() {
      if (armed) ClearVideoWorkFolder(folder);
    }
  } remove_on_error{work, !worker};
  records =
      ReusableWindows(std::move(records), windows, clock, work, source, &result.windows_changed);
  result.windows_resumed = static_cast<int>(records.size());
  std::vector<int> pending;
  for (const VideoWindow& window : windows) {
    if (records.count(window.index) == 0) pending.push_back(window.index);
  }
  OrderLongestFirst(windows, &pending);

  // Solve.
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const VideoSchedule schedule =
      ScheduleVideo(request.jobs, request.threads_per_window, static_cast<int>(pending.size()),
                    cores, static_cast<int64_t>(result.width) * result.height, AddressSpaceLimit());
  result.jobs = schedule.jobs;
  result.threads_per_window = schedule.threads_per_window;
  if (!schedule.lowered_because.empty() && request.notice) {
    request.notice("--jobs=" + std::to_string(request.jobs) + " lowered to " +
                   std::to_string(result.jobs) + ": " + schedule.lowered_because);
  }
  SearchLogOffset(windows, source, request, cores, &result);
  WindowContext context;
  if (result.log_offset_choice) {
    context.interpolation_log_offset = result.log_offset_choice->chosen;
  }
  context.request = &request;
  context.source = &source;
  context.clock = &clock;
  context.method = request.method;
  context.method.reconstruction.solver.num_threads = result.threads_per_window;
  context.method.adam.num_threads = result.threads_per_window;
  context.method.lbfgs.num_threads = result.threads_per_window;
  context.denoiser = denoiser.get();
  context.work = work;
  VideoProgress progress;
  progress.windows_total = result.windows;
  progress.windows_done = progress.windows_resumed = result.windows_resumed;
  const auto stop_if_requested = [&] {
    if (request.method.interrupt == nullptr || !request.method.interrupt->load()) return;
    remove_on_error.armed = false;
    throw InterruptedError("interrupted: the windows finished so far are kept for --resume");
  };
  const auto solve_start = Clock::now();
  const int solved =
      SolveWindows(windows, pending, result.jobs, context, fingerprint, &progress, &records);
  stop_if_requested();
  result.solve_wall_s = SecondsSince(solve_start);
  result.windows_per_s = result.solve_wall_s > 0.0 ? solved / result.solve_wall_s : 0.0;
  result.events_per_s =
      result.solve_wall_s > 0.0 ? progress.events_done / result.solve_wall_s : 0.0;
  if (worker) {
    remove_on_error.armed = false;
    return result;
  }

  // Assemble and sum up, in the OutputTarget's staging folder.
  const fs::path out = staging;
  result.codec = AssembleVideo(windows, source, clock, result.fps, result.output_frames,
                               request.preview, work, out, stop_if_requested);
  std::vector<Json> window_records;
  for (int i = 0; i < result.windows; ++i) {
    window_records.push_back(records.at(i));
    result.events += window_records.back()["events"].get<int64_t>();
  }
  SummarizeTruth(TruthScores(window_records), &result);
  result.total_wall_s = SecondsSince(total_start);
  const std::string denoiser_name =
      denoiser != nullptr ? NameOf(kDenoiseModeNames, request.denoise.mode) : "none";
  WriteFileAtomically(
      out / "summary.json",
      VideoSummary(request, result, clock, denoiser_name, std::move(window_records)).dump(2) +
          "\n");
  if (request.report) WriteRunReport(out.string());
  remove_on_error.armed = false;
  return result;
}

}  // namespace evfs

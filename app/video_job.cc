#include "evfs/app/video_job.h"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string_view>
#include <thread>

#include "evfs/app/run_report.h"
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

// The marker of a work folder: its first line, then the run's settings.
constexpr char kWorkMarkerFile[] = ".evfs-video-work";
constexpr char kWorkMarkerTitle[] = "evfs video work folder";
// Most output frames a video may have (a runaway --fps would fill the disk).
constexpr int64_t kMaxOutputFrames = 10000000;
// A time beyond any recording's last event, with room to add to it.
constexpr int64_t kFarFutureNs = std::numeric_limits<int64_t>::max() / 4;

// JSON has no inf or nan: they become null.
Json Number(double value) { return std::isfinite(value) ? Json(value) : Json(nullptr); }

std::string FrameName(int64_t n) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06lld", static_cast<long long>(n));
  return name;
}

// Writes `text` to `path` under a temporary name, then renames it: the file appears whole.
void WriteFileAtomically(const fs::path& path, const std::string& text) {
  const fs::path temporary = path.string() + ".tmp";
  std::ofstream file(temporary);
  file << text;
  file.close();
  std::error_code error;
  if (!file || (fs::rename(temporary, path, error), error)) {
    throw InputError(InputError::Kind::kUnwritable, path.string(), 0, "cannot write it");
  }
}

std::string ReadWholeFile(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

bool IsOwnWorkFolder(const fs::path& folder) {
  std::error_code error;
  if (fs::is_symlink(folder, error) || !fs::is_directory(folder, error)) return false;
  const fs::path marker = folder / kWorkMarkerFile;
  if (fs::is_symlink(marker, error) || !fs::is_regular_file(marker, error)) return false;
  std::ifstream file(marker);
  std::string title;
  std::getline(file, title);
  return title == kWorkMarkerTitle;
}

// Whether `name` is a run of decimal digits followed by `suffix`.
bool DigitsThen(std::string_view name, std::string_view suffix) {
  if (name.size() <= suffix.size() || name.substr(name.size() - suffix.size()) != suffix) {
    return false;
  }
  const std::string_view digits = name.substr(0, name.size() - suffix.size());
  return std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Whether `relative` (inside a work folder, '/'-separated) is a path a video run writes there:
// the marker, frames/, confidence/ and windows/ with their files, and each file's temporary name.
bool IsWorkFolderPath(const std::string& relative, bool is_folder) {
  if (is_folder) return relative == "frames" || relative == "confidence" || relative == "windows";
  std::string_view name = relative;
  constexpr std::string_view kTemporary = ".tmp";
  if (name.size() > kTemporary.size() && name.substr(name.size() - kTemporary.size()) == kTemporary)
    name.remove_suffix(kTemporary.size());
  if (name == kWorkMarkerFile) return true;
  for (const std::string_view folder : {"frames/", "confidence/"}) {
    if (name.substr(0, folder.size()) == folder) {
      const std::string_view file = name.substr(folder.size());
      return DigitsThen(file, ".png") || DigitsThen(file, ".tmp.png");
    }
  }
  constexpr std::string_view kWindows = "windows/";
  return name.substr(0, kWindows.size()) == kWindows &&
         DigitsThen(name.substr(kWindows.size()), ".json");
}

// The paths in a work folder that a video run does not write ("REL", "REL/" for a folder),
// and the own files when `own_files` is given. Links are listed, never followed.
std::vector<std::string> WorkFolderForeign(const fs::path& folder,
                                           std::vector<fs::path>* own_files = nullptr) {
  std::vector<std::string> foreign;
  std::error_code error;
  fs::recursive_directory_iterator it(folder, fs::directory_options::none, error);
  for (; !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    const std::string relative = it->path().lexically_relative(folder).generic_string();
    std::error_code status_error;
    const fs::file_status status = it->symlink_status(status_error);
    const bool is_folder = fs::is_directory(status);
    if (IsWorkFolderPath(relative, is_folder) && (is_folder || fs::is_regular_file(status))) {
      if (!is_folder && own_files != nullptr) own_files->push_back(it->path());
      continue;
    }
    foreign.push_back(relative + (is_folder ? "/" : ""));
    if (is_folder) it.disable_recursion_pending();
  }
  std::sort(foreign.begin(), foreign.end());
  if (error) foreign.push_back("(a folder that cannot be listed: " + error.message() + ")");
  return foreign;
}

// Removes what a video run wrote in its work folder, and the folder when nothing else is left
// in it: what the user put there stays.
void RemoveWorkFolder(const fs::path& folder) {
  std::vector<fs::path> own_files;
  std::error_code error;
  if (WorkFolderForeign(folder, &own_files).empty()) {
    fs::remove_all(folder, error);
    return;
  }
  for (const fs::path& file : own_files) fs::remove(file, error);
  for (const char* sub : {"frames", "confidence", "windows", ""}) {
    fs::remove(folder / sub, error);  // if empty
  }
}

// "a, b, c (and 4 more)".
std::string NameSome(const std::vector<std::string>& paths) {
  constexpr size_t kNamed = 3;
  std::string names;
  for (size_t i = 0; i < paths.size() && i < kNamed; ++i) names += (i > 0 ? ", " : "") + paths[i];
  if (paths.size() > kNamed) names += " (and " + std::to_string(paths.size() - kNamed) + " more)";
  return names;
}

// Makes the work folder ready and returns the records of the windows it already holds (only
// with `resume`, and only when the settings match).
std::map<int, Json> PrepareWorkFolder(const fs::path& folder, const std::string& fingerprint,
                                      bool resume) {
  std::error_code error;
  const bool exists = fs::exists(fs::symlink_status(folder, error));
  if (exists && !IsOwnWorkFolder(folder)) {
    throw InvalidArgumentError(folder.string() +
                               " exists and is not an evfs video work folder: evfs keeps "
                               "unfinished windows there; move it away");
  }
  if (exists) {
    // A work folder is reused or replaced whole: nothing the user added may be mixed in or lost.
    const std::vector<std::string> foreign = WorkFolderForeign(folder);
    if (!foreign.empty()) {
      throw InvalidArgumentError(folder.string() +
                                 " (the work folder of this video) holds what "
                                 "evfs did not write: " +
                                 NameSome(foreign) + "; move that away");
    }
  }
  const std::string marker_text = std::string(kWorkMarkerTitle) + "\n" + fingerprint;
  std::map<int, Json> done;
  if (exists && resume) {
    if (ReadWholeFile(folder / kWorkMarkerFile) != marker_text) {
      throw InvalidArgumentError(
          "--resume: the interrupted run in " + folder.string() +
          " had other settings or data; run again without --resume to start over");
    }
    for (const auto& entry : fs::directory_iterator(folder / "windows", error)) {
      if (entry.path().extension() != ".json") continue;
      try {
        Json record = Json::parse(ReadWholeFile(entry.path()));
        const int index = record.at("index").get<int>();
        done[index] = std::move(record);
      } catch (const std::exception&) {
        // An unreadable record is a window to solve again.
      }
    }
    return done;
  }
  error.clear();
  if (exists) fs::remove_all(folder, error);
  if (error || !fs::create_directory(folder, error) || error ||
      !fs::create_directory(folder / "frames", error) ||
      !fs::create_directory(folder / "confidence", error) ||
      !fs::create_directory(folder / "windows", error)) {
    throw InputError(InputError::Kind::kUnwritable, folder.string(), 0,
                     "cannot create the work folder: " + error.message());
  }
  WriteFileAtomically(folder / kWorkMarkerFile, marker_text);
  return done;
}

// What a window depends on, for the fingerprint of a run.
std::string PlanText(const std::vector<VideoWindow>& windows, const OutputClock& clock) {
  std::ostringstream text;
  for (const VideoWindow& window : windows) {
    int64_t begin = 0, end = 0;
    clock.FramesOf(window, &begin, &end);
    text << window.index << ' ' << NameOf(kVideoWindowKindNames, window.kind);
    for (const VideoWindowFrame& frame : window.frames) {
      text << ' ' << frame.index << (frame.blurred ? "b" : "s");
    }
    text << ' ' << window.begin_ns << ' ' << window.end_ns << ' ' << begin << ' ' << end << '\n';
  }
  return text.str();
}

// Serialises reads of the recording (DataSource is not thread-safe) and names bad frames.
class SharedSource {
 public:
  SharedSource(const std::string& path, const DataSourceOptions& options)
      : source_(DataSource::Open(path, options)) {}

  const DataSource& unlocked() const { return *source_; }

  Image ReadImage(int index) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    try {
      return source_->ReadImage(index);
    } catch (const InputError& error) {
      throw InputError(error.kind(), error.file(), error.line(),
                       std::string("frame ") + std::to_string(index) + ": " + error.what() +
                           " (--skip_bad_frames goes on across it)");
    }
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

// Solves one window, writes the output frames it owns into the work folder and returns its
// record (written last).
Json RunWindow(const VideoWindow& window, const WindowContext& context) {
  const auto start = Clock::now();
  const VideoRequest& request = *context.request;
  std::vector<TimedFrame> frames;
  for (const VideoWindowFrame& observed : window.frames) {
    TimedFrame frame;
    frame.image = context.source->ReadImage(observed.index);
    frame.exposure_begin_ns = observed.exposure_begin_ns;
    frame.exposure_end_ns = observed.exposure_end_ns;
    frame.label = context.source->unlocked().frames()[observed.index].path;
    frames.push_back(std::move(frame));
  }
  const EventStream events = context.source->ReadEvents(window.begin_ns, window.end_ns);
  WindowInputHash input_hash;
  for (const TimedFrame& frame : frames) input_hash.AddImage(frame.image);
  input_hash.AddEvents(events);
  const double read_s = SecondsSince(start);

  const auto bin_start = Clock::now();
  const Scene scene = MakeScene(frames, events, window.begin_ns, window.end_ns, request.binning);
  const double bin_s = SecondsSince(bin_start);
  CheckMethodSupports(context.method.method, scene, "window " + std::to_string(window.index));
  MethodOptions method = context.method;  // --max_time_s bounds each window's solve
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
    DenoiseRegion region = SolvedRegion(scene, context.method, run.solved);
    region.frames = FramesTheOutputNeeds(window, scene, run.video, context, begin, end);
    const std::unique_ptr<DenoiseGate> gate =
        MakeDenoiseGate(request.denoise, scene, context.method, run);
    denoise_record = DenoiseLatentVideo(*context.denoiser, request.denoise.mode, region,
                                        request.denoise.consistency ? &scene : nullptr, nullptr, -1,
                                        &run.video, gate.get());
    denoise_s = SecondsSince(denoise_start);
  }
  ApplySharpFrameSeams(scene, context.method, &run);
  // A sharp observed frame is the output at its own time, unchanged.
  Video& latent = run.video;
  for (size_t k = 0; k < window.frames.size(); ++k) {
    if (window.frames[k].blurred) continue;
    const int at = latent.NearestFrame(window.frames[k].t_ns);
    if (latent.timestamp_ns(at) == window.frames[k].t_ns) latent.frame(at) = frames[k].image;
  }

  const Video sigma = PredictErrorSigma(scene, latent, ConfidenceFor(context.method, run));

  const auto write_start = Clock::now();
  // The confidence map first: a frame whose image exists is complete (--resume reads that).
  for (const auto& [folder, video] :
       {std::pair<const char*, const Video*>{"confidence", &sigma}, {"frames", &latent}}) {
    for (int64_t n = begin; n < end; ++n) {
      const fs::path final_path = context.work / folder / (FrameName(n) + ".png");
      const fs::path temporary = context.work / folder / (FrameName(n) + ".tmp.png");
      WriteGreyPng16(temporary.string(), video->InterpolateAt(context.clock->TimeNs(n)));
      std::error_code error;
      fs::rename(temporary, final_path, error);
      if (error) {
        throw InputError(InputError::Kind::kUnwritable, final_path.string(), 0, error.message());
      }
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

}  // namespace

bool VideoRequest::IsValid(std::string* error) const {
  OptionChecker check;
  check.Valid(windows)
      .Require(std::isfinite(fps) && (fps == 0.0 || fps >= kMinVideoFps), "--fps",
               "0 (derived) or at least 1 frame per second")
      .Require(!(fps > kMaxVideoFps), "--fps",
               "at most 1e9 frames per second (output times are whole nanoseconds)")
      .InRange("--jobs", jobs, 0, 4096)
      .InRange("--threads", threads_per_window, 0, 4096)
      .Valid(method.reconstruction)
      .Valid(binning);
  return check.Passed(error);
}

std::string VideoWorkFolder(const std::string& out_path) {
  const fs::path out = fs::path(out_path).lexically_normal();
  const fs::path name = out.has_filename() ? out.filename() : out.parent_path().filename();
  const fs::path parent = out.has_filename() ? out.parent_path() : out.parent_path().parent_path();
  return (parent / ("." + name.string() + ".evfs-video-work")).string();
}

void RemoveVideoWorkFolder(const std::string& out_path) {
  const fs::path folder = VideoWorkFolder(out_path);
  if (IsOwnWorkFolder(folder)) RemoveWorkFolder(folder);
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

int64_t AddressSpaceLimit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return 0;
  return static_cast<int64_t>(std::min<rlim_t>(limit.rlim_cur, INT64_MAX));
}

int CapVideoJobs(int jobs, int windows, int cores, int threads_per_window, int64_t pixels,
                 int64_t address_space_bytes, std::string* why) {
  int capped = std::max(jobs, 1);
  const auto lower = [&](int64_t most, const std::string& reason) {
    most = std::max<int64_t>(most, 1);
    if (capped > most) {
      capped = static_cast<int>(most);
      *why = reason;
    }
  };
  lower(static_cast<int64_t>(cores) * kMaxJobsPerCore,
        "at most " + std::to_string(kMaxJobsPerCore) + " per hardware thread (" +
            std::to_string(cores) + ")");
  if (address_space_bytes > 0) {
    // Each job reserves its threads' stacks and holds its window's frames, events and problem;
    // the rest of the address space is the process' own (libraries, the recording's index).
    rlimit stack{};
    int64_t stack_bytes = kDefaultThreadStackBytes;
    if (getrlimit(RLIMIT_STACK, &stack) == 0 && stack.rlim_cur != RLIM_INFINITY) {
      stack_bytes = static_cast<int64_t>(stack.rlim_cur);
    }
    const int64_t per_job = std::max(threads_per_window, 1) * stack_bytes +
                            std::max<int64_t>(pixels, 1) * kWindowBytesPerPixel;
    lower(address_space_bytes / 2 / per_job,
          "the address space limit (ulimit -v, " + std::to_string(address_space_bytes >> 20) +
              " MiB) leaves room for that many windows' stacks and working memory");
  }
  if (windows > 0)
    lower(windows, "there are only " + std::to_string(windows) + " windows to solve");
  return capped;
}

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
  CheckWholeTextRecording(source.unlocked());
  const DataSource& data = source.unlocked();

  VideoResult result;
  result.width = data.width();
  result.height = data.height();
  // From the declared size, before a frame is decoded (each window needs two latent frames).
  CheckSensorFitsLatentVoxels(result.width, result.height, request.binning);
  VideoWindowOptions window_options = request.windows;
  if (request.skip_bad_frames) {
    const int last = window_options.last >= 0
                         ? std::min<int>(window_options.last, data.frames().size() - 1)
                         : static_cast<int>(data.frames().size()) - 1;
    for (int i = std::max(window_options.first, 0); i <= last; ++i) {
      try {
        source.ReadImage(i);
      } catch (const InputError&) {
        window_options.excluded_frames.push_back(i);
        result.skipped_frames.push_back(i);
      }
    }
  }
  if (window_options.blur_from_data && data.has_events()) {
    for (const int i : SelectedFrames(static_cast<int>(data.frames().size()), window_options)) {
      int64_t begin_ns = 0, end_ns = 0;
      if (!BlurCandidateExposure(data.frames()[i], window_options, &begin_ns, &end_ns)) continue;
      const ExposureBlurEstimate estimate = ExposureBlur(
          source.ReadImage(i), source.ReadEvents(begin_ns, end_ns + 1), begin_ns, end_ns);
      if (!estimate.blurred) window_options.sharp_frames.push_back(i);
      result.exposure_tests.emplace_back(i, estimate);
    }
  }
  // The prediction tail ends at the last event: planned first against a far end, then once
  // more against the last event actually found there.
  std::vector<VideoWindow> windows =
      PlanVideoWindows(data.frames(), data.has_events(), kFarFutureNs, window_options);
  if (data.has_events() && windows.back().kind == VideoWindowKind::kPredict) {
    const VideoWindow& tail = windows.back();
    int64_t last_event_ns = 0;
    if (tail.end_ns >= kFarFutureNs) {
      last_event_ns = data.Summarize().t_last_ns;
    } else {
      const EventStream events = source.ReadEvents(tail.frames[0].t_ns, tail.end_ns);
      // No event after the last frame: a time before it, so that no tail is planned.
      last_event_ns = events.empty() ? tail.frames[0].t_ns - 1 : events.last_t_ns();
    }
    windows = PlanVideoWindows(data.frames(), true, last_event_ns, window_options);
  }
  result.windows = static_cast<int>(windows.size());

  double fps = request.fps;
  if (fps == 0.0) {
    // The observed frames' mean rate (over the interpolation windows, or the one window's
    // length when there are none), times the upsampling.
    int gaps = 0;
    int64_t span_ns = 0;
    for (const VideoWindow& window : windows) {
      if (window.kind != VideoWindowKind::kInterpolate) continue;
      ++gaps;
      span_ns += window.output_end_ns - window.output_begin_ns;
    }
    if (gaps == 0) {
      gaps = 1;
      span_ns = windows.front().output_end_ns - windows.front().output_begin_ns;
    }
    const double observed_rate = gaps / std::max(NanosecondsToSeconds(span_ns), 1e-9);
    fps = std::round(kDefaultUpsampling * observed_rate);
    fps = std::max(fps, 1.0);
  }
  result.fps = fps;
  const OutputClock clock(windows.front().output_begin_ns, fps);
  int64_t ignored = 0;
  clock.FramesOf(windows.back(), &ignored, &result.output_frames);
  if (result.output_frames > kMaxOutputFrames) {
    throw InvalidArgumentError("--fps=" + std::to_string(fps) + " would make " +
                               std::to_string(result.output_frames) + " frames, more than " +
                               std::to_string(kMaxOutputFrames));
  }
  // Each window holds its resampled frames and confidence maps until it writes them.
  int64_t longest_ns = 0;
  for (const VideoWindow& window : windows) {
    longest_ns = std::max(longest_ns, window.output_end_ns - window.output_begin_ns);
  }
  CheckResampledOutputFits(fps, NanosecondsToSeconds(longest_ns), result.width, result.height,
                           "longest window");

  // The run's fingerprint: what must not change for --resume to reuse windows.
  std::ostringstream fingerprint;
  fingerprint << "data " << fs::absolute(request.data_path).lexically_normal().string() << "\n"
              << "fps " << fps << "\n"
              << "settings " << request.settings << "\n"
              << PlanText(windows, clock);
  const fs::path work = VideoWorkFolder(out_path);
  const VideoDistribution* distribution = request.distribution;
  const bool worker = distribution != nullptr && !distribution->coordinator;
  // A worker process writes into the work folder its coordinator prepared.
  std::map<int, Json> records =
      worker ? std::map<int, Json>() : PrepareWorkFolder(work, fingerprint.str(), request.resume);
  // The work folder outlives a signal (that is what --resume is for), not an error: a run that
  // failed leaves nothing behind.
  struct RemoveOnError {
    fs::path folder;
    bool armed = true;
    ~RemoveOnError() {
      if (armed && IsOwnWorkFolder(folder)) RemoveWorkFolder(folder);
    }
  } remove_on_error{work, !worker};
  for (auto it = records.begin(); it != records.end();) {
    // A recorded window is reused only when every frame it wrote is still there.
    bool complete = it->first >= 0 && it->first < result.windows;
    if (complete) {
      int64_t begin = 0, end = 0;
      clock.FramesOf(windows[it->first], &begin, &end);
      for (int64_t n = begin; n < end && complete; ++n) {
        complete = fs::is_regular_file(work / "frames" / (FrameName(n) + ".png"));
      }
    }
    it = complete ? std::next(it) : records.erase(it);
  }
  // A recorded window is reused only when the recording still gives it the same frames and
  // events: the settings' fingerprint above does not see a recording edited in place. Each
  // window's input is read again (no solve), which costs a small part of solving it.
  const int windows_recorded = static_cast<int>(records.size());
  for (auto it = records.begin(); it != records.end();) {
    const bool same = it->second.contains("input_hash") && it->second["input_hash"].is_string() &&
                      it->second["input_hash"].get<std::string>() ==
                          ReadWindowInputHash(windows[it->first], source);
    if (!same) ++result.windows_changed;
    it = same ? std::next(it) : records.erase(it);
  }
  if (result.windows_changed > 0) {
    std::fprintf(stderr,
                 "evfs: --resume: the recording changed since the interrupted run: recomputing "
                 "%d of the %d windows it had finished\n",
                 result.windows_changed, windows_recorded);
  }
  result.windows_resumed = static_cast<int>(records.size());
  std::vector<int> pending;
  for (const VideoWindow& window : windows) {
    if (records.count(window.index) == 0) pending.push_back(window.index);
  }
  OrderLongestFirst(windows, &pending);

  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int threads_per_window =
      request.threads_per_window > 0
          ? request.threads_per_window
          : std::max(1, cores / std::max(1, request.jobs > 0 ? request.jobs : cores));
  std::string capped_because;
  result.jobs =
      CapVideoJobs(request.jobs > 0 ? request.jobs : cores, static_cast<int>(pending.size()), cores,
                   threads_per_window, static_cast<int64_t>(result.width) * result.height,
                   AddressSpaceLimit(), &capped_because);
  if (request.jobs > 0 && result.jobs < request.jobs && request.notice) {
    request.notice("--jobs=" + std::to_string(request.jobs) + " lowered to " +
                   std::to_string(result.jobs) + ": " + capped_because);
  }
  result.threads_per_window = request.threads_per_window > 0 ? request.threads_per_window
                                                             : std::max(1, cores / result.jobs);
  WindowContext context;
  context.request = &request;
  context.source = &source;
  context.clock = &clock;
  context.method = request.method;
  context.method.reconstruction.solver.num_threads = result.threads_per_window;
  context.method.adam.num_threads = result.threads_per_window;
  context.method.lbfgs.num_threads = result.threads_per_window;
  context.denoiser = denoiser.get();
  std::mutex progress_mutex;
  context.work = work;

  VideoProgress progress;
  progress.windows_total = result.windows;
  progress.windows_done = progress.windows_resumed = result.windows_resumed;
  std::atomic<bool> failed(false);
  const auto solve_start = Clock::now();
  // Each of the --jobs threads takes the next window as it becomes free: from the pending
  // list, or, in a worker process, from its coordinator.
  std::mutex take_mutex;
  size_t next_pending = 0;
  int solved = 0;
  const auto stop_requested = [&request] {
    return request.method.interrupt != nullptr && request.method.interrupt->load();
  };
  const auto stop_if_requested = [&] {
    if (!stop_requested()) return;
    remove_on_error.armed = false;
    throw InterruptedError("interrupted: the windows finished so far are kept for --resume");
  };
  const auto take = [&]() -> int {
    const std::lock_guard<std::mutex> lock(take_mutex);
    if (failed) return -1;  // an earlier window failed: the run ends with its error
    if (stop_requested()) {
      failed = true;
      return -1;
    }
    if (worker) return distribution->next();
    return next_pending < pending.size() ? pending[next_pending++] : -1;
  };
  if (distribution != nullptr && distribution->coordinator) {
    distribution->serve(pending);
    // The workers' records, as they wrote them.
    records = PrepareWorkFolder(work, fingerprint.str(), /*resume=*/true);
    solved = static_cast<int>(pending.size());
    for (const int index : pending) {
      if (records.count(index) != 0)
        progress.events_done += records[index]["events"].get<int64_t>();
    }
  } else {
    ParallelForEach(result.jobs, result.jobs, [&](int) {
      for (int index = take(); index >= 0; index = take()) {
        try {
          Json record = RunWindow(windows[index], context);
          const std::lock_guard<std::mutex> lock(progress_mutex);
          progress.events_done += record["events"].get<int64_t>();
          ++progress.windows_done;
          ++solved;
          progress.elapsed_s = SecondsSince(solve_start);
          records[index] = std::move(record);
          if (request.progress) request.progress(progress);
        } catch (const InterruptedError&) {
          // Not a failure of the run: the work folder stays for resume (checked below).
          failed = true;
        } catch (...) {
          failed = true;
          throw;
        }
      }
    });
  }
  stop_if_requested();
  result.solve_wall_s = SecondsSince(solve_start);
  result.windows_per_s = result.solve_wall_s > 0.0 ? solved / result.solve_wall_s : 0.0;
  result.events_per_s =
      result.solve_wall_s > 0.0 ? progress.events_done / result.solve_wall_s : 0.0;
  if (worker) {
    remove_on_error.armed = false;
    return result;
  }

  // Assembly, in the OutputTarget's staging folder.
  const fs::path out = staging;
  fs::create_directories(out / "frames");
  fs::create_directories(out / "confidence");
  std::vector<int64_t> times;
  for (int64_t n = 0; n < result.output_frames; ++n) {
    stop_if_requested();
    for (const char* folder : {"frames", "confidence"}) {
      LinkFrame(work / folder / (FrameName(n) + ".png"), out / folder / (FrameName(n) + ".png"));
    }
    times.push_back(clock.TimeNs(n));
  }
  WriteTimestampsTxt((out / "timestamps.txt").string(), times);
  {
    Mp4Writer video((out / "video.mp4").string(), fps, result.width, result.height);
    for (int64_t n = 0; n < result.output_frames; ++n) {
      stop_if_requested();
      video.WriteGrey(ReadGreyImage((work / "frames" / (FrameName(n) + ".png")).string()));
    }
    video.Close();
    result.codec = video.codec();
  }
  if (request.preview) WritePreview(windows, source, clock, fps, work, out / "preview.mp4");

  Json window_records = Json::array();
  std::vector<double> psnr, ssim, blend_psnr, blend_ssim, within_sigma;
  for (int i = 0; i < result.windows; ++i) {
    const Json& record = records.at(i);
    result.events += record["events"].get<int64_t>();
    if (record.contains("truth")) {
      for (const Json& score : record["truth"]) {
        psnr.push_back(score["psnr"].is_number() ? score["psnr"].get<double>() : 0.0);
        ssim.push_back(score["ssim"].is_number() ? score["ssim"].get<double>() : 0.0);
        blend_psnr.push_back(score["blend_psnr"].is_number() ? score["blend_psnr"].get<double>()
                                                             : 0.0);
        blend_ssim.push_back(score["blend_ssim"].is_number() ? score["blend_ssim"].get<double>()
                                                             : 0.0);
        if (score.contains("within_predicted_sigma") && score["within_predicted_sigma"].is_number())
          within_sigma.push_back(score["within_predicted_sigma"].get<double>());
      }
    }
    window_records.push_back(record);
  }
  const auto mean = [](const std::vector<double>& values) {
    double sum = 0.0;
    for (const double value : values) sum += value;
    return values.empty() ? 0.0 : sum / values.size();
  };
  const auto worst = [](const std::vector<double>& values) {
    return values.empty() ? 0.0 : *std::min_element(values.begin(), values.end());
  };
  result.truth_frames = static_cast<int>(psnr.size());
  result.mean_psnr = mean(psnr);
  result.worst_psnr = worst(psnr);
  result.mean_ssim = mean(ssim);
  result.worst_ssim = worst(ssim);
  result.mean_blend_psnr = mean(blend_psnr);
  result.mean_blend_ssim = mean(blend_ssim);
  result.mean_within_sigma = mean(within_sigma);
  result.total_wall_s = SecondsSince(total_start);

  Json summary;
  summary["command"] = "video";
  summary["data"] = request.data_label.empty() ? request.data_path : request.data_label;
  summary["width"] = result.width;
  summary["height"] = result.height;
  summary["fps"] = Number(fps);
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
  summary["settings"] = request.settings;
  summary["denoiser"] =
      denoiser != nullptr ? NameOf(kDenoiseModeNames, request.denoise.mode) : "none";
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
  WriteFileAtomically(out / "summary.json", summary.dump(2) + "\n");
  if (request.report) WriteRunReport(out.string());
  remove_on_error.armed = false;
  return result;
}

}  // namespace evfs

// Writes the recordings that the memory bound is measured on (BENCHMARKS.md, "Memory
// bounded before allocation"), as data folders for `evfs info` and `evfs reconstruct`:
//
//   OUT/hot_pixel    240x180, a quiet synthetic scene (its events simulated) plus one hot
//                    pixel firing --hot_pixel_events times, alternating ON and OFF, spread over
//                    the window between its two frames;
//   OUT/busy_640x480 640x480, a textured scene under a camera pan, with background noise
//                    (uniform in time and pixel): --busy_events (2 M, within 2 %) events
//                    between its two frames, --busy_noise_fraction (half) of them noise.
//
//   build/benchmarks/memory_cases --out=/tmp/evfs-memory [--hot_pixel_events=10000]
//                                 [--busy_events=2000000]
//
// With --add_hot_pixel_to=DIR it writes OUT/NAME_hot instead: the recording DIR (NAME its
// folder name) with the same hot pixel firing --hot_pixel_events times over its events' span,
// to measure what a hot pixel does to the accuracy on real data.
//
// benchmarks/memory_benchmark.sh runs evfs on them under /usr/bin/time -v.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/io/data_source.h"
#include "evfs/io/text_folder.h"

DEFINE_string(out, "",
              "Folder to write hot_pixel/ and busy_640x480/ into (created; must not "
              "hold them already).");
DEFINE_int32(hot_pixel_events, 10000,
             "Events of the hot pixel (between the two frames, or "
             "over the events of --add_hot_pixel_to).");
DEFINE_string(add_hot_pixel_to, "",
              "A recording to copy into OUT/NAME_hot with a hot pixel "
              "added, instead of writing the two synthetic cases.");
DEFINE_int64(busy_events, 2000000, "Events of the 640x480 case (within 2 %: the pan is scaled).");
DEFINE_double(busy_noise_fraction, 0.5,
              "Fraction of the 640x480 case's events that are "
              "background noise (which collision binning turns into thousands of frames).");

namespace evfs {
namespace {

namespace fs = std::filesystem;

// The hot pixel: a quiet corner of the synthetic scene and of the shared DAVIS snippets.
constexpr int kHotX = 17;
constexpr int kHotY = 23;
// Rendering rate of the scenes the events are simulated from: several renderings per pixel of
// motion, so that events are spread in time as a real sensor's are.
constexpr double kRenderFps = 2000.0;
// Window between the two frames of each case.
constexpr double kWindowS = 0.04;

// A recording of two frames (the first and last rendering) with `events`.
void WriteTwoFrames(const std::string& folder, const Video& rendered, const EventStream& events) {
  std::vector<FrameInfo> frames(2);
  std::vector<Image> images;
  const int indices[2] = {0, rendered.num_frames() - 1};
  for (int i = 0; i < 2; ++i) {
    frames[i].t_ns = rendered.timestamp_ns(indices[i]);
    frames[i].path = "images/frame_" + std::to_string(i) + ".png";
    images.push_back(rendered.frame(indices[i]));
  }
  WriteDataFolder(folder, events, frames, images);
  std::printf("%s: %dx%d, %zu events, 2 frames %.3f s apart\n", folder.c_str(), rendered.width(),
              rendered.height(), events.size(), kWindowS);
}

// `events` plus `count` events at (x, y) spread evenly over (t_begin_ns, t_end_ns), alternating
// in polarity, merged in time order.
EventStream WithHotPixel(const EventStream& events, int x, int y, int count, int64_t t_begin_ns,
                         int64_t t_end_ns) {
  std::vector<std::tuple<int64_t, uint16_t, uint16_t, int8_t>> all;
  all.reserve(events.size() + count);
  for (size_t i = 0; i < events.size(); ++i) {
    all.emplace_back(events.t_ns(i), events.x(i), events.y(i), events.polarity(i));
  }
  for (int i = 0; i < count; ++i) {
    all.emplace_back(t_begin_ns + 1 + (t_end_ns - t_begin_ns - 2) * i / count,
                     static_cast<uint16_t>(x), static_cast<uint16_t>(y), i % 2 ? 1 : -1);
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  EventStream merged(events.width(), events.height());
  merged.reserve(all.size());
  for (const auto& [t_ns, ex, ey, polarity] : all) merged.push_back(t_ns, ex, ey, polarity);
  return merged;
}

void WriteHotPixelCase(const std::string& folder) {
  SceneOptions scene;  // DAVIS240-sized, slow shapes: fewer collision frames than auto's 48
  scene.num_shapes = 3;
  scene.max_speed_px_per_s = 60.0;
  scene.max_rotation_rad_per_s = 0.5;
  scene.duration_s = kWindowS;
  const Video rendered = SceneSynthesizer(scene).RenderAtRate(kRenderFps);
  const EventStream quiet = SimulateEvents(rendered, SimulatorOptions());
  const EventStream events =
      WithHotPixel(quiet, kHotX, kHotY, FLAGS_hot_pixel_events, rendered.timestamp_ns(0),
                   rendered.timestamp_ns(rendered.num_frames() - 1));
  WriteTwoFrames(folder, rendered, events);
}

void WriteBusyCase(const std::string& folder) {
  SceneOptions scene;
  scene.width = 640;
  scene.height = 480;
  scene.num_shapes = 12;
  scene.min_shape_size_px = 20.0;
  scene.max_shape_size_px = 80.0;
  scene.duration_s = kWindowS;
  // The event count grows with the pan speed, though not quite linearly (the shapes' own
  // events do not): the speed is scaled until the count is within kCountTolerance of the target.
  constexpr double kCountTolerance = 0.02;
  constexpr int kMaxPasses = 6;
  scene.background_speed_px_per_s = 200.0;
  SimulatorOptions sensor;
  sensor.noise_rate_hz = FLAGS_busy_noise_fraction * static_cast<double>(FLAGS_busy_events) /
                         (static_cast<double>(scene.width) * scene.height * kWindowS);
  Video rendered;
  EventStream events;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    rendered = SceneSynthesizer(scene).RenderAtRate(kRenderFps);
    events = SimulateEvents(rendered, sensor);
    const double target = static_cast<double>(FLAGS_busy_events);
    if (std::abs(static_cast<double>(events.size()) / target - 1.0) <= kCountTolerance) break;
    // The noise is fixed by its rate; the pan scales the rest.
    const double noise = FLAGS_busy_noise_fraction * target;
    scene.background_speed_px_per_s *=
        (target - noise) / std::max(1.0, static_cast<double>(events.size()) - noise);
  }
  WriteTwoFrames(folder, rendered, events);
}

// The recording `input` with the hot pixel added, as a data folder.
void WriteWithHotPixel(const std::string& input, const std::string& folder) {
  const std::unique_ptr<DataSource> source = DataSource::Open(input);
  const EventStream events = source->ReadAllEvents();
  if (events.empty()) throw InvalidArgumentError(input + " has no events to add a hot pixel to");
  std::vector<Image> images;
  for (int i = 0; i < static_cast<int>(source->frames().size()); ++i) {
    images.push_back(source->ReadImage(i));
  }
  const EventStream hot = WithHotPixel(events, kHotX, kHotY, FLAGS_hot_pixel_events,
                                       events.first_t_ns(), events.last_t_ns());
  WriteDataFolder(folder, hot, source->frames(), images);
  std::printf("%s: %s with %d events at (%d, %d)\n", folder.c_str(), input.c_str(),
              FLAGS_hot_pixel_events, kHotX, kHotY);
}

int Main() {
  if (FLAGS_out.empty()) {
    std::fprintf(stderr, "memory_cases: pass --out=DIR (a scratch folder)\n");
    return 2;
  }
  const fs::path out(FLAGS_out);
  if (!FLAGS_add_hot_pixel_to.empty()) {
    fs::path input = fs::path(FLAGS_add_hot_pixel_to).lexically_normal();
    if (input.filename().empty()) input = input.parent_path();  // "DIR/"
    const fs::path folder = out / (input.filename().string() + "_hot");
    if (fs::exists(folder)) {
      std::fprintf(stderr, "memory_cases: %s exists; pass a fresh --out\n", folder.c_str());
      return 2;
    }
    fs::create_directories(out);
    WriteWithHotPixel(FLAGS_add_hot_pixel_to, folder.string());
    return 0;
  }
  for (const char* name : {"hot_pixel", "busy_640x480"}) {
    if (fs::exists(out / name)) {
      std::fprintf(stderr, "memory_cases: %s exists; pass a fresh --out\n", (out / name).c_str());
      return 2;
    }
  }
  fs::create_directories(out);
  WriteHotPixelCase((out / "hot_pixel").string());
  WriteBusyCase((out / "busy_640x480").string());
  return 0;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "writes the hot-pixel and 2 M-event recordings of BENCHMARKS.md's "
      "memory section");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  try {
    return evfs::Main();
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "memory_cases: %s\n", error.what());
    return 2;
  }
}

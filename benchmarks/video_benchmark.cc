// `evfs video` at scale: throughput with --jobs=1 and --jobs=2, peak memory as the
// recording grows 10x (2 s and 20 s synthetic recordings), and the seams where windows meet.
//
// The recordings come from the project's scene synthesizer and event simulator (rendered step
// by step, so that a long recording never sits in memory as a video), frames every 40 ms. Each
// run is the evfs binary in a process of its own (benchmarks/cell_runner.h), so its peak
// resident memory is its own. Prints a table and writes video_benchmark.csv into --work_dir.
//
//   video_benchmark --work_dir=/tmp/vid_bench [--repeats=3] [--denoise=none|auto]
//   video_benchmark --work_dir=/tmp/vid_bench --recordings_only   (WORK/rec_2s, WORK/rec_20s)
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "evfs/benchmarks/cell_runner.h"
#include "evfs/core/metrics.h"
#include "evfs/core/time.h"
#include "evfs/core/video.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/io/data_source.h"
#include "evfs/io/image_io.h"
#include "evfs/io/text_folder.h"

DEFINE_string(work_dir, "", "Scratch folder for the recordings and outputs (created; under /tmp).");
DEFINE_string(evfs, EVFS_BINARY, "The evfs binary.");
DEFINE_int32(repeats, 3, "Runs per row; the table gives medians.");
DEFINE_int32(width, 64, "Sensor width of the synthetic recordings.");
DEFINE_int32(height, 48, "Sensor height of the synthetic recordings.");
DEFINE_bool(recordings_only, false,
            "Write the two recordings (WORK/rec_2s, WORK/rec_20s) and stop, for other benchmarks.");
DEFINE_string(denoise, "none",
              "evfs video's --denoise: none (the solve alone), auto (evfs' default: the shipped "
              "denoiser, once) or once.");

namespace evfs {
namespace {

namespace fs = std::filesystem;

// The rendering rate: the simulator's time resolution, and the output rate, so that output
// frame n is rendered frame n (the ground truth of the seam row).
constexpr double kRenderHz = 500.0;
// A frame every 20 render steps: 40 ms, a DAVIS-like 25 Hz.
constexpr int kStepsPerFrame = 20;

struct Recording {
  std::string folder;
  double duration_s = 0.0;
  int64_t events = 0;
  std::vector<Image> truth;  // every rendered frame (short recordings only)
};

Recording MakeRecording(const fs::path& folder, double duration_s, bool keep_truth) {
  SceneOptions scene;
  scene.width = FLAGS_width;
  scene.height = FLAGS_height;
  scene.duration_s = duration_s;
  scene.num_shapes = 3;
  scene.min_shape_size_px = 5.0;
  scene.max_shape_size_px = 12.0;
  scene.max_speed_px_per_s = 60.0;
  // A slow camera pan keeps every second of a long recording as busy as the first (shapes
  // alone leave the view within seconds).
  scene.background_speed_px_per_s = 10.0;
  const SceneSynthesizer synthesizer(scene);
  EventSimulator simulator(scene.height, scene.width, SimulatorOptions());
  EventStream events(scene.width, scene.height);
  std::vector<FrameInfo> frames;
  std::vector<Image> images;
  Recording recording;
  const int steps = static_cast<int>(std::lround(duration_s * kRenderHz));
  for (int step = 0; step <= steps; ++step) {
    const int64_t t_ns = SecondsToNanoseconds(step / kRenderHz);
    const Image image = synthesizer.Render(step / kRenderHz);
    if (step == 0) {
      simulator.Reset(image, t_ns);
    } else {
      events.Append(simulator.Advance(image, t_ns));
    }
    if (step % kStepsPerFrame == 0) {
      FrameInfo info;
      info.t_ns = t_ns;
      info.path = "images/frame_" + std::to_string(step) + ".png";
      frames.push_back(info);
      images.push_back(image);
    }
    if (keep_truth) recording.truth.push_back(image);
  }
  WriteDataFolder(folder.string(), events, frames, images);
  recording.folder = folder.string();
  recording.duration_s = duration_s;
  recording.events = static_cast<int64_t>(events.size());
  return recording;
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

struct Row {
  std::string recording;
  int64_t events = 0;
  int windows = 0;
  int jobs = 0;
  double wall_s = 0.0, windows_per_s = 0.0, events_per_s = 0.0, peak_mb = 0.0;
};

Row Measure(const Recording& recording, const std::string& name, int jobs, const fs::path& out) {
  std::vector<double> wall, windows_per_s, events_per_s, peak;
  Row row;
  row.recording = name;
  row.events = recording.events;
  row.jobs = jobs;
  for (int repeat = 0; repeat < FLAGS_repeats; ++repeat) {
    const std::vector<std::string> args = {FLAGS_evfs,
                                           "video",
                                           "--data=" + recording.folder,
                                           "--out=" + out.string(),
                                           "--overwrite",
                                           "--fps=" + std::to_string(static_cast<int>(kRenderHz)),
                                           "--jobs=" + std::to_string(jobs),
                                           "--denoise=" + FLAGS_denoise,
                                           "--progress_interval_s=0"};
    const CellRun run = RunCellProcess(args, (out / "summary.json").string(), CellLimits());
    CHECK(run.has_result) << name << ": " << run.failure;
    const nlohmann::json summary = nlohmann::json::parse(run.result);
    row.windows = static_cast<int>(summary["windows"].size());
    wall.push_back(run.wall_s);
    windows_per_s.push_back(summary["run"]["windows_per_s"].get<double>());
    events_per_s.push_back(summary["run"]["events_per_s"].get<double>());
    peak.push_back(run.peak_memory_mb);
  }
  row.wall_s = Median(wall);
  row.windows_per_s = Median(windows_per_s);
  row.events_per_s = Median(events_per_s);
  row.peak_mb = Median(peak);
  return row;
}

// Seams: output frames on observed frames (where windows meet) against the frames one step
// away from them and those in the middle of windows: PSNR against the rendering and the mean
// absolute change from the previous output frame.
void PrintSeams(const Recording& recording, const fs::path& out, std::FILE* csv) {
  double psnr_seam = 0.0, psnr_next = 0.0, psnr_mid = 0.0;
  double change_seam = 0.0, change_next = 0.0, change_mid = 0.0;
  int seams = 0, mids = 0, nexts = 0;
  const auto frame = [&out](size_t n) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", n);
    return ReadGreyImage((out / "frames" / name).string());
  };
  Image previous = frame(0);
  for (size_t n = 1; n < recording.truth.size(); ++n) {
    const Image current = frame(n);
    const double psnr = Psnr(current, recording.truth[n]);
    const double change = (current - previous).abs().mean();
    const int phase = static_cast<int>(n % kStepsPerFrame);
    if (phase == 0) {
      psnr_seam += psnr, change_seam += change, ++seams;
    } else if (phase == 1) {
      psnr_next += psnr, change_next += change, ++nexts;
    } else if (phase == kStepsPerFrame / 2) {
      psnr_mid += psnr, change_mid += change, ++mids;
    }
    previous = current;
  }
  std::printf("\nseams (%s, %d windows): PSNR against the rendering, mean |frame - previous|\n",
              recording.folder.c_str(), seams);
  std::printf("  %-34s %8s %12s\n", "output frames", "PSNR dB", "change");
  std::printf("  %-34s %8.2f %12.5f\n", "on observed frames (the seams)", psnr_seam / seams,
              change_seam / seams);
  std::printf("  %-34s %8.2f %12.5f\n", "one step after a seam", psnr_next / nexts,
              change_next / nexts);
  std::printf("  %-34s %8.2f %12.5f\n", "mid-window", psnr_mid / mids, change_mid / mids);
  std::fprintf(csv, "seam,%f,%f\nafter_seam,%f,%f\nmid_window,%f,%f\n", psnr_seam / seams,
               change_seam / seams, psnr_next / nexts, change_next / nexts, psnr_mid / mids,
               change_mid / mids);
}

int Main() {
  CHECK(!FLAGS_work_dir.empty()) << "--work_dir is required";
  const fs::path work = FLAGS_work_dir;
  fs::create_directories(work);
  const Recording short_recording = MakeRecording(work / "rec_2s", 2.0, true);
  const Recording long_recording = MakeRecording(work / "rec_20s", 20.0, false);
  if (FLAGS_recordings_only) return 0;

  std::vector<Row> rows;
  rows.push_back(Measure(short_recording, "2 s", 1, work / "out_2s_j1"));
  rows.push_back(Measure(short_recording, "2 s", 2, work / "out_2s_j2"));
  rows.push_back(Measure(long_recording, "20 s", 1, work / "out_20s_j1"));
  rows.push_back(Measure(long_recording, "20 s", 2, work / "out_20s_j2"));

  std::FILE* csv = std::fopen((work / "video_benchmark.csv").c_str(), "w");
  CHECK(csv != nullptr);
  std::fprintf(csv, "recording,events,windows,jobs,wall_s,windows_per_s,events_per_s,peak_mb\n");
  std::printf(
      "evfs video, %dx%d synthetic recordings, frames every 40 ms, %d fps output, "
      "median of %d runs\n",
      FLAGS_width, FLAGS_height, static_cast<int>(kRenderHz), FLAGS_repeats);
  std::printf("%-9s %9s %8s %5s %8s %10s %12s %9s\n", "recording", "events", "windows", "jobs",
              "wall s", "windows/s", "events/s", "peak MB");
  for (const Row& row : rows) {
    std::printf("%-9s %9lld %8d %5d %8.2f %10.2f %12.0f %9.1f\n", row.recording.c_str(),
                static_cast<long long>(row.events), row.windows, row.jobs, row.wall_s,
                row.windows_per_s, row.events_per_s, row.peak_mb);
    std::fprintf(csv, "%s,%lld,%d,%d,%f,%f,%f,%f\n", row.recording.c_str(),
                 static_cast<long long>(row.events), row.windows, row.jobs, row.wall_s,
                 row.windows_per_s, row.events_per_s, row.peak_mb);
  }
  std::printf(
      "jobs=2 / jobs=1 windows/s: %.2fx (2 s), %.2fx (20 s); peak memory 20 s / 2 s "
      "(jobs=2): %.2f\n",
      rows[1].windows_per_s / rows[0].windows_per_s, rows[3].windows_per_s / rows[2].windows_per_s,
      rows[3].peak_mb / rows[1].peak_mb);
  PrintSeams(short_recording, work / "out_2s_j1", csv);
  std::fclose(csv);
  return 0;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  return evfs::Main();
}

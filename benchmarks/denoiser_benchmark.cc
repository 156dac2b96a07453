// The residual denoiser: its speed and what it adds to the reconstruction.
//
//   denoiser_benchmark [--weights=FILE.onnx] [--data=../shared/data] [--parts=speed,quality]
//                      [--runs=10] [--csv=FILE] [--out=PICTURE_DIR] [--cases=NAME,...]
//                      [--clip_crop_px=N]
//                      [--pnp_iterations=N --pnp_rho=R --pnp_rho_growth=G]
//                      [--pnp=false] [--generic=false]
//
// speed: ms per 240×180 frame (median of --runs) with 5 %, 25 % and 100 % of the pixels active
//   (a centred rectangle), for one network on OpenCV's own threads and for one network per
//   thread (DenoiserOptions::num_threads).
// quality: the denoiser's validation cases, none of which the trainer may see: adobe240
//   IMG_0004b and IMG_0036 (events simulated as `evfs simulate` does) interpolated (frame 2 from
//   0 and 4) and deblurred (the mean of frames 0–7), slider_depth prediction, shapes_rotation
//   interpolation (frame 3 from 2 and 4) and eslnet_cups deblur (no truth: re-blur PSNR and
//   sharpness). Rows: the model-based reconstruction alone (DMR), DMR + the residual denoiser
//   applied once (RD) and in plug & play (plug_and_play/plug_and_play.h), and DMR + two generic
//   denoisers with their strength tuned on the truth (OpenCV's fastNlMeansDenoising and its
//   TV-L1 denoiser, run on the scored frames only), PSNR / SSIM and ms per frame. With --out, a
//   picture per case (DMR | DMR + RD | truth, a zoomed crop below), as the paper's Fig. 7.
//   --pnp=false and --generic=false leave out the slow rows (their cells read "-"), to compare
//   weights files on the once row alone.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>
#include <string>
#include <vector>

#include "evfs/app/denoise_job.h"
#include "evfs/app/method.h"
#include "evfs/app/reconstruct_job.h"
#include "evfs/benchmarks/benchmark_cases.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/denoiser/denoiser.h"
#include "evfs/io/data_source.h"
#include "evfs/plug_and_play/plug_and_play.h"

DEFINE_string(weights, "", "The denoiser's ONNX file; empty: the shipped weights.");
DEFINE_string(data, EVFS_DATA_DIR, "The shared data folder.");
DEFINE_string(parts, "speed,quality", "speed, quality or both.");
DEFINE_int32(runs, 10, "Runs per speed measurement (the median is reported).");
DEFINE_int32(threads, 2, "Threads of the one-network-per-thread rows.");
DEFINE_int32(tile_size_px, evfs::DenoiserOptions().tile_size_px,
             "Speed: the side of the tiles a frame is cut into (DenoiserOptions).");
DEFINE_string(csv, "", "Also write the quality rows as CSV to this file.");
DEFINE_string(out, "",
              "Write a picture per quality case (DMR | DMR + RD | truth, a zoomed crop below) "
              "as PNG into this folder.");
DEFINE_int32(clip_crop_px, 0,
             "Keep the central N x N pixels of the adobe240 clips (0: whole 500x500 frames).");
DEFINE_string(cases, "",
              "Only the quality cases whose name contains one of these (comma list); empty: all.");
DEFINE_bool(denoise_consistency, evfs::DenoiseRequest().consistency,
            "DMR + RD once: keep the case's frames as the solve matched them, as evfs does by "
            "default (the share of the correction's energy this took out is printed after the "
            "case's name); false: the correction as the network gives it.");
DEFINE_bool(pnp, true, "Quality: run the plug & play row.");
DEFINE_bool(generic, true, "Quality: run the truth-tuned fastNlMeans and TV-L1 rows.");
DEFINE_int32(pnp_iterations, evfs::PlugAndPlayOptions().iterations,
             "Plug & play: ADMM iterations.");
DEFINE_double(pnp_rho, evfs::PlugAndPlayOptions().initial_rho,
              "Plug & play: rho of the first x-update.");
DEFINE_double(pnp_rho_growth, evfs::PlugAndPlayOptions().rho_growth,
              "Plug & play: rho's factor per iteration.");
DEFINE_int32(pnp_solver_iterations, evfs::PlugAndPlayOptions().solver_iterations,
             "Plug & play: LM iterations per x-update.");

namespace evfs {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kSpeedWidth = 240;
constexpr int kSpeedHeight = 180;
constexpr int kSpeedFrames = 8;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string WeightsPath() {
  const std::string path = FLAGS_weights.empty() ? ShippedDenoiserWeights() : FLAGS_weights;
  if (path.empty()) {
    throw InvalidArgumentError("no shipped denoiser weights in this build: pass --weights");
  }
  return path;
}

// A smooth random-looking video (its content does not change the cost of a convolution).
Video SpeedVideo() {
  Video video(kSpeedHeight, kSpeedWidth, kSpeedFrames);
  for (int t = 0; t < kSpeedFrames; ++t) {
    for (int y = 0; y < kSpeedHeight; ++y) {
      for (int x = 0; x < kSpeedWidth; ++x) {
        video.at(t, y, x) = 0.5 + 0.4 * std::sin(0.05 * x + 0.3 * t) * std::cos(0.07 * y);
      }
    }
  }
  return video;
}

// A centred rectangle of `fraction` of the frame, with the frame's aspect ratio.
DenoiseRegion CentredRegion(double fraction) {
  DenoiseRegion region;
  region.pixels.assign(kSpeedWidth * kSpeedHeight, 0);
  const int w = static_cast<int>(std::lround(kSpeedWidth * std::sqrt(fraction)));
  const int h = static_cast<int>(std::lround(kSpeedHeight * std::sqrt(fraction)));
  const int x0 = (kSpeedWidth - w) / 2, y0 = (kSpeedHeight - h) / 2;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) region.pixels[y * kSpeedWidth + x] = 1;
  }
  return region;
}

void RunSpeed() {
  const Video video = SpeedVideo();
  std::printf(
      "\n## Denoiser speed: %s, %dx%d frames, tiles of %d px, median of %d runs of %d frames\n\n",
      WeightsPath().c_str(), kSpeedWidth, kSpeedHeight, FLAGS_tile_size_px, FLAGS_runs,
      kSpeedFrames);
  std::printf("| active area | threads | networks | ms per frame | network pixels per frame |\n");
  std::printf("| --- | --- | --- | --- | --- |\n");
  for (const int networks : {1, FLAGS_threads}) {
    DenoiserOptions options;
    options.weights_path = WeightsPath();
    options.num_threads = networks;
    options.tile_size_px = FLAGS_tile_size_px;
    const Denoiser denoiser(options);
    // One network: OpenCV parallelises each convolution over the threads itself. Several: each
    // network runs on one thread, frames and tiles side by side.
    cv::setNumThreads(networks == 1 ? FLAGS_threads : 1);
    for (const double fraction : {0.05, 0.25, 1.0}) {
      const DenoiseRegion region = CentredRegion(fraction);
      std::vector<double> ms;
      DenoiseStats stats;
      denoiser.Apply(video, region, &stats);  // warm-up: allocation of the layers' buffers
      for (int run = 0; run < FLAGS_runs; ++run) {
        const auto start = Clock::now();
        denoiser.Apply(video, region, &stats);
        ms.push_back(1e3 * SecondsSince(start) / kSpeedFrames);
      }
      std::printf("| %.0f %% | %d | %d | %.2f | %lld |\n", 100 * fraction, FLAGS_threads, networks,
                  Median(ms), static_cast<long long>(stats.network_pixels / kSpeedFrames));
    }
  }
  cv::setNumThreads(-1);
}

// ---- quality ----

// printf into a string.
template <typename... Args>
std::string Format(const char* format, Args... args) {
  char buffer[128];
  std::snprintf(buffer, sizeof(buffer), format, args...);
  return buffer;
}

struct Score {
  double first = 0.0, second = 0.0;  // PSNR and SSIM (cups: re-blur PSNR and sharpness ×1e3)
};

// Sharpness of some frames: the variance of the Laplacian, in which pixel noise counts as much
// as edges, and the edge width (EdgeWidth: the 10–90 % rise across the strongest edges, which
// speckle barely moves; smaller is sharper), pooled over the edges of all the frames.
struct Sharpness {
  double laplacian_variance = 0.0;
  double edge_width_px = 0.0;
};

// The sharpness of `frames` at the edges of `edges` (one image per frame: the truth, or a
// reference video's frames).
Sharpness SharpnessOf(const std::vector<Image>& frames, const std::vector<Image>& edges) {
  Sharpness sharpness;
  double width_sum = 0.0;
  int edge_count = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    sharpness.laplacian_variance += LaplacianVariance(frames[i]) / frames.size();
    const EdgeWidthScore width = EdgeWidth(frames[i], edges[i]);
    if (width.edges > 0) width_sum += width.mean_px * width.edges;
    edge_count += width.edges;
  }
  sharpness.edge_width_px =
      edge_count > 0 ? width_sum / edge_count : std::numeric_limits<double>::quiet_NaN();
  return sharpness;
}

// `video`'s frames nearest `times_ns`.
std::vector<Image> FramesAt(const Video& video, const std::vector<int64_t>& times_ns) {
  std::vector<Image> frames;
  for (const int64_t t_ns : times_ns) frames.push_back(video.frame(video.NearestFrame(t_ns)));
  return frames;
}

// QualityCase::sharpness for frames with a truth at `times_ns`, and the truth's own.
std::function<Sharpness(const Video&)> SharpnessAgainst(const std::vector<int64_t>& times_ns,
                                                        const std::vector<Image>& truth) {
  return [times_ns, truth](const Video& video) {
    return SharpnessOf(FramesAt(video, times_ns), truth);
  };
}

// A validation case: the DMR, DMR + RD once and DMR + RD plug & play videos, and how a video is
// scored.
struct QualityCase {
  std::string name;
  std::string metrics;  // "PSNR / SSIM" or the cups metrics
  bool has_truth = true;
  Video dmr, rd, pnp;
  double rd_ms_per_frame = 0.0;
  double rd_removed = -1.0;  // the share of the correction frame consistency took out; < 0: off
  double pnp_s = 0.0;        // the ADMM iterations: x-updates and denoising
  // The latent frames the score reads: the truth-tuned generic denoisers filter only these
  // (the score does not see the others). Empty: every frame.
  std::vector<int> scored_frames;
  std::function<Score(const Video&)> score;
  // A video's sharpness at the frames the score reads, and the truth's (cups: none).
  std::function<Sharpness(const Video&)> sharpness;
  Sharpness truth_sharpness;
  // The picture: latent frame `picture_frame` next to `reference` (the truth, or the blurred
  // input when there is none), labelled `reference_label`.
  int picture_frame = 0;
  Image reference;
  std::string reference_label;
};

PlugAndPlayOptions PnpFromFlags() {
  PlugAndPlayOptions pnp;
  pnp.iterations = FLAGS_pnp_iterations;
  pnp.initial_rho = FLAGS_pnp_rho;
  pnp.rho_growth = FLAGS_pnp_rho_growth;
  pnp.solver_iterations = FLAGS_pnp_solver_iterations;
  return pnp;
}

// Applies an 8-bit OpenCV denoiser to the `frames` of `video` (empty: all), keeping the float
// precision of the input: the denoiser's change of the quantised frame is added to the frame.
// Other frames are copied unchanged.
Video Apply8Bit(const Video& video, const std::vector<int>& frames,
                const std::function<void(const cv::Mat&, cv::Mat&)>& filter, double* ms_per_frame) {
  Video output = video;
  std::vector<int> selected = frames;
  if (selected.empty()) {
    for (int t = 0; t < video.num_frames(); ++t) selected.push_back(t);
  }
  const auto start = Clock::now();
  for (const int t : selected) {
    cv::Mat frame(video.height(), video.width(), CV_64F, const_cast<double*>(video.frame_data(t)));
    cv::Mat quantised, filtered;
    frame.convertTo(quantised, CV_8U, 255.0);
    filter(quantised, filtered);
    cv::Mat change;
    cv::subtract(filtered, quantised, change, cv::noArray(), CV_64F);
    cv::Mat out(video.height(), video.width(), CV_64F, output.frame_data(t));
    out = frame + change / 255.0;
  }
  *ms_per_frame = 1e3 * SecondsSince(start) / std::max<size_t>(1, selected.size());
  return output;
}

// The best score of `filter` over `strengths` on the truth; `best` receives that strength.
Score TuneOnTruth(const QualityCase& c, const std::vector<double>& strengths,
                  const std::function<void(const cv::Mat&, cv::Mat&, double)>& filter, double* best,
                  double* ms_per_frame) {
  Score best_score{-1e9, 0.0};
  for (const double strength : strengths) {
    double ms = 0.0;
    const Video filtered = Apply8Bit(
        c.dmr, c.scored_frames, [&](const cv::Mat& in, cv::Mat& out) { filter(in, out, strength); },
        &ms);
    const Score score = c.score(filtered);
    if (score.first > best_score.first) {
      best_score = score;
      *best = strength;
      *ms_per_frame = ms;
    }
  }
  return best_score;
}

Score ScoreFrame(const Video& latent, int64_t t_ns, const Image& truth) {
  const Image estimate = latent.frame(latent.NearestFrame(t_ns));
  return {Psnr(estimate, truth), Ssim(estimate, truth)};
}

// A case on a DAVIS snippet, through RunReconstruction as `evfs reconstruct` runs it (once per
// denoising mode: the job does not hand out its scene).
QualityCase DavisCase(const std::string& snippet, Mode mode, int first, int last, int truth) {
  ReconstructRequest request;
  request.data_path = (fs::path(FLAGS_data) / snippet).string();
  request.mode = mode;
  request.first = first;
  request.last = last;
  request.truth = truth;
  QualityCase c;
  c.name = snippet + " " + ModeName(mode);
  request.denoise.mode = DenoiseMode::kNone;
  c.dmr = RunReconstruction(request).run.video;
  request.denoise.denoiser.weights_path = WeightsPath();
  request.denoise.mode = DenoiseMode::kOnce;
  request.denoise.consistency = FLAGS_denoise_consistency;
  const ReconstructResult with_rd = RunReconstruction(request);
  if (with_rd.denoise.consistent) c.rd_removed = with_rd.denoise.consistency.RemovedFraction();
  c.rd = with_rd.run.video;
  c.rd_ms_per_frame = 1e3 * with_rd.denoise.stats.time_s / std::max(1, c.rd.num_frames());
  if (FLAGS_pnp) {
    request.denoise.mode = DenoiseMode::kPnp;
    request.denoise.pnp = PnpFromFlags();
    const ReconstructResult with_pnp = RunReconstruction(request);
    c.pnp = with_pnp.run.video;
    c.pnp_s = with_pnp.denoise.pnp.solve_time_s + with_pnp.denoise.pnp.denoise_time_s;
  }
  const auto source = DataSource::Open(request.data_path);
  if (truth >= 0) {
    c.metrics = "PSNR / SSIM (frame " + std::to_string(truth) + ")";
    const Image truth_image = source->ReadImage(truth);
    const int64_t t_ns = source->frames()[truth].t_ns;
    c.score = [truth_image, t_ns](const Video& video) {
      return ScoreFrame(video, t_ns, truth_image);
    };
    c.picture_frame = c.dmr.NearestFrame(t_ns);
    c.scored_frames = {c.picture_frame};
    c.reference = truth_image;
    c.reference_label = "truth";
    c.sharpness = SharpnessAgainst({t_ns}, {truth_image});
    c.truth_sharpness = SharpnessOf({truth_image}, {truth_image});
  } else {
    c.has_truth = false;
    c.metrics = "re-blur PSNR / sharpness x1e3";
    const Image blurred = source->ReadImage(first);
    c.score = [blurred](const Video& video) {
      const DeblurWithoutTruthScore score = ScoreDeblurWithoutTruth(video, blurred);
      return Score{score.mean_vs_input_psnr, 1e3 * score.latent_sharpness};
    };
    c.picture_frame = c.dmr.num_frames() / 2;
    c.reference = blurred;
    c.reference_label = "blurred input";
    // No truth: every latent frame, at the DMR's edges.
    c.sharpness = SharpnessAgainst(c.dmr.timestamps_ns(), FramesAt(c.dmr, c.dmr.timestamps_ns()));
  }
  return c;
}

// A case on a 240 fps clip with simulated events, through RunMethod on the scene.
QualityCase ClipCase(const std::string& clip_name, bool deblur, const Denoiser& denoiser) {
  const SimulatedClip clip = LoadSimulatedClip(FLAGS_data, clip_name, FLAGS_clip_crop_px);
  const BinningOptions binning;
  const Scene scene =
      deblur ? MakeClipDeblurScene(clip, binning) : MakeClipInterpolationScene(clip, binning);
  const MethodOptions method;
  const MethodResult run = RunMethod(scene, method);
  QualityCase c;
  c.name = clip_name + (deblur ? " deblur" : " interpolate");
  c.dmr = run.video;
  const DenoiseRegion region = SolvedRegion(scene, method, run.solved);
  c.rd = run.video;
  const DenoiseRecord once =
      DenoiseLatentVideo(denoiser, DenoiseMode::kOnce, region,
                         FLAGS_denoise_consistency ? &scene : nullptr, nullptr, -1, &c.rd);
  if (once.consistent) c.rd_removed = once.consistency.RemovedFraction();
  c.rd_ms_per_frame = 1e3 * once.stats.time_s / std::max(1, c.rd.num_frames());
  if (FLAGS_pnp) {
    MethodResult pnp_run = run;
    const DenoiseRecord pnp = PlugAndPlayLatentVideo(denoiser, scene, method, PnpFromFlags(),
                                                     region, nullptr, -1, &pnp_run);
    c.pnp = std::move(pnp_run.video);
    c.pnp_s = pnp.pnp.solve_time_s + pnp.pnp.denoise_time_s;
  }
  if (deblur) {
    c.metrics = "PSNR / SSIM (mean over frames 0-7)";
    c.score = [frames = clip.frames](const Video& video) {
      SimulatedClip reference;  // ScoreClipDeblur reads only the frames
      reference.frames = frames;
      return Score{ScoreClipDeblur(video, reference, Psnr),
                   ScoreClipDeblur(video, reference, Ssim)};
    };
    for (int t = 0; t < kClipFrames; ++t) {
      c.scored_frames.push_back(c.dmr.NearestFrame(clip.frames.timestamp_ns(t)));
    }
    std::sort(c.scored_frames.begin(), c.scored_frames.end());
    c.scored_frames.erase(std::unique(c.scored_frames.begin(), c.scored_frames.end()),
                          c.scored_frames.end());
    std::vector<int64_t> times_ns;
    std::vector<Image> truth;
    for (int t = 0; t < kClipFrames; ++t) {
      times_ns.push_back(clip.frames.timestamp_ns(t));
      truth.push_back(clip.frames.frame(t));
    }
    c.sharpness = SharpnessAgainst(times_ns, truth);
    c.truth_sharpness = SharpnessOf(truth, truth);
    c.picture_frame = c.dmr.NearestFrame(clip.frames.timestamp_ns(kClipFrames / 2));
    c.reference = clip.frames.frame(kClipFrames / 2);
  } else {
    c.metrics = "PSNR / SSIM (frame 2)";
    const Image truth = clip.frames.frame(kClipTruthFrame);
    const int64_t t_ns = clip.frames.timestamp_ns(kClipTruthFrame);
    c.score = [truth, t_ns](const Video& video) { return ScoreFrame(video, t_ns, truth); };
    c.picture_frame = c.dmr.NearestFrame(t_ns);
    c.scored_frames = {c.picture_frame};
    c.reference = truth;
    c.sharpness = SharpnessAgainst({t_ns}, {truth});
    c.truth_sharpness = SharpnessOf({truth}, {truth});
  }
  c.reference_label = "truth";
  return c;
}

cv::Mat ToBgr8(const Image& image) {
  cv::Mat grey(static_cast<int>(image.rows()), static_cast<int>(image.cols()), CV_8U);
  for (int y = 0; y < grey.rows; ++y) {
    for (int x = 0; x < grey.cols; ++x) {
      grey.at<uint8_t>(y, x) =
          cv::saturate_cast<uint8_t>(std::lround(255.0 * std::clamp(image(y, x), 0.0, 1.0)));
    }
  }
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

// The case's picture, as the paper's Fig. 7: DMR | DMR + RD | reference on top, and below each
// the same square crop zoomed, where the denoiser changed the frame most (outlined in red).
void WritePicture(const QualityCase& c, const std::string& folder) {
  const Image dmr = c.dmr.frame(c.picture_frame), rd = c.rd.frame(c.picture_frame);
  const int height = static_cast<int>(dmr.rows()), width = static_cast<int>(dmr.cols());
  const int side = std::max(8, std::min(height, width) / 3);
  // Where |RD − DMR| summed over a crop is largest.
  cv::Mat change(height, width, CV_64F);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) change.at<double>(y, x) = std::abs(rd(y, x) - dmr(y, x));
  }
  cv::Mat summed;
  cv::boxFilter(change, summed, CV_64F, cv::Size(side, side), cv::Point(-1, -1), false,
                cv::BORDER_CONSTANT);
  const cv::Rect inner(side / 2, side / 2, width - side + 1, height - side + 1);
  cv::Point best;
  cv::minMaxLoc(summed(inner), nullptr, nullptr, nullptr, &best);
  const cv::Rect crop(best.x, best.y, side, side);

  constexpr int kLabelPx = 18;
  const std::vector<std::pair<std::string, Image>> panels = {
      {"DMR", dmr}, {"DMR + RD", rd}, {c.reference_label, c.reference}};
  cv::Mat canvas(kLabelPx + height + width, 3 * width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (size_t i = 0; i < panels.size(); ++i) {
    const int x0 = static_cast<int>(i) * width;
    const cv::Mat panel = ToBgr8(panels[i].second);
    cv::putText(canvas, panels[i].first, cv::Point(x0 + 4, kLabelPx - 5), cv::FONT_HERSHEY_SIMPLEX,
                0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    cv::Mat zoomed;
    cv::resize(panel(crop), zoomed, cv::Size(width, width), 0, 0, cv::INTER_NEAREST);
    panel.copyTo(canvas(cv::Rect(x0, kLabelPx, width, height)));
    cv::rectangle(canvas, cv::Rect(x0 + crop.x, kLabelPx + crop.y, crop.width, crop.height),
                  cv::Scalar(0, 0, 255), 1);
    zoomed.copyTo(canvas(cv::Rect(x0, kLabelPx + height, width, width)));
  }
  std::string file = c.name;
  std::replace(file.begin(), file.end(), ' ', '_');
  // JPEG at quality 92, small enough to commit beside BENCHMARKS.md.
  const fs::path path = fs::path(folder) / (file + ".jpg");
  if (!cv::imwrite(path.string(), canvas, {cv::IMWRITE_JPEG_QUALITY, 92})) {
    throw InputError(InputError::Kind::kUnwritable, path.string(), 0, "cannot write the picture");
  }
}

bool Wanted(const std::string& name) {
  if (FLAGS_cases.empty()) return true;
  for (const std::string& part : SplitCommaList(FLAGS_cases)) {
    if (name.find(part) != std::string::npos) return true;
  }
  return false;
}

void RunQuality() {
  if (FLAGS_data.empty() || !fs::is_directory(FLAGS_data)) {
    std::printf("\nquality: no data folder (--data); skipped\n");
    return;
  }
  if (!FLAGS_out.empty()) fs::create_directories(FLAGS_out);
  DenoiserOptions options;
  options.weights_path = WeightsPath();
  const Denoiser denoiser(options);
  const PlugAndPlayOptions pnp = PnpFromFlags();
  std::string error;
  if (!pnp.IsValid(&error)) throw InvalidArgumentError("plug & play flags: " + error);

  std::printf("\n## Denoiser quality: %s (sha256 %s)\n\n", denoiser.weights_path().c_str(),
              denoiser.weights_sha256().c_str());
  std::printf("plug & play: %d iterations, rho %g x %g, %d LM iterations per x-update\n\n",
              pnp.iterations, pnp.initial_rho, pnp.rho_growth, pnp.solver_iterations);
  std::printf(
      "| case | metrics | DMR | DMR + RD once | once gain dB | DMR + RD pnp | pnp gain dB | "
      "fastNlMeans (h) | TV-L1 (lambda) | ms/frame RD, NLM, TV | pnp s |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  std::fflush(stdout);
  std::ofstream csv;
  if (!FLAGS_csv.empty()) {
    csv.open(FLAGS_csv);
    csv << "case,metrics,dmr_1,dmr_2,rd_1,rd_2,pnp_1,pnp_2,nlm_1,nlm_2,nlm_h,tv_1,tv_2,tv_lambda,"
           "rd_ms,nlm_ms,tv_ms,pnp_s\n";
  }

  std::vector<std::function<QualityCase()>> makers;
  std::vector<std::string> names;
  for (const std::string clip : {"adobe240_IMG_0004b", "adobe240_IMG_0036"}) {
    for (const bool deblur : {false, true}) {
      names.push_back(clip + (deblur ? " deblur" : " interpolate"));
      makers.push_back([clip, deblur, &denoiser] { return ClipCase(clip, deblur, denoiser); });
    }
  }
  names.push_back("slider_depth_70_71 predict");
  makers.push_back([] { return DavisCase("slider_depth_70_71", Mode::kPredict, 0, 1, 1); });
  names.push_back("shapes_rotation_13_20 interpolate");
  makers.push_back([] { return DavisCase("shapes_rotation_13_20", Mode::kInterpolate, 2, 4, 3); });
  names.push_back("eslnet_cups_blur deblur");
  makers.push_back([] { return DavisCase("eslnet_cups_blur", Mode::kDeblur, 1, -1, -1); });

  // Gains over DMR on the cases with a truth.
  std::vector<double> once_gain, pnp_gain, nlm_gain;
  std::vector<std::string> sharpness_lines;
  for (size_t i = 0; i < makers.size(); ++i) {
    if (!Wanted(names[i])) continue;
    const QualityCase c = makers[i]();
    const Score dmr = c.score(c.dmr), rd = c.score(c.rd);
    const Score pnp_score = FLAGS_pnp ? c.score(c.pnp) : Score{};
    const std::string name =
        c.name +
        (c.rd_removed >= 0.0 ? Format(" (%.0f %% kept)", 100.0 * (1.0 - c.rd_removed)) : "");
    const char* pair_format = c.has_truth ? "%.2f / %.4f" : "%.2f / %.2f";
    const auto pair = [pair_format](const Score& score) {
      return Format(pair_format, score.first, score.second);
    };
    std::string pnp_cells = "- | -";
    if (FLAGS_pnp) pnp_cells = pair(pnp_score) + Format(" | %+.2f", pnp_score.first - dmr.first);
    double h = 0.0, lambda = 0.0, nlm_ms = 0.0, tv_ms = 0.0;
    Score nlm, tv;
    std::string generic_cells = "n/a | n/a", generic_ms = "-, -";
    if (c.has_truth && FLAGS_generic) {
      nlm = TuneOnTruth(
          c, {1, 2, 3, 5, 7, 10, 15},
          [](const cv::Mat& in, cv::Mat& out, double strength) {
            cv::fastNlMeansDenoising(in, out, static_cast<float>(strength));
          },
          &h, &nlm_ms);
      tv = TuneOnTruth(
          c, {0.25, 0.5, 1.0, 2.0, 4.0},
          [](const cv::Mat& in, cv::Mat& out, double strength) {
            cv::denoise_TVL1({in}, out, strength, 30);
          },
          &lambda, &tv_ms);
      nlm_gain.push_back(nlm.first - dmr.first);
      generic_cells = pair(nlm) + Format(" (%g) | ", h) + pair(tv) + Format(" (%g)", lambda);
      generic_ms = Format("%.1f, %.1f", nlm_ms, tv_ms);
    } else if (c.has_truth) {
      generic_cells = "- | -";
    }
    if (c.has_truth) {
      once_gain.push_back(rd.first - dmr.first);
      if (FLAGS_pnp) pnp_gain.push_back(pnp_score.first - dmr.first);
    }
    std::printf("| %s | %s | %s | %s | %+.2f | %s | %s | %.1f, %s | %s |\n", name.c_str(),
                c.metrics.c_str(), pair(dmr).c_str(), pair(rd).c_str(), rd.first - dmr.first,
                pnp_cells.c_str(), generic_cells.c_str(), c.rd_ms_per_frame, generic_ms.c_str(),
                FLAGS_pnp ? Format("%.1f", c.pnp_s).c_str() : "-");
    if (csv) {
      csv << c.name << "," << c.metrics << "," << dmr.first << "," << dmr.second << "," << rd.first
          << "," << rd.second << "," << pnp_score.first << "," << pnp_score.second << ","
          << nlm.first << "," << nlm.second << "," << h << "," << tv.first << "," << tv.second
          << "," << lambda << "," << c.rd_ms_per_frame << "," << nlm_ms << "," << tv_ms << ","
          << c.pnp_s << "\n";
    }
    if (c.sharpness) {
      const Sharpness before = c.sharpness(c.dmr), after = c.sharpness(c.rd);
      const std::string truth_lv =
          c.has_truth ? Format("truth %.2f, ", 1e3 * c.truth_sharpness.laplacian_variance) : "";
      const std::string truth_width =
          c.has_truth ? Format("truth %.2f, ", c.truth_sharpness.edge_width_px) : "";
      sharpness_lines.push_back(
          Format("* %s: ", c.name.c_str()) + truth_lv +
          Format("DMR %.2f, DMR + RD once %.2f | ", 1e3 * before.laplacian_variance,
                 1e3 * after.laplacian_variance) +
          truth_width +
          Format("DMR %.2f, DMR + RD once %.2f", before.edge_width_px, after.edge_width_px));
    }
    if (!FLAGS_out.empty()) WritePicture(c, FLAGS_out);
    std::fflush(stdout);
  }
  const auto summary = [](const char* label, const std::vector<double>& gains) {
    if (gains.empty()) return;
    double mean = 0.0;
    for (const double gain : gains) mean += gain / gains.size();
    std::printf("%s: mean gain over DMR %+.2f dB, worst case %+.2f dB (%zu cases with a truth)\n",
                label, mean, *std::min_element(gains.begin(), gains.end()), gains.size());
  };
  std::printf("\n");
  summary("DMR + RD once", once_gain);
  summary("DMR + RD pnp", pnp_gain);
  summary("DMR + fastNlMeans (tuned on the truth)", nlm_gain);
  if (!sharpness_lines.empty()) {
    std::printf(
        "\nSharpness of the scored frames (cups: every latent frame): the variance of the "
        "Laplacian x1e3, in which pixel noise counts as much as edges | the edge width in px "
        "(core/metrics.h EdgeWidth: the 10-90 %% rise across the strongest 3 %% of the truth's "
        "edges, cups: the DMR's; speckle barely moves it; smaller is sharper):\n\n");
    for (const std::string& line : sharpness_lines) std::printf("%s\n", line.c_str());
  }
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  try {
    const std::vector<std::string> parts = evfs::SplitCommaList(FLAGS_parts);
    const auto wants = [&parts](const char* part) {
      return std::find(parts.begin(), parts.end(), part) != parts.end();
    };
    if (wants("speed")) evfs::RunSpeed();
    if (wants("quality")) evfs::RunQuality();
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "denoiser_benchmark: %s\n", error.what());
    return 2;
  }
  return 0;
}

// make_denoiser_pairs: the training pairs of the residual denoiser (paper §3.4), made
// by evfs itself. Each sample takes a short ground-truth clip from one of the sources, simulates
// its events, reconstructs one of the three cases with the DMR (Ceres LM, app/method.h) under a
// configuration randomised as the paper's Table 3 does, and writes a few
// (DMR latent frame, ground-truth frame at the same time) pairs.
//
//   make_denoiser_pairs --out=DIR --samples=N [--seed=S] [--first_sample=I]
//                       [--photos=a.jpg,b.png] [--videos=a.avi] [--clips=DIR,DIR]
//                       [--synthetic_weight=1 --photo_weight=1 --video_weight=1 --clip_weight=1]
//                       [--realistic=0]
//
// Sources: synthetic scenes (events/scene_synthesizer.h); photographs moved by a smooth affine
// motion (a camera pan with a little rotation and zoom) rendered at 1 kHz; video files read
// with OpenCV and taken as 240 fps; folders in the text layout (images.txt) taken at their own
// timestamps. What the sources are is the caller's choice: the validation recordings must not
// be among them (models/README.md, tools/train_denoiser/train.sh).
//
// Realistic samples (a share `--realistic` of them) record the clip with the effects of a real
// sensor (`evfs simulate`'s: hot pixels, leak, photoreceptor bandwidth, a mains lamp, frame gain
// that saturates, fixed-pattern and read noise): the pair's truth is then what the same sensor
// would record without temporal read noise (its lamp, gain, saturation and fixed pattern kept),
// since a real recording's truth frame is such a frame.
//
// Output (one folder, written whole or not at all, io/output_target.h):
//   pair_NNNNNNN_K.npy  float32, shape (3, H, W): the DMR latent frame, the ground truth at its
//                       timestamp, and the solver's activity mask (1 where the solver changed
//                       the pixel in some latent frame, 0 where it kept the initialisation)
//   pairs.tsv           one line per pair: file, sample, source, case, size, events, latent
//                       frames and index, PSNR of the initialisation and of the DMR against the
//                       truth, and the randomised configuration
// Values are evfs's linear intensities (core/video.h).
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/app/method.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"
#include "evfs/events/flicker.h"
#include "evfs/events/frame_effects.h"
#include "evfs/events/random.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/io/frame_list.h"
#include "evfs/io/image_io.h"
#include "evfs/io/output_target.h"
#include "evfs/scene/scene.h"

DEFINE_string(out, "", "Output folder: a new one, or an earlier output with --overwrite.");
DEFINE_bool(overwrite, false, "Replace --out when it is an earlier output of this tool.");
DEFINE_int32(samples, 100, "Reconstructions to run; each gives up to --pairs_per_sample pairs.");
DEFINE_int32(first_sample, 0, "Index of the first sample (samples are seeded by their index).");
DEFINE_uint64(seed, 17, "Seeds every random choice, together with the sample index.");
DEFINE_int32(pairs_per_sample, 3, "Most latent frames written per reconstruction.");
DEFINE_int32(threads, 1, "Ceres threads per reconstruction.");
DEFINE_string(photos, "", "Comma-separated photographs to move (any format OpenCV reads).");
DEFINE_string(videos, "", "Comma-separated video files (taken as 240 fps).");
DEFINE_string(clips, "", "Comma-separated folders with images.txt (frames at their timestamps).");
DEFINE_double(synthetic_weight, 1.0, "Relative frequency of synthetic scenes.");
DEFINE_double(photo_weight, 1.0, "Relative frequency of moving photographs.");
DEFINE_double(video_weight, 1.0, "Relative frequency of video files.");
DEFINE_double(clip_weight, 1.0, "Relative frequency of frame folders.");
DEFINE_double(realistic, 0.0,
              "Share of samples, in [0, 1], recorded with a real sensor's effects (hot pixels, "
              "leak, bandwidth, mains lamp, saturation, fixed-pattern and read noise).");
DEFINE_bool(quiet, false, "Print only the final count.");

namespace evfs {
namespace {

namespace fs = std::filesystem;

// Frame rate of the photographs' rendering: their motion is at most ~0.6 px per rendered frame,
// so the simulator's linear interpolation between frames is close to the continuous motion.
constexpr double kPhotoRenderFps = 1000.0;
// Nominal rate of video files: the shipped samples are 25–30 fps recordings of slow motion;
// halved in size and read as 240 fps, their motion per frame is that of the 240 fps clips.
constexpr double kVideoFps = 240.0;
constexpr double kVideoScale = 0.5;
// Added to a sample's seed for the realistic sensor's own random stream.
constexpr uint64_t kRealisticSeedOffset = 0x5eed5eedULL;
// Latent frames farther than this fraction of the source's frame period from a source frame
// get no pair: between the frames of a clip the truth is only a linear interpolation.
constexpr double kMaxTruthOffsetPeriods = 0.25;

struct PairGeneratorOptions {
  std::string out;
  int samples = 100;
  int first_sample = 0;
  uint64_t seed = 17;
  int pairs_per_sample = 3;
  int threads = 1;
  std::vector<std::string> photos, videos, clips;
  double synthetic_weight = 1.0, photo_weight = 1.0, video_weight = 1.0, clip_weight = 1.0;
  double realistic = 0.0;

  bool IsValid(std::string* error) const {
    OptionChecker check;
    check.Check(!out.empty(), "--out is required");
    check.Check(samples >= 1, "--samples must be >= 1");
    check.Check(first_sample >= 0, "--first_sample must be >= 0");
    check.Check(pairs_per_sample >= 1, "--pairs_per_sample must be >= 1");
    check.Check(threads >= 1, "--threads must be >= 1");
    check.Check(synthetic_weight >= 0 && photo_weight >= 0 && video_weight >= 0 && clip_weight >= 0,
                "source weights must be >= 0");
    check.Check(realistic >= 0 && realistic <= 1, "--realistic must be in [0, 1]");
    const double total = synthetic_weight + (photos.empty() ? 0 : photo_weight) +
                         (videos.empty() ? 0 : video_weight) + (clips.empty() ? 0 : clip_weight);
    check.Check(total > 0, "no source: give a positive weight to a source that has files");
    return check.Passed(error);
  }
};

std::vector<std::string> SplitList(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream stream(list);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

double LogUniform(Random* random, double low, double high) {
  return std::exp(random->Uniform(std::log(low), std::log(high)));
}

Image MatToImage(const cv::Mat& grey8) {
  Image image(grey8.rows, grey8.cols);
  for (int y = 0; y < grey8.rows; ++y) {
    for (int x = 0; x < grey8.cols; ++x) image(y, x) = grey8.at<uint8_t>(y, x) / 255.0;
  }
  return image;
}

/// Grey 8-bit frames of a source, all of one size, at uniform or listed timestamps.
struct FrameSequence {
  std::string name;
  std::vector<cv::Mat> frames;  // CV_8UC1
  std::vector<int64_t> t_ns;
};

FrameSequence ReadVideo(const std::string& path) {
  cv::VideoCapture capture(path);
  if (!capture.isOpened()) {
    throw InputError(InputError::Kind::kMissingFile, path, 0, "a video file OpenCV can read");
  }
  FrameSequence sequence;
  sequence.name = fs::path(path).filename().string();
  cv::Mat frame, grey, small;
  while (capture.read(frame)) {
    if (frame.channels() == 1) {
      grey = frame;
    } else {
      cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    }
    cv::resize(grey, small, cv::Size(), kVideoScale, kVideoScale, cv::INTER_AREA);
    sequence.t_ns.push_back(SecondsToNanoseconds(sequence.frames.size() / kVideoFps));
    sequence.frames.push_back(small.clone());
  }
  if (sequence.frames.size() < 3) {
    throw InputError(InputError::Kind::kEmptyWindow, path, 0, "a video of at least 3 frames");
  }
  return sequence;
}

FrameSequence ReadClip(const std::string& folder) {
  const std::vector<FrameInfo> infos = ReadFrameList((fs::path(folder) / "images.txt").string());
  FrameSequence sequence;
  sequence.name = fs::path(folder).filename().string();
  for (const FrameInfo& info : infos) {
    const std::string path = (fs::path(folder) / info.path).string();
    const cv::Mat grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (grey.empty()) throw InputError(InputError::Kind::kMissingFile, path, 0, "an image");
    sequence.frames.push_back(grey);
    sequence.t_ns.push_back(info.t_ns);
  }
  if (sequence.frames.size() < 3) {
    throw InputError(InputError::Kind::kEmptyWindow, folder, 0, "a clip of at least 3 frames");
  }
  return sequence;
}

/// What one sample reconstructs: the dense ground truth, where the pairs may be taken, and a
/// description of where it came from.
struct TruthClip {
  Video video;
  std::string source;
  /// The source's frame period: latent frames farther than kMaxTruthOffsetPeriods of it from a
  /// frame of `video` get no pair (0: `video` is dense enough everywhere).
  int64_t source_period_ns = 0;
};

/// Crop size: a sensor of 112×84 to 240×180 (DAVIS240 at most), keeping each solve short.
void DrawCropSize(Random* random, int* width, int* height) {
  *width = 112 + 8 * static_cast<int>(random->UniformIndex(17));
  *height = (*width * 3) / 4;
}

TruthClip SyntheticClip(Random* random, double duration_s) {
  SceneOptions options;
  DrawCropSize(random, &options.width, &options.height);
  options.num_shapes = 2 + static_cast<int>(random->UniformIndex(5));
  options.duration_s = duration_s;
  options.min_shape_size_px = random->Uniform(6.0, 14.0);
  options.max_shape_size_px = options.min_shape_size_px + random->Uniform(8.0, 30.0);
  options.max_speed_px_per_s = random->Uniform(100.0, 800.0);
  options.max_rotation_rad_per_s = random->Uniform(0.0, 4.0);
  options.background_speed_px_per_s = random->Uniform() < 0.5 ? 0.0 : random->Uniform(20, 300);
  options.edge_width_px = random->Uniform(0.3, 2.0);
  options.seed = random->UniformIndex(1u << 30);
  TruthClip clip;
  clip.video = SceneSynthesizer(options).RenderAtRate(kPhotoRenderFps);
  clip.source = "synthetic:" + std::to_string(options.seed);
  return clip;
}

TruthClip PhotoClip(Random* random, const std::string& path, double duration_s) {
  const cv::Mat grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (grey.empty()) throw InputError(InputError::Kind::kMissingFile, path, 0, "an image");
  int width, height;
  DrawCropSize(random, &width, &height);
  // Scale the photograph so that the crop covers 40–100 % of its shorter side.
  const double cover = random->Uniform(0.4, 1.0);
  const double scale =
      std::min(1.5, std::max(width / (cover * grey.cols), height / (cover * grey.rows)));
  cv::Mat scaled;
  cv::resize(grey, scaled, cv::Size(), scale, scale, scale < 1 ? cv::INTER_AREA : cv::INTER_CUBIC);
  cv::Mat source;
  scaled.convertTo(source, CV_32F, 1.0 / 255.0);
  const double center_x = random->Uniform(0.3, 0.7) * source.cols;
  const double center_y = random->Uniform(0.3, 0.7) * source.rows;
  const double speed = random->Uniform(50.0, 600.0);
  const double direction = random->Uniform(0.0, 2.0 * M_PI);
  const double angular_speed = random->Uniform(-1.0, 1.0);  // rad/s
  const double zoom_rate = random->Uniform(-1.0, 1.0);      // relative size change per second
  TruthClip clip;
  clip.source = "photo:" + fs::path(path).filename().string();
  const int num_frames = static_cast<int>(std::floor(duration_s * kPhotoRenderFps + 1e-9)) + 1;
  cv::Mat warped;
  for (int i = 0; i < num_frames; ++i) {
    const double t = i / kPhotoRenderFps;
    // The crop's centre moves along a line; the view rotates and zooms about it.
    const double cx = center_x + speed * std::cos(direction) * t;
    const double cy = center_y + speed * std::sin(direction) * t;
    cv::Mat transform = cv::getRotationMatrix2D(cv::Point2f(cx, cy), angular_speed * t * 180 / M_PI,
                                                1.0 + zoom_rate * t);
    transform.at<double>(0, 2) += width / 2.0 - cx;
    transform.at<double>(1, 2) += height / 2.0 - cy;
    cv::warpAffine(source, warped, transform, cv::Size(width, height), cv::INTER_LINEAR,
                   cv::BORDER_REFLECT);
    Image frame(height, width);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        frame(y, x) = std::clamp(static_cast<double>(warped.at<float>(y, x)), 0.0, 1.0);
      }
    }
    clip.video.AppendFrame(frame, SecondsToNanoseconds(t));
  }
  return clip;
}

TruthClip SequenceClip(Random* random, const FrameSequence& sequence, int num_frames) {
  num_frames = std::min<int>(num_frames, sequence.frames.size());
  const int first = static_cast<int>(random->UniformIndex(sequence.frames.size() - num_frames + 1));
  const cv::Mat& sample = sequence.frames[first];
  // Large frames (the 500×500 Adobe clips) are shrunk by up to half before cropping.
  double scale = 1.0;
  if (std::min(sample.cols, sample.rows) > 300) scale = random->Uniform(0.5, 1.0);
  const int scaled_cols = static_cast<int>(sample.cols * scale);
  const int scaled_rows = static_cast<int>(sample.rows * scale);
  int width, height;
  DrawCropSize(random, &width, &height);
  width = std::min(width, scaled_cols);
  height = std::min(height, scaled_rows);
  const int x0 = static_cast<int>(random->UniformIndex(scaled_cols - width + 1));
  const int y0 = static_cast<int>(random->UniformIndex(scaled_rows - height + 1));
  TruthClip clip;
  clip.source = "frames:" + sequence.name + "@" + std::to_string(first);
  clip.source_period_ns = sequence.t_ns[first + 1] - sequence.t_ns[first];
  cv::Mat scaled;
  for (int i = first; i < first + num_frames; ++i) {
    if (scale != 1.0) {
      cv::resize(sequence.frames[i], scaled, cv::Size(scaled_cols, scaled_rows), 0, 0,
                 cv::INTER_AREA);
    } else {
      scaled = sequence.frames[i];
    }
    clip.video.AppendFrame(MatToImage(scaled(cv::Rect(x0, y0, width, height))),
                           sequence.t_ns[i] - sequence.t_ns[first]);
  }
  return clip;
}

/// Share of samples whose truth is re-toned by ToneAugment.
constexpr double kToneAugmentationProbability = 0.5;

/// Maps every intensity I of `video` to low + (high - low) * I^gamma, with the range and gamma
/// drawn so that dark, low-contrast scenes (a DAVIS sensor's frames: shapes_rotation's background
/// sits near 0.35 and its shapes near 0.02) are as common as the full-range photographs. Without
/// it the network learnt to soften every strong edge and lift black levels, which lowered PSNR on
/// a dark real recording. Returns the draw for the manifest.
std::string ToneAugment(Random* random, Video* video) {
  const double low = random->Uniform(0.0, 0.1);
  const double high = random->Uniform(low + 0.2, 1.0);
  const double gamma = LogUniform(random, 0.6, 1.8);
  for (int t = 0; t < video->num_frames(); ++t) {
    video->frame(t) = low + (high - low) * video->frame(t).array().max(0.0).pow(gamma);
  }
  std::ostringstream draw;
  draw << "tone=" << low << ':' << high << ':' << gamma;
  return draw.str();
}

/// An observed frame as a camera records it: 8-bit, sometimes with read noise.
Image Recorded(const Image& image, double noise_sigma, Random* random) {
  Image recorded(image.rows(), image.cols());
  for (int y = 0; y < image.rows(); ++y) {
    for (int x = 0; x < image.cols(); ++x) {
      const double value = image(y, x) + (noise_sigma > 0 ? random->Normal(0.0, noise_sigma) : 0);
      recorded(y, x) = std::round(std::clamp(value, 0.0, 1.0) * 255.0) / 255.0;
    }
  }
  return recorded;
}

void WriteNpy(const std::string& path, const std::vector<const Image*>& channels) {
  const int height = static_cast<int>(channels[0]->rows());
  const int width = static_cast<int>(channels[0]->cols());
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                       std::to_string(channels.size()) + ", " + std::to_string(height) + ", " +
                       std::to_string(width) + "), }";
  // Magic (6) + version (2) + length (2) + header + '\n', padded to a multiple of 64.
  const size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header.push_back('\n');
  std::ofstream file(path, std::ios::binary);
  file.write("\x93NUMPY\x01\x00", 8);
  const uint16_t length = static_cast<uint16_t>(header.size());
  const char length_bytes[2] = {static_cast<char>(length & 0xff), static_cast<char>(length >> 8)};
  file.write(length_bytes, 2);
  file << header;
  std::vector<float> values;
  values.reserve(channels.size() * height * width);
  for (const Image* channel : channels) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) values.push_back(static_cast<float>((*channel)(y, x)));
    }
  }
  // The format is little-endian float32 ('<f4'); x86-64 and ARM64 Linux are little-endian.
  file.write(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
  file.close();
  if (!file) throw InputError(InputError::Kind::kUnwritable, path, 0, "a writable file");
}

/// A real sensor's effects drawn for one sample, around `evfs simulate`'s realistic variants
/// (benchmarks/realistic_variants.sh): each effect on for about half the samples.
struct RealisticSensor {
  FlickerOptions lamp;
  FrameEffectsOptions frames;
};

RealisticSensor DrawRealisticSensor(Random* random, SimulatorOptions* simulator,
                                    std::ostream* config) {
  RealisticSensor sensor;
  if (random->Uniform() < 0.5) {
    simulator->hot_pixel_fraction = random->Uniform(0.0005, 0.003);
    simulator->hot_pixel_rate_hz = LogUniform(random, 30.0, 300.0);
  }
  if (random->Uniform() < 0.5) simulator->leak_rate_hz = LogUniform(random, 0.02, 0.5);
  // A dim scene's photoreceptor bandwidth (a few hundred Hz); higher cutoffs follow the light
  // nearly at once and only cost simulation sub-steps.
  if (random->Uniform() < 0.3) simulator->cutoff_hz = LogUniform(random, 100.0, 500.0);
  if (random->Uniform() < 0.15) {
    sensor.lamp.mains_hz = random->Uniform() < 0.5 ? 100.0 : 120.0;
    sensor.lamp.mains_depth = random->Uniform(0.05, 0.2);
  }
  if (random->Uniform() < 0.4) sensor.frames.gain = random->Uniform(1.0, 1.6);
  sensor.frames.read_noise_dn = random->Uniform() < 0.3 ? 0.0 : random->Uniform(0.5, 3.0);
  if (random->Uniform() < 0.6) {
    sensor.frames.fpn_offset_dn = random->Uniform(0.2, 2.0);
    sensor.frames.fpn_gain_sigma = random->Uniform(0.0, 0.015);
  }
  sensor.frames.seed = random->UniformIndex(1u << 30);
  *config << "realistic hot=" << simulator->hot_pixel_fraction
          << " leak_hz=" << simulator->leak_rate_hz << " cutoff_hz=" << simulator->cutoff_hz
          << " mains_hz=" << sensor.lamp.mains_hz << ':' << sensor.lamp.mains_depth
          << " gain=" << sensor.frames.gain << " read_dn=" << sensor.frames.read_noise_dn
          << " fpn_dn=" << sensor.frames.fpn_offset_dn << ':' << sensor.frames.fpn_gain_sigma
          << ' ';
  return sensor;
}

class PairGenerator {
 public:
  explicit PairGenerator(const PairGeneratorOptions& options) : options_(options) {
    for (const std::string& path : options.videos) sequences_.push_back(ReadVideo(path));
    num_videos_ = static_cast<int>(sequences_.size());
    for (const std::string& folder : options.clips) sequences_.push_back(ReadClip(folder));
  }

  /// Runs sample `index`, writes its pairs into `folder` and appends their lines to `manifest`.
  /// Returns the number of pairs written (0 when the clip gave no events).
  int RunSample(int index, const std::string& folder, std::ostream* manifest) {
    Random random(options_.seed * 1000003ULL + static_cast<uint64_t>(index));
    std::ostringstream config;

    // The case, and how long its window is.
    const double case_draw = random.Uniform();
    const char* case_name = case_draw < 0.4   ? "interpolate"
                            : case_draw < 0.7 ? "predict"
                                              : "deblur";
    const bool deblur = case_name[0] == 'd';
    const bool interpolate = case_name[0] == 'i';

    // The ground-truth clip.
    const double photo_weight = options_.photos.empty() ? 0 : options_.photo_weight;
    const double video_weight = num_videos_ == 0 ? 0 : options_.video_weight;
    const double clip_weight =
        static_cast<int>(sequences_.size()) == num_videos_ ? 0 : options_.clip_weight;
    const double total = options_.synthetic_weight + photo_weight + video_weight + clip_weight;
    const double source_draw = random.Uniform(0.0, total);
    // Windows like the validation cases: 4 frames at 240 fps for an interpolation (frame 2 from
    // 0 and 4), 8 for a deblur, 2–10 for a prediction (slider's 39 ms is ~9).
    const int clip_frames = interpolate ? 3 + static_cast<int>(random.UniformIndex(5))
                            : deblur    ? 5 + static_cast<int>(random.UniformIndex(8))
                                        : 3 + static_cast<int>(random.UniformIndex(9));
    const double duration_s = (clip_frames - 1) / 240.0 * random.Uniform(0.8, 1.6);
    TruthClip clip;
    if (source_draw < options_.synthetic_weight) {
      clip = SyntheticClip(&random, duration_s);
    } else if (source_draw < options_.synthetic_weight + photo_weight) {
      clip = PhotoClip(&random, options_.photos[random.UniformIndex(options_.photos.size())],
                       duration_s);
    } else if (source_draw < options_.synthetic_weight + photo_weight + video_weight) {
      clip = SequenceClip(&random, sequences_[random.UniformIndex(num_videos_)], clip_frames);
    } else {
      const int num_clips = static_cast<int>(sequences_.size()) - num_videos_;
      clip = SequenceClip(&random, sequences_[num_videos_ + random.UniformIndex(num_clips)],
                          clip_frames);
    }
    if (random.Uniform() < 0.5) ReverseTime(&clip.video);  // the paper's random temporal flip
    if (random.Uniform() < kToneAugmentationProbability) {
      config << ToneAugment(&random, &clip.video) << ' ';
    }
    const Video& truth = clip.video;

    // Events: the sensor model randomised (Table 3: thresholds; their spread 0–0.05).
    SimulatorOptions simulator;
    simulator.contrast_threshold_pos = random.Uniform(0.1, 0.4);
    simulator.contrast_threshold_neg =
        std::clamp(simulator.contrast_threshold_pos * random.Uniform(0.75, 1.33), 0.08, 0.5);
    simulator.threshold_sigma = random.Uniform(0.0, 0.05);
    simulator.noise_rate_hz = random.Uniform() < 0.5 ? 0.0 : LogUniform(&random, 0.05, 2.0);
    simulator.refractory_period_ns =
        random.Uniform() < 0.7 ? 0 : static_cast<int64_t>(random.Uniform(0, 1e6));
    simulator.seed = random.UniformIndex(1u << 30);
    // The realistic sensor has its own random stream, so that samples without it are drawn as
    // they are with --realistic=0.
    Random sensor_random(options_.seed * 1000003ULL + static_cast<uint64_t>(index) +
                         kRealisticSeedOffset);
    const bool realistic = sensor_random.Uniform() < options_.realistic;
    RealisticSensor sensor;
    if (realistic) sensor = DrawRealisticSensor(&sensor_random, &simulator, &config);
    const EventStream events = SimulateEvents(truth, simulator, sensor.lamp);
    // What the camera sees at a time (the lamp's light included), what it records of that, and
    // what the same sensor records without temporal read noise (the realistic pairs' truth).
    const auto scene_at = [&](int64_t t_ns) { return SceneAt(truth, sensor.lamp, t_ns); };
    std::unique_ptr<FrameReadout> readout, noiseless_readout;
    if (realistic) {
      readout = std::make_unique<FrameReadout>(truth.height(), truth.width(), sensor.frames);
      FrameEffectsOptions noiseless = sensor.frames;
      noiseless.read_noise_dn = 0.0;
      noiseless_readout = std::make_unique<FrameReadout>(truth.height(), truth.width(), noiseless);
    }
    config << "C+=" << simulator.contrast_threshold_pos
           << " C-=" << simulator.contrast_threshold_neg << " sigma=" << simulator.threshold_sigma
           << " noise_hz=" << simulator.noise_rate_hz
           << " refractory_ns=" << simulator.refractory_period_ns;

    // The observed frames.
    const double noise_sigma = random.Uniform() < 0.6 ? 0.0 : random.Uniform(0.002, 0.015);
    const auto record = [&](const Image& seen) {
      return realistic ? readout->Read(seen) : Recorded(seen, noise_sigma, &random);
    };
    const int last = truth.num_frames() - 1;
    const int64_t t_end = truth.timestamp_ns(last);
    BinningOptions binning;
    const double binning_draw = random.Uniform();
    if (binning_draw < 0.2) {
      binning.method = BinningOptions::Method::kCollision;
      config << " binning=collision";
    } else if (binning_draw < 0.4) {
      binning.method = BinningOptions::Method::kStacked;
      binning.stacked.num_frames = 4 + static_cast<int>(random.UniformIndex(29));
      binning.stacked.split = random.Uniform() < 0.5 ? StackedBinningOptions::Split::kEqualTime
                                                     : StackedBinningOptions::Split::kEqualCount;
      config << " binning=stacked" << binning.stacked.num_frames;
    } else {
      binning.max_latent_frames = 24 + static_cast<int>(random.UniformIndex(41));
      config << " binning=auto" << binning.max_latent_frames;
    }
    Scene scene;
    try {
      if (deblur) {
        TimedFrame blurred;
        Image mean = Image::Zero(truth.height(), truth.width());
        for (int t = 0; t <= last; ++t) mean += scene_at(truth.timestamp_ns(t));
        blurred.image = record(mean / (last + 1));
        blurred.exposure_begin_ns = 0;
        blurred.exposure_end_ns = t_end;
        scene = MakeDeblurScene(blurred, events, binning);
      } else {
        TimedFrame first;
        first.image = record(scene_at(truth.timestamp_ns(0)));
        if (interpolate) {
          TimedFrame end;
          end.image = record(scene_at(t_end));
          end.exposure_begin_ns = end.exposure_end_ns = t_end;
          scene = MakeInterpolationScene(first, end, events, binning);
        } else {
          scene = MakePredictionScene(first, t_end, events, binning);
        }
      }
    } catch (const InvalidArgumentError& error) {
      // Collision binning refused (more steps than the voxel cap): not a sample.
      if (!FLAGS_quiet) std::printf("sample %d: skipped (%s)\n", index, error.what());
      return 0;
    }
    if (scene.num_events == 0) return 0;

    // The DMR, its configuration randomised around evfs's defaults (Table 3's ranges are for
    // the paper's unnormalised objective; these factors span a similar 2–3× range).
    MethodOptions method;
    ObjectiveOptions& objective = method.reconstruction.objective;
    if (random.Uniform() < 0.7) {
      objective.frame_weight *= LogUniform(&random, 0.5, 2.0);
      objective.event_weight *= LogUniform(&random, 0.4, 2.0);
      objective.spatial_tv_weight *= LogUniform(&random, 0.5, 2.0);
      objective.temporal_tv_weight *= LogUniform(&random, 0.5, 2.0);
      method.reconstruction.estimation.alpha_times_change = LogUniform(&random, 0.6, 1.6);
      if (random.Uniform() < 0.15) {
        objective.event_model.model = EventModel::kLinear;
      } else {
        objective.event_model.log_offset = LogUniform(&random, 0.2, 1.0);
      }
      // The paper's running epochs: the solve stopped early, or run to its tolerance.
      if (random.Uniform() < 0.5) {
        method.reconstruction.solver.max_num_iterations =
            3 + static_cast<int>(random.UniformIndex(18));
      }
    }
    method.reconstruction.solver.num_threads = options_.threads;
    config << " frame_w=" << objective.frame_weight << " event_w=" << objective.event_weight
           << " tv_xy=" << objective.spatial_tv_weight << " tv_t=" << objective.temporal_tv_weight
           << " model=" << EventModelName(objective.event_model.model)
           << " b=" << objective.event_model.log_offset
           << " alpha_x_change=" << method.reconstruction.estimation.alpha_times_change
           << " max_iter=" << method.reconstruction.solver.max_num_iterations
           << " frame_noise=" << noise_sigma;
    const MethodResult result = RunMethod(scene, method);
    const Video& latent = result.video;
    const Video initial = InitializeLatentVideo(scene);

    // The solver's activity: pixels it changed in some latent frame.
    Image active = Image::Zero(latent.height(), latent.width());
    for (int t = 0; t < latent.num_frames(); ++t) {
      active = (latent.frame(t) != initial.frame(t))
                   .select(Image::Ones(active.rows(), active.cols()), active);
    }
    if (active.sum() == 0) return 0;

    // Latent frames with a truth: near a source frame (clips) or anywhere (dense renders).
    std::vector<int> candidates;
    for (int k = 0; k < latent.num_frames(); ++k) {
      const int64_t t = latent.timestamp_ns(k);
      const int nearest = truth.NearestFrame(t);
      if (clip.source_period_ns > 0 && std::abs(truth.timestamp_ns(nearest) - t) >
                                           kMaxTruthOffsetPeriods * clip.source_period_ns) {
        continue;
      }
      candidates.push_back(k);
    }
    int written = 0;
    while (!candidates.empty() && written < options_.pairs_per_sample) {
      const size_t pick = random.UniformIndex(candidates.size());
      const int k = candidates[pick];
      candidates.erase(candidates.begin() + pick);
      const int64_t t_ns = latent.timestamp_ns(k);
      const Image target =
          realistic ? noiseless_readout->Read(scene_at(t_ns)) : truth.InterpolateAt(t_ns);
      const Image dmr = latent.frame(k);
      char name[64];
      std::snprintf(name, sizeof(name), "pair_%07d_%d.npy", index, written);
      WriteNpy((fs::path(folder) / name).string(), {&dmr, &target, &active});
      *manifest << name << '\t' << index << '\t' << clip.source << '\t' << case_name << '\t'
                << latent.width() << 'x' << latent.height() << '\t' << scene.num_events << '\t'
                << latent.num_frames() << '\t' << k << '\t' << Psnr(initial.frame(k), target)
                << '\t' << Psnr(dmr, target) << '\t' << config.str() << '\n';
      ++written;
    }
    if (!FLAGS_quiet) {
      std::printf("sample %d: %s %s %dx%d, %lld events, %d latent frames, %d pairs\n", index,
                  case_name, clip.source.c_str(), latent.width(), latent.height(),
                  static_cast<long long>(scene.num_events), latent.num_frames(), written);
      std::fflush(stdout);
    }
    return written;
  }

 private:
  /// Plays the clip backwards (same timestamps, frames in reverse order).
  static void ReverseTime(Video* video) {
    Video reversed;
    for (int t = video->num_frames() - 1; t >= 0; --t) {
      reversed.AppendFrame(video->frame(t), video->timestamp_ns(video->num_frames() - 1 - t));
    }
    *video = std::move(reversed);
  }

  PairGeneratorOptions options_;
  std::vector<FrameSequence> sequences_;  // the videos first, then the clips
  int num_videos_ = 0;
};

int Run() {
  PairGeneratorOptions options;
  options.out = FLAGS_out;
  options.samples = FLAGS_samples;
  options.first_sample = FLAGS_first_sample;
  options.seed = FLAGS_seed;
  options.pairs_per_sample = FLAGS_pairs_per_sample;
  options.threads = FLAGS_threads;
  options.photos = SplitList(FLAGS_photos);
  options.videos = SplitList(FLAGS_videos);
  options.clips = SplitList(FLAGS_clips);
  options.synthetic_weight = FLAGS_synthetic_weight;
  options.photo_weight = FLAGS_photo_weight;
  options.video_weight = FLAGS_video_weight;
  options.clip_weight = FLAGS_clip_weight;
  options.realistic = FLAGS_realistic;
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError(error);

  OutputOptions output;
  output.path = options.out;
  output.command = "make_denoiser_pairs";
  output.overwrite = FLAGS_overwrite;
  output.inputs = options.photos;
  output.inputs.insert(output.inputs.end(), options.videos.begin(), options.videos.end());
  output.inputs.insert(output.inputs.end(), options.clips.begin(), options.clips.end());
  OutputTarget target(output);

  PairGenerator generator(options);
  std::ofstream manifest(fs::path(target.staging()) / "pairs.tsv");
  manifest << "file\tsample\tsource\tcase\tsize\tevents\tlatent_frames\tlatent_index\t"
              "psnr_initial\tpsnr_dmr\tconfiguration\n";
  manifest.precision(6);
  int pairs = 0;
  for (int i = 0; i < options.samples; ++i) {
    pairs += generator.RunSample(options.first_sample + i, target.staging(), &manifest);
  }
  manifest.close();
  if (!manifest) {
    throw InputError(InputError::Kind::kUnwritable, options.out + "/pairs.tsv", 0,
                     "a writable file");
  }
  target.Commit();
  std::printf("make_denoiser_pairs: %d pairs from %d samples in %s\n", pairs, options.samples,
              options.out.c_str());
  return 0;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "make_denoiser_pairs --out=DIR --samples=N [--seed=S] [--photos=...] [--videos=...] "
      "[--clips=...]: (DMR latent frame, truth) pairs for training the residual denoiser");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  try {
    return evfs::Run();
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "make_denoiser_pairs: %s\n", error.what());
    return evfs::kExitUserError;
  }
}

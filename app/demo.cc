#include "evfs/app/demo.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "evfs/app/denoise_job.h"
#include "evfs/app/reconstruct_job.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/time.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/io/data_source.h"
#include "evfs/io/text_folder.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

// The demo scene: small enough to run in seconds, with motion fast enough that the blend and
// copy baselines are clearly wrong. Events are simulated from a 1 kHz rendering; the "camera"
// records sharp frames every 10 ms and one frame blurred over 20 ms.
constexpr int kWidth = 120;
constexpr int kHeight = 96;
constexpr double kRenderFps = 1000.0;
constexpr double kDurationS = 0.04;
constexpr int kFrameEveryRendered = 10;  // a recorded frame every 10 ms
constexpr double kBlurBeginS = 0.010;    // exposure of the blurred frame
constexpr double kBlurEndS = 0.030;

struct DemoCase {
  const char* name;
  Mode mode;
  std::string data;
  int first, last;
  double truth_s;  // time of the ground-truth frame to score
};

std::vector<FrameInfo> SharpFrames(const Video& video, std::vector<Image>* images) {
  std::vector<FrameInfo> frames;
  for (int t = 0; t < video.num_frames(); t += kFrameEveryRendered) {
    FrameInfo info;
    info.t_ns = video.timestamp_ns(t);
    char path[64];
    std::snprintf(path, sizeof(path), "images/frame_%08d.png", t / kFrameEveryRendered);
    info.path = path;
    frames.push_back(info);
    images->push_back(video.frame(t));
  }
  return frames;
}

}  // namespace

int RunDemo(const std::string& folder, const std::string& shown_as) {
  const fs::path out(folder);
  const fs::path shown(shown_as);

  SceneOptions scene_options;
  scene_options.width = kWidth;
  scene_options.height = kHeight;
  scene_options.duration_s = kDurationS;
  scene_options.num_shapes = 3;
  scene_options.min_shape_size_px = 10.0;
  scene_options.max_shape_size_px = 24.0;
  scene_options.max_speed_px_per_s = 600.0;
  const SceneSynthesizer synthesizer(scene_options);
  const Video rendered = synthesizer.RenderAtRate(kRenderFps);
  const EventStream events = SimulateEvents(rendered, SimulatorOptions());
  std::printf("demo scene: %dx%d, %d frames rendered at %.0f fps, %zu simulated events\n", kWidth,
              kHeight, rendered.num_frames(), kRenderFps, events.size());

  std::vector<Image> sharp_images;
  const std::vector<FrameInfo> sharp_frames = SharpFrames(rendered, &sharp_images);
  WriteDataFolder((out / "data").string(), events, sharp_frames, sharp_images);

  // The blurred frame is the time average of the rendering over its exposure.
  FrameInfo blurred;
  blurred.exposure_begin_ns = SecondsToNanoseconds(kBlurBeginS);
  blurred.exposure_end_ns = SecondsToNanoseconds(kBlurEndS);
  blurred.t_ns = (blurred.exposure_begin_ns + blurred.exposure_end_ns) / 2;
  blurred.has_exposure = true;
  blurred.path = "images/blurred.png";
  Image blurred_image = Image::Zero(kHeight, kWidth);
  int averaged = 0;
  for (int t = 0; t < rendered.num_frames(); ++t) {
    if (rendered.timestamp_ns(t) < blurred.exposure_begin_ns ||
        rendered.timestamp_ns(t) > blurred.exposure_end_ns) {
      continue;
    }
    blurred_image += rendered.frame(t);
    ++averaged;
  }
  blurred_image /= averaged;
  WriteDataFolder((out / "data_blur").string(), events, {blurred}, {blurred_image});

  const std::vector<DemoCase> cases = {
      {"interpolate", Mode::kInterpolate, (out / "data").string(), 0, 2, 0.010},
      {"predict", Mode::kPredict, (out / "data").string(), 0, 1, 0.010},
      {"deblur", Mode::kDeblur, (out / "data_blur").string(), 0, -1,
       NanosecondsToSeconds(blurred.t_ns)},
  };

  // evfs as `evfs reconstruct` runs it by default, beside the same solve followed by the shipped
  // denoiser (--denoise=once), when it is found.
  const bool shipped = !ShippedDenoiserWeights().empty();
  std::string table =
      "| case | baseline | baseline PSNR | evfs PSNR | with denoiser | baseline SSIM | evfs SSIM | "
      "with denoiser | latent frames | time |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const DemoCase& demo_case : cases) {
    ReconstructRequest request;
    request.data_path = demo_case.data;
    request.data_label = (shown / fs::path(demo_case.data).filename()).string();
    request.mode = demo_case.mode;
    request.first = demo_case.first;
    request.last = demo_case.last;
    request.denoise.mode = AutoDenoiseMode("");
    ReconstructResult result = RunReconstruction(request);
    WriteReconstruction(request, &result, (out / demo_case.name).string());
    Video denoised;
    if (shipped) {
      ReconstructRequest with_denoiser = request;
      with_denoiser.denoise.mode = DenoiseMode::kOnce;
      denoised = RunReconstruction(with_denoiser).run.video;
    }

    // Score the latent frame nearest to the truth time against the exact rendering there.
    const Video& latent = result.run.video;
    const int index = latent.NearestFrame(SecondsToNanoseconds(demo_case.truth_s));
    const Image truth = synthesizer.Render(latent.timestamp_s(index));
    const double psnr = Psnr(latent.frame(index), truth);
    const double ssim = Ssim(latent.frame(index), truth);
    const double baseline_psnr = Psnr(result.baseline.frame(index), truth);
    const double baseline_ssim = Ssim(result.baseline.frame(index), truth);
    char denoised_psnr[32] = "-", denoised_ssim[32] = "-";
    if (shipped) {
      std::snprintf(denoised_psnr, sizeof(denoised_psnr), "%.2f dB",
                    Psnr(denoised.frame(index), truth));
      std::snprintf(denoised_ssim, sizeof(denoised_ssim), "%.4f",
                    Ssim(denoised.frame(index), truth));
    }
    char row[256];
    std::snprintf(row, sizeof(row),
                  "| %s | %s | %.2f dB | %.2f dB | %s | %.4f | %.4f | %s | %d | %.1f s |\n",
                  demo_case.name, demo_case.mode == Mode::kInterpolate ? "blend" : "copy",
                  baseline_psnr, psnr, denoised_psnr, baseline_ssim, ssim, denoised_ssim,
                  latent.num_frames(), result.time.total_s);
    table += row;
  }
  std::ofstream results(out / "results.md");
  results << "# evfs demo\n\n" << table;
  results.close();
  if (!results) {
    throw InputError(InputError::Kind::kUnwritable, (shown / "results.md").string(), 0,
                     "cannot write the results table");
  }
  std::printf("\n%s\n", table.c_str());
  return 0;
}

}  // namespace evfs

#include "evfs/app/denoise_job.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/time.h"
#include "evfs/io/decimal_seconds.h"
#include "evfs/io/image_io.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/scene/confidence.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

constexpr char kWeightsFile[] = "evfs_denoiser.onnx";

using Json = nlohmann::ordered_json;

// The folder of the running executable ("" when /proc does not say).
fs::path ExecutableFolder() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

// timestamps.txt of a reconstruction: `index t_seconds` lines, indices 0, 1, 2, ...
std::vector<int64_t> ReadTimestamps(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "not found: expected a reconstruction folder written by evfs reconstruct");
  }
  std::vector<int64_t> timestamps_ns;
  std::string line;
  for (int64_t number = 1; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    std::istringstream fields(line);
    long long index = -1;
    std::string seconds;
    std::string extra;
    if (!(fields >> index >> seconds) || (fields >> extra) ||
        index != static_cast<long long>(timestamps_ns.size())) {
      throw InputError(
          InputError::Kind::kMalformed, path, number,
          "expected 'index t_seconds' with index " + std::to_string(timestamps_ns.size()));
    }
    int64_t t_ns = 0;
    DecimalStatus status = DecimalStatus::kOk;
    const char* end = ParseDecimalSeconds(seconds.c_str(), &t_ns, &status);
    if (status != DecimalStatus::kOk || *end != '\0') {
      throw InputError(InputError::Kind::kMalformed, path, number,
                       "expected a time in seconds, found '" + seconds + "'");
    }
    timestamps_ns.push_back(t_ns);
  }
  if (timestamps_ns.empty()) {
    throw InputError(InputError::Kind::kEmptyWindow, path, 0, "holds no frames");
  }
  return timestamps_ns;
}

}  // namespace

std::string ShippedDenoiserWeights() {
  std::vector<fs::path> candidates;
  const fs::path exe_folder = ExecutableFolder();
  if (!exe_folder.empty()) {
    candidates.push_back(exe_folder / "models" / kWeightsFile);
    candidates.push_back(exe_folder / ".." / "share" / "evfs" / "models" / kWeightsFile);
  }
  candidates.push_back(fs::path(EVFS_SOURCE_MODELS_DIR) / kWeightsFile);
  for (const fs::path& candidate : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec)) return candidate.lexically_normal().string();
  }
  return "";
}

DenoiseMode AutoDenoiseMode(const std::string& weights_path) {
  if (!weights_path.empty()) return DenoiseMode::kOnce;
  return ShippedDenoiserWeights().empty() ? DenoiseMode::kNone : kShippedWeightsDenoiseMode;
}

std::unique_ptr<Denoiser> LoadDenoiser(const DenoiseRequest& request) {
  if (!(request.gate_tau >= 0.0) || !std::isfinite(request.gate_tau)) {
    throw InvalidArgumentError("--denoise_gate_tau must be >= 0 (0: from the frames' noise), not " +
                               std::to_string(request.gate_tau));
  }
  if (request.mode == DenoiseMode::kNone) return nullptr;
  DenoiserOptions options = request.denoiser;
  if (options.weights_path.empty()) {
    options.weights_path = ShippedDenoiserWeights();
    if (options.weights_path.empty()) {
      throw InvalidArgumentError(
          std::string("--denoise=") + NameOf(kDenoiseModeNames, request.mode) +
          " needs denoiser weights: none are shipped with this build (models/" + kWeightsFile +
          "); pass --denoiser=FILE.onnx");
    }
  }
  return std::make_unique<Denoiser>(options);
}

DenoiseRegion SolvedRegion(const Scene& scene, const MethodOptions& method, bool solved) {
  DenoiseRegion region;
  if (!IsIterative(method.method)) return region;  // a baseline sets every pixel
  const ActivityMask mask(scene.events, method.reconstruction.activity_radius_px);
  region.pixels.assign(mask.num_pixels(), 0);
  if (!solved) return region;
  for (int64_t p = 0; p < mask.num_pixels(); ++p) region.pixels[p] = mask.active(p) ? 1 : 0;
  return region;
}

std::unique_ptr<DenoiseGate> MakeDenoiseGate(const DenoiseRequest& request, const Scene& scene,
                                             const MethodOptions& method, const MethodResult& run) {
  if (!request.gate || request.mode != DenoiseMode::kOnce) return nullptr;
  auto gate = std::make_unique<DenoiseGate>();
  ConfidenceModel model;
  gate->sigma = PredictErrorSigma(scene, run.video, ConfidenceFor(method, run), &model);
  gate->tau = request.gate_tau > 0.0
                  ? request.gate_tau
                  : std::max(kMinGateTau, kGateNoiseMultiple * model.frame_noise_sigma);
  return gate;
}

DenoiseRecord DenoiseLatentVideo(const Denoiser& denoiser, DenoiseMode mode,
                                 const DenoiseRegion& region, const Scene* observed,
                                 const Image* truth, int truth_index, Video* latent,
                                 const DenoiseGate* gate) {
  DenoiseRecord record;
  record.mode = mode;
  record.weights_path = denoiser.weights_path();
  record.weights_sha256 = denoiser.weights_sha256();
  record.margin_px = denoiser.margin_px();
  if (truth != nullptr && truth_index >= 0 && truth_index < latent->num_frames()) {
    const Image before = latent->frame(truth_index);
    record.scored = true;
    record.psnr_before = Psnr(before, *truth);
    record.ssim_before = Ssim(before, *truth);
  }
  Video denoised = denoiser.Apply(*latent, region, &record.stats);
  if (gate != nullptr) {
    denoised = GateCorrection(*latent, denoised, gate->sigma, gate->tau);
    record.gate_tau = gate->tau;
  }
  if (observed != nullptr) {
    record.consistent = true;
    record.consistency = KeepFramesConsistent(*observed, *latent, &denoised);
  }
  *latent = std::move(denoised);
  return record;
}

void CheckDenoiseMode(DenoiseMode mode, Method method) {
  if (mode == DenoiseMode::kPnp && method != Method::kCeresLm) {
    throw InvalidArgumentError(std::string("--denoise=pnp needs --solver=ceres_lm (its Ceres "
                                           "problem takes the plug & play coupling term), not ") +
                               MethodName(method));
  }
}

DenoiseRecord PlugAndPlayLatentVideo(const Denoiser& denoiser, const Scene& scene,
                                     const MethodOptions& method, const PlugAndPlayOptions& pnp,
                                     const DenoiseRegion& region, const Image* truth,
                                     int truth_index, MethodResult* solved) {
  CheckDenoiseMode(DenoiseMode::kPnp, method.method);
  DenoiseRecord record;
  record.mode = DenoiseMode::kPnp;
  record.weights_path = denoiser.weights_path();
  record.weights_sha256 = denoiser.weights_sha256();
  record.margin_px = denoiser.margin_px();
  Video& latent = solved->video;
  if (truth != nullptr && truth_index >= 0 && truth_index < latent.num_frames()) {
    const Image before = latent.frame(truth_index);
    record.scored = true;
    record.psnr_before = Psnr(before, *truth);
    record.ssim_before = Ssim(before, *truth);
  }
  if (!solved->solved) {
    // Nothing was solved (no events): nothing to couple, and no pixel to denoise.
    latent = denoiser.Apply(latent, region, &record.stats);
    return record;
  }
  ReconstructionOptions options = method.reconstruction;
  options.objective.event_model.alpha = solved->reconstruction.model.alpha;
  options.objective.event_model.saturation = solved->reconstruction.model.saturation;
  options.objective.event_model.off_alpha_ratio = solved->reconstruction.model.off_alpha_ratio;
  latent = PlugAndPlay(scene, options, denoiser, region, latent, pnp, &record.pnp, &record.stats);
  return record;
}

DenoiseRecord DenoiseSolution(const Denoiser& denoiser, const DenoiseRequest& request,
                              const Scene& scene, const MethodOptions& method,
                              const MethodOptions& clocked, const Image* truth,
                              int64_t truth_timestamp_ns, const std::vector<uint8_t>* only_frames,
                              MethodResult* run) {
  const int truth_latent = truth != nullptr ? run->video.NearestFrame(truth_timestamp_ns) : -1;
  DenoiseRegion region = SolvedRegion(scene, method, run->solved);
  if (only_frames != nullptr) region.frames = *only_frames;
  if (request.mode == DenoiseMode::kPnp) {
    return PlugAndPlayLatentVideo(denoiser, scene, clocked, request.pnp, region, truth,
                                  truth_latent, run);
  }
  const std::unique_ptr<DenoiseGate> gate = MakeDenoiseGate(request, scene, method, *run);
  return DenoiseLatentVideo(denoiser, request.mode, region, request.consistency ? &scene : nullptr,
                            truth, truth_latent, &run->video, gate.get());
}

Json DenoiseJson(const DenoiseRecord& record) {
  Json json;
  json["mode"] = NameOf(kDenoiseModeNames, record.mode);
  if (record.mode == DenoiseMode::kNone) return json;
  json["weights"] = record.weights_path;
  json["sha256"] = record.weights_sha256;
  json["margin_px"] = record.margin_px;
  json["frames"] = record.stats.frames;
  json["network_runs"] = record.stats.tiles;
  json["pixels_changed"] = record.stats.pixels_changed;
  json["network_pixels"] = record.stats.network_pixels;
  json["time_s"] = record.stats.time_s;
  if (record.mode == DenoiseMode::kPnp) {
    json["pnp"] = {{"iterations", record.pnp.iterations},
                   {"rho", record.pnp.rho},
                   {"solver_iterations", record.pnp.solver_iterations},
                   {"solve_time_s", record.pnp.solve_time_s},
                   {"denoise_time_s", record.pnp.denoise_time_s}};
  }
  if (record.mode == DenoiseMode::kOnce) {
    if (record.consistent) {
      json["consistency"] = {{"observations", record.consistency.observations},
                             {"correction_energy", record.consistency.correction_energy},
                             {"removed_energy", record.consistency.removed_energy},
                             {"removed_fraction", record.consistency.RemovedFraction()}};
    } else {
      json["consistency"] = nullptr;
    }
    json["gate_tau"] = record.gate_tau > 0.0 ? Json(record.gate_tau) : Json(nullptr);
  }
  if (record.scored) {
    json["psnr_before"] = record.psnr_before;
    json["ssim_before"] = record.ssim_before;
  }
  return json;
}

DenoiseRecord DenoiseReconstructionFolder(const std::string& in_folder, const Denoiser& denoiser,
                                          const std::string& out_folder) {
  const fs::path in(in_folder);
  std::error_code ec;
  if (!fs::is_directory(in, ec)) {
    throw InputError(InputError::Kind::kMissingFile, in_folder, 0,
                     std::string(fs::exists(in, ec) ? "not a folder" : "not found") +
                         ": expected a reconstruction folder written by evfs reconstruct");
  }
  const std::vector<int64_t> timestamps_ns = ReadTimestamps((in / "timestamps.txt").string());
  Video video;
  char name[32];
  for (size_t t = 0; t < timestamps_ns.size(); ++t) {
    std::snprintf(name, sizeof(name), "%06zu.png", t);
    const std::string path = (in / "frames" / name).string();
    const Image image = ReadGreyImage(path);
    if (!video.empty() && (image.rows() != video.height() || image.cols() != video.width())) {
      throw InputError(InputError::Kind::kSizeMismatch, path, 0,
                       "expected " + std::to_string(video.width()) + "x" +
                           std::to_string(video.height()) + " like frame 000000.png");
    }
    video.AppendFrame(image, timestamps_ns[t]);
  }

  DenoiseRecord record =
      DenoiseLatentVideo(denoiser, DenoiseMode::kOnce, {}, nullptr, nullptr, -1, &video);
  const fs::path out(out_folder);
  WriteFrameSequence(out_folder, video);
  Json summary;
  summary["command"] = "denoise";
  summary["input"] = in_folder;
  summary["width"] = video.width();
  summary["height"] = video.height();
  summary["output_frames"] = video.num_frames();
  summary["denoiser"] = DenoiseJson(record);
  std::ofstream file(out / "summary.json");
  file << summary.dump(2) << "\n";
  file.close();
  if (!file) {
    throw InputError(InputError::Kind::kUnwritable, (out / "summary.json").string(), 0,
                     "cannot write the summary");
  }
  return record;
}

}  // namespace evfs

// The residual denoiser (denoiser/) inside evfs' jobs: once after a reconstruction
// (`evfs reconstruct --denoise=once`) and on an existing reconstruction folder (`evfs denoise`).
// Which pixels it may change comes from the solve: those the solver solved for (ActivityMask's
// active pixels); every pixel a solver skipped keeps its value bit for bit.
#ifndef EVFS_APP_DENOISE_JOB_H_
#define EVFS_APP_DENOISE_JOB_H_

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "evfs/app/method.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/video.h"
#include "evfs/denoiser/denoiser.h"
#include "evfs/denoiser/frame_consistency.h"
#include "evfs/plug_and_play/plug_and_play.h"
#include "evfs/scene/scene.h"

namespace evfs {

enum class DenoiseMode { kNone, kOnce, kPnp };

inline constexpr EnumName<DenoiseMode> kDenoiseModeNames[] = {
    {DenoiseMode::kNone, "none", "the reconstruction as the solver left it"},
    {DenoiseMode::kOnce, "once", "the residual denoiser applied once after the solve"},
    {DenoiseMode::kPnp, "pnp",
     "plug & play: ADMM between the Ceres problem and the denoiser (ceres_lm only)"},
};

/// The weights shipped with evfs: models/evfs_denoiser.onnx next to the executable, in its
/// ../share/evfs/models, or in the source tree evfs was built from. "" when none exists.
std::string ShippedDenoiserWeights();

/// What `--denoise=auto` does with the shipped weights: none. The shipped network learned from
/// simulated events only; on real recordings it widens edges and lowers SSIM against the
/// reconstruction alone (BENCHMARKS.md, "Real recordings"), and a default must not lose on real
/// data. `--denoise=once` still applies it.
inline constexpr DenoiseMode kShippedWeightsDenoiseMode = DenoiseMode::kNone;

/// `--denoise=auto`: once when the user names weights (`weights_path` not empty: they asked for
/// a denoiser), kShippedWeightsDenoiseMode when weights are shipped, else none.
DenoiseMode AutoDenoiseMode(const std::string& weights_path);

/// How a job denoises. `denoiser.weights_path` "" means the shipped weights.
struct DenoiseRequest {
  DenoiseMode mode = DenoiseMode::kNone;
  DenoiserOptions denoiser;
  /// Mode pnp: the ADMM iterations and ρ schedule.
  PlugAndPlayOptions pnp;
  /// Mode once: keep the correction consistent with the scene's frames (KeepFramesConsistent).
  bool consistency = true;
  /// Mode once: weigh the correction by the solve's predicted error σ (GateCorrection in
  /// denoiser/denoiser.h, σ from scene/confidence.h), so that the network corrects only where
  /// the solve is unsure.
  bool gate = false;
  /// τ of the gate in intensity units, >= 0: the predicted error at which half the correction is
  /// kept; 0: kGateNoiseMultiple times the observed frames' noise sigma (ConfidenceModel), at
  /// least kMinGateTau.
  double gate_tau = 0.0;
};

/// The automatic gate's τ in units of the frames' noise sigma. In the Wiener reading of the gate
/// τ² is the variance of the network's own error, independent of the solve's: on real
/// recordings, which it never saw in training, that error is far above the frames' noise. 24
/// puts τ near 0.08 on the DAVIS240 windows (noise 0.0034–0.0056), where the real windows'
/// SSIM stops falling (benchmarks/denoiser_gate_windows.sh); at 3 it
/// lost up to 0.010 SSIM there. A pixel whose predicted error is the frames' noise alone keeps
/// under 1 % of the correction.
inline constexpr double kGateNoiseMultiple = 24.0;
/// The least automatic τ: one 8-bit level, the noise of quantised frames without read noise.
inline constexpr double kMinGateTau = 1.0 / 255.0;

/// The confidence gate of a solve (DenoiseRequest::gate): the predicted error of its latent
/// frames and τ.
struct DenoiseGate {
  Video sigma;
  double tau = 0.0;
};

/// The gate `request` asks for on `run` (the solve of `scene` by `method`): σ from
/// PredictErrorSigma, τ as DenoiseRequest::gate_tau says. Null when the request has no gate or
/// its mode is not once.
std::unique_ptr<DenoiseGate> MakeDenoiseGate(const DenoiseRequest& request, const Scene& scene,
                                             const MethodOptions& method, const MethodResult& run);

/// What denoising did, for summary.json.
struct DenoiseRecord {
  DenoiseMode mode = DenoiseMode::kNone;
  std::string weights_path;
  std::string weights_sha256;
  int margin_px = 0;
  DenoiseStats stats;
  /// With a truth frame: the score before denoising (the score after is the job's own).
  bool scored = false;
  double psnr_before = 0.0, ssim_before = 0.0;
  /// Mode pnp: the ADMM iterations (stats then sums every application of the denoiser).
  PlugAndPlayRecord pnp;
  /// Mode once with a scene to keep consistent with: what the projection took out.
  bool consistent = false;
  FrameConsistency consistency;
  /// Mode once with a confidence gate: its τ (0: no gate).
  double gate_tau = 0.0;
};

/// The denoiser `request` asks for, loaded (null for mode none). Throws InvalidArgumentError
/// when a mode needs weights and none are given or shipped, InputError for a bad weights file.
std::unique_ptr<Denoiser> LoadDenoiser(const DenoiseRequest& request);

/// The pixels `method` solved for on `scene`: the active pixels of an iterative method's
/// ActivityMask (none when the scene needed no solve), every pixel for a classical baseline.
DenoiseRegion SolvedRegion(const Scene& scene, const MethodOptions& method, bool solved);

/// Applies `denoiser` to `latent` in place at `region`, scoring frame `truth_index` against
/// `truth` before it does when `truth` is not null. When `observed` is not null (the scene
/// `latent` reconstructs), the correction is scaled by what its frames support
/// (CalibrateResidual); null applies it as the network gives it. When `gate` is not null the
/// network's correction is weighted by it (GateCorrection) before that.
DenoiseRecord DenoiseLatentVideo(const Denoiser& denoiser, DenoiseMode mode,
                                 const DenoiseRegion& region, const Scene* observed,
                                 const Image* truth, int truth_index, Video* latent,
                                 const DenoiseGate* gate = nullptr);

/// Throws InvalidArgumentError (one line) when `mode` cannot follow `method`: plug & play
/// needs the Ceres problem (ceres_lm), whose quadratic prior couples it to the denoiser.
void CheckDenoiseMode(DenoiseMode mode, Method method);

/// Plug & play on `scene` from the Ceres solve `solved` (its MethodResult, method ceres_lm)
/// at `region`: replaces solved->video by the result and returns the record, scored like
/// DenoiseLatentVideo's.
DenoiseRecord PlugAndPlayLatentVideo(const Denoiser& denoiser, const Scene& scene,
                                     const MethodOptions& method, const PlugAndPlayOptions& pnp,
                                     const DenoiseRegion& region, const Image* truth,
                                     int truth_index, MethodResult* solved);

/// The denoising stage of a job: `denoiser` on the latent video of `run` (the solve of `scene`
/// by `method`; `clocked` is `method` with its time budget started, for plug & play's solves)
/// as `request` asks: plug & play, or once with its gate. Denoises the frames of `only_frames`
/// when it is not null (one flag per latent frame), else every frame of the solved region;
/// scores the latent frame nearest `truth_timestamp_ns` against `truth` when it is not null.
DenoiseRecord DenoiseSolution(const Denoiser& denoiser, const DenoiseRequest& request,
                              const Scene& scene, const MethodOptions& method,
                              const MethodOptions& clocked, const Image* truth,
                              int64_t truth_timestamp_ns, const std::vector<uint8_t>* only_frames,
                              MethodResult* run);

/// summary.json's "denoiser" object.
nlohmann::ordered_json DenoiseJson(const DenoiseRecord& record);

/// `evfs denoise`: reads a reconstruction folder (frames/NNNNNN.png, timestamps.txt, written by
/// `evfs reconstruct`), denoises every pixel of every frame (the folder does not say which
/// pixels were solved) and writes frames/, timestamps.txt and summary.json into `out_folder`
/// (an OutputTarget's staging folder). Throws InputError for a folder that is not a
/// reconstruction.
DenoiseRecord DenoiseReconstructionFolder(const std::string& in_folder, const Denoiser& denoiser,
                                          const std::string& out_folder);

}  // namespace evfs

#endif  // EVFS_APP_DENOISE_JOB_H_

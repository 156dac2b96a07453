// The residual denoiser of the paper's second stage (§3.4, docs/design.md §4): a fixed-weight
// convolutional network R, loaded from an ONNX file and run with OpenCV's DNN module, predicts
// the artefact of a reconstructed frame H; the denoised frame is H − R(H).
//
// The network contract (what tools/train_denoiser exports): one input named `input`, shape
// 1×1×H×W float32 with dynamic H and W, holding linear intensities as in core/video.h (roughly
// [0, 1]); one output of the same shape, the residual R(H).
//
// Only what the solver changed is touched: a frame is cut into tiles, and a tile is run through
// the network (with its receptive field as margin, so that the result equals running the whole
// frame) only when it holds a pixel to denoise. Every other pixel comes back bit-identical.
// Networks with strided layers (a half-resolution middle) run on inputs padded to a multiple of
// their total stride by repeating the last row and column, as the trainer does.
#ifndef EVFS_DENOISER_DENOISER_H_
#define EVFS_DENOISER_DENOISER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evfs/core/video.h"

namespace evfs {

struct DenoiserOptions {
  /// The ONNX file of the network.
  std::string weights_path;
  /// Threads that run tiles and frames at the same time, each with a copy of the network;
  /// 0: one per hardware thread.
  int num_threads = 0;
  /// Side of the square tiles a frame is cut into (pixels); each tile is run with `margin_px`
  /// of context around it. Small tiles follow sparse activity closely; large ones waste less
  /// on margins. A frame whose active tiles would cost more than the whole frame is run whole.
  int tile_size_px = 48;
  /// Context around a tile (pixels): at least the network's receptive radius, so that a tile's
  /// result equals that of the whole frame. < 0: the radius derived from the network's layers.
  int margin_px = -1;

  bool IsValid(std::string* error) const;
};

/// Which pixels the denoiser may change. Empty vectors mean "all".
struct DenoiseRegion {
  /// height × width flags (row-major), the same for every frame: nonzero where the solver
  /// changed the pixel's values (ActivityMask's active pixels).
  std::vector<uint8_t> pixels;
  /// One flag per frame: nonzero for the frames to denoise.
  std::vector<uint8_t> frames;
};

/// What one Apply did.
struct DenoiseStats {
  int frames = 0;              // frames that held a pixel to denoise
  int64_t tiles = 0;           // network runs (a frame run whole counts as one)
  int64_t pixels_changed = 0;  // pixels (over all frames) given H − R(H)
  int64_t network_pixels = 0;  // pixels fed to the network, margins included
  double time_s = 0.0;
};

class Denoiser {
 public:
  /// Loads the network once. Throws InvalidArgumentError for invalid options, and InputError
  /// (one line naming the file) for a weights file that is missing, unreadable, not an ONNX
  /// network OpenCV can load, or not of the 1×1×H×W → 1×1×H×W shape.
  explicit Denoiser(const DenoiserOptions& options);
  ~Denoiser();
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

  /// `video` with H − R(H) at the pixels of `region` in the frames of `region`; every other
  /// value is copied unchanged. Throws InvalidArgumentError when the region's sizes do not
  /// match the video. Safe to call from several threads at once: the calls share the network
  /// copies (num_threads of them), each tile waiting for a free one.
  Video Apply(const Video& video, const DenoiseRegion& region = {},
              DenoiseStats* stats = nullptr) const;

  /// The weights file, as given.
  const std::string& weights_path() const { return options_.weights_path; }
  /// SHA-256 of the weights file (64 lower-case hex digits).
  const std::string& weights_sha256() const { return sha256_; }
  /// The context used around tiles (pixels): margin_px, or the derived receptive radius.
  int margin_px() const { return margin_px_; }
  /// The network's receptive radius derived from its layers; -1 when a layer's extent is
  /// unknown (then margin_px must be given).
  int receptive_radius_px() const { return receptive_radius_px_; }
  /// The product of the network's strides (1 for a network at full resolution throughout):
  /// inputs are padded at the bottom and right to multiples of it by repeating the last row and
  /// column, and tiles start at multiples of it, so that tiles give the whole frame's values.
  int input_multiple_px() const { return input_multiple_px_; }

 private:
  struct Networks;
  DenoiserOptions options_;
  std::string sha256_;
  int receptive_radius_px_ = -1;
  int input_multiple_px_ = 1;
  int margin_px_ = 0;
  std::unique_ptr<Networks> networks_;
};

/// The confidence gate: `input` plus the correction `corrected` − `input` weighted per pixel by
///   w = σ² / (σ² + τ²),
/// σ the solve's predicted one-sigma error of the pixel (scene/confidence.h) and τ > 0 the error
/// at which half the correction is kept. Where the solve is sure (σ ≪ τ) the pixel keeps the
/// solve's value, and σ = 0 keeps it bit for bit; where it is unsure (σ ≫ τ) the pixel takes the
/// network's value. A smooth weight rather than a threshold, so that the output does not jump
/// between neighbouring pixels whose σ straddles τ; its form is the Wiener gain of a correction
/// whose own error has variance τ² blended with an estimate whose error has variance σ².
/// Throws InvalidArgumentError when the three videos differ in size or τ is not positive and
/// finite.
Video GateCorrection(const Video& input, const Video& corrected, const Video& sigma, double tau);

}  // namespace evfs

#endif  // EVFS_DENOISER_DENOISER_H_

// A predicted error for every reconstructed pixel: how far the latent video is expected to lie
// from a frame the camera would have recorded at the same moment, in intensity units (one sigma).
//
// The model reads what the scene itself shows about how much its events can be trusted:
//  * Between two sharp frames F_a (latent frame a) and F_b, the events integrated from F_a
//    predict F_b; the gap D = F_b − ((F_a + b) · exp(ΔG) − b), with ΔG the change of g the
//    events record, is what the events got wrong over the whole interval. Read as a random walk
//    pinned at both frames (a Brownian bridge), the error at the fraction s of the pixel's
//    events (or of the time, where it has none) has variance ∝ s · (1 − s): at a pixel that
//    fired, from the local mean of D² (pooled over a small neighbourhood, since one pixel's gap
//    is a single sample), plus a share of the change the events drove; at a pixel that did not,
//    from its own D, a change under one threshold that the solve follows most of the way.
//  * Beyond the last sharp frame (prediction) or inside a blurred exposure nothing pins the far
//    end: the variance grows with the events since the nearest observation, n · v, v the
//    per-event variance the scene's pairs of sharp frames measured (Σ D² / Σ (n + 1)), or the
//    caller's prior, or the threshold's spread ((I + b) · σ_C)² when nothing measured it; at a
//    pixel that fired, plus a share of the change the events drove since the observation; at a
//    pixel that did not, a share of the change under one threshold that its gradient and the
//    motion around it (the events nearby per unit of gradient) suggest.
//  * The frames' own noise, the smaller of what the difference of two sharp frames shows where
//    the scene holds still and NoiseSigma's single-frame estimate, both without clipped pixels
//    (IsClippedLevel): once for the frame the output is compared with and once for the
//    observations the output carries (their blend at s).
#ifndef EVFS_SCENE_CONFIDENCE_H_
#define EVFS_SCENE_CONFIDENCE_H_

#include <string>

#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

struct ConfidenceOptions {
  /// Δg of one ON event in g = log(I + b) (the event model's change per event), > 0.
  double change_per_event = 0.2;
  /// Δg of an OFF event over Δg of an ON event, > 0.
  double off_change_ratio = 1.0;
  /// b of g = log(I + b), > 0.
  double log_offset = 0.5;
  /// Variance (intensity², per event) of what one event gets wrong, for scenes without a pair
  /// of sharp frames to measure it; < 0: unknown (one event's own change is used).
  double prior_event_variance = -1.0;
  /// Spread of a pixel's contrast threshold in g (σ of the change one event stands for), > 0:
  /// what one event gets wrong when nothing in the scene measured it. 0.03 is the literature's
  /// threshold mismatch (v2e's default; DAVIS pixels measure 2–4 % contrast).
  double threshold_spread = 0.03;
  /// Half-width in pixels of the square over which the frames' gaps are pooled, >= 0.
  int pool_radius_px = 2;

  bool IsValid(std::string* error) const;
};

/// What PredictErrorSigma measured on the scene.
struct ConfidenceModel {
  double frame_noise_sigma = 0.0;  // mean NoiseSigma of the observed frames
  /// Per-event variance measured between sharp frames (Σ D² / Σ (n + 1)); < 0 when the scene
  /// has no pair of sharp frames.
  double measured_event_variance = -1.0;
  /// One line for logs and summaries.
  std::string description;
};

/// The predicted one-sigma error of every pixel of `latent` (the scene's latent video, same
/// timeline), as a video of the same size and timestamps. `model` (may be null) receives what
/// was measured. Throws InvalidArgumentError for invalid options or a video that does not match
/// the scene.
Video PredictErrorSigma(const Scene& scene, const Video& latent, const ConfidenceOptions& options,
                        ConfidenceModel* model = nullptr);

/// The share of pixels whose error against the scene is at most `sigma` (the calibration of a
/// predicted one-sigma band: about 0.68 when the errors are Gaussian with that sigma). A truth
/// whose values are all whole 8-bit levels (a camera frame) gives the scene's intensity only to
/// within half a level: each pixel then counts with the probability that |estimate − x| <= sigma
/// for x uniform over its level's bin, the randomised count of Czado, Gneiting and Held
/// (Biometrics, 2009) for discrete observations. Counting |estimate − truth| <= sigma instead
/// jumps with sigma from level to level: where most errors are 0 or 1 level, no band holds
/// between 45 and 85 % of the pixels. Other truths count |estimate − truth| <= sigma. Throws
/// InvalidArgumentError when the sizes differ or the images are empty.
double ShareWithinSigma(const Image& estimate, const Image& truth, const Image& sigma);

/// The width of the bins `image`'s values were rounded to: 1/255 when every value is a whole
/// 8-bit level, else 0.
double QuantisationStep(const Image& image);

}  // namespace evfs

#endif  // EVFS_SCENE_CONFIDENCE_H_

// Deriving the event model's α from the data (docs/design.md §3, "model parameters from the data").
//
// α decides the quality more than any solver choice: tanh(α·Δg) must be able to express the
// change Δg one event stands for. α is set to `alpha_times_change / Δg`. When the scene has two
// sharp frames, Δg is measured: the median over pixels of the change of g between the frames
// divided by the net event count between them. Without two sharp frames but with two blurred
// ones, it is measured the same way between them, each at the middle of its exposure (a frame
// averaged over its exposure is close to the scene at that moment). Otherwise an assumed Δg is
// used: a typical DAVIS contrast threshold for the log model, and for the linear model the change
// measured this way on the shared DAVIS snippets (slider_depth 0.098, shapes_rotation 0.087). I·C
// with I the local intensity is not used: DAVIS frames and events see brightness through different
// responses, and it was 3× off on both snippets.
#ifndef EVFS_SCENE_EVENT_MODEL_ESTIMATION_H_
#define EVFS_SCENE_EVENT_MODEL_ESTIMATION_H_

#include <string>

#include "evfs/scene/event_model.h"
#include "evfs/scene/scene.h"

namespace evfs {

struct EventModelEstimationOptions {
  /// α times the intensity change of one event (in g's units): how far into tanh's range one
  /// event reaches. Chosen by measurement on the shared DAVIS snippets (docs/model.md).
  double alpha_times_change = 1.0;
  /// Log model: change of g per event assumed when the scene cannot tell (one frame only).
  /// 0.2 is a typical DAVIS contrast threshold; with the default b = 0.5 it is also near what
  /// slider_depth prediction measures best (benchmarks/results/model_choices.md, "The
  /// baselines' settings").
  double assumed_contrast_threshold = 0.2;
  /// Linear model: intensity change per event assumed when the scene cannot tell.
  double assumed_linear_change = 0.09;
  /// c of the event model (EventModelParams::saturation) when Δg is measured between two sharp
  /// frames: α = 1/Δg then says what one event stands for, and the curve should predict it
  /// rather than push past it (c = 1). An assumed Δg keeps the paper's c = 1, with which
  /// alpha_times_change and assumed_contrast_threshold were chosen.
  double measured_saturation = 1.25;
  /// Fewest pixels with both a net event count and a matching frame change needed to trust an
  /// estimate from frames.
  int min_pixels = 100;
  /// When Δg is measured and both polarities have min_pixels pixels: measure it apart for the
  /// pixels that brightened (ON) and darkened (OFF), α = alpha_times_change / Δg_ON and
  /// EventModelParams::off_alpha_ratio = Δg_ON / Δg_OFF. Otherwise one Δg for both.
  bool per_polarity = true;

  bool IsValid(std::string* error) const;
};

struct EventModelEstimate {
  double change_per_event = 0.0;  // Δg one event stands for, in the units of g
  bool estimated_from_frames = false;
  double alpha = 0.0;
  /// EventModelParams::off_alpha_ratio: Δg_ON / Δg_OFF when measured per polarity, else 1.
  double off_alpha_ratio = 1.0;
  /// c of the event model used with α (EventModelParams::saturation).
  double saturation = 1.0;
  /// One line for logs and summaries, e.g.
  /// "change per event 0.0912 (measured between the frames at 4172 pixels), alpha 5.48".
  std::string description;
};

/// Estimates Δg and α for `model` from the scene (its frame observations and event frames).
EventModelEstimate EstimateEventModel(const Scene& scene, const EventModelParams& model,
                                      const EventModelEstimationOptions& options);

}  // namespace evfs

#endif  // EVFS_SCENE_EVENT_MODEL_ESTIMATION_H_

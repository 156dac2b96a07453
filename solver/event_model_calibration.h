// Calibrating the event model of a recording from its own frames and events: the offset b of
// g(I) = log(I + b), the ON and OFF contrast thresholds, their spread over pixels and the rate
// of background events (docs/model.md, "Calibrating the event model").
//
// Over the frames of a recording, a pixel's reference level (the log intensity of its last
// event) moves by exactly C_on per ON event and -C_off per OFF event, and its log intensity
// log(I + b) stays within (-C_off, C_on) of it (paper Eq. 1). So, with N_on,k and N_off,k its
// events from the first frame to frame k,
//   log(I_k + b) - C_on · N_on,k + C_off · N_off,k
// is the same at every frame up to that band (cost_functions/event_count_residual.h). A robust
// (Huber) least-squares fit of its spread over every usable pixel that fires gives b and the
// thresholds. Pixels that change without firing are left out of it: they bound the thresholds
// from below only, and as residuals in events (divided by the threshold) they would pull the
// thresholds up; where most pixels fire rarely (real recordings, slow scenes) that pull tripled
// the thresholds of a simulated sensor.
// Taking the levels over several frames rather than the change between two keeps the band's
// width from biasing the thresholds where the light reverses: a pixel that darkened before
// needs more than C_on of rise for its first ON event, which a per-pair fit reads as a larger
// threshold.
#ifndef EVFS_SOLVER_EVENT_MODEL_CALIBRATION_H_
#define EVFS_SOLVER_EVENT_MODEL_CALIBRATION_H_

#include <string>
#include <vector>

#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"

namespace evfs {

struct EventModelCalibrationOptions {
  /// A pixel is left out at the frames where it is darker than this, in [0, 1): 8-bit frames
  /// quantise a dark pixel's log intensity too coarsely to say what its events stand for. Its
  /// runs of usable frames between enter the fit apart.
  double min_intensity = 2.0 / 255.0;
  /// A pixel at or above this level is saturated and left out at that frame, in (0, 1].
  double saturation_level = 0.99;
  /// A pixel whose frames span less than this is left out of the fit, >= 0: with no change to
  /// explain it says nothing of b or the thresholds (only of the background, which is measured
  /// apart). 1/255: the step of 8-bit frames. Runs of frames without events are left out as
  /// well (CalibrateEventModel).
  double min_frame_change = 1.0 / 255.0;
  /// Huber scale of the residual, in events, > 0: the band alone scatters a pixel's level by
  /// about ±0.5 events; a pixel that occlusion, noise or a hot pixel puts several events off
  /// counts linearly.
  double huber_scale_events = 1.0;
  /// Bounds of b and of each threshold.
  double min_log_offset = 1e-4;
  double max_log_offset = 10.0;
  double min_threshold = 0.01;
  double max_threshold = 2.0;
  /// b the solve starts from; the start with the lowest cost wins (the cost is not convex in
  /// b, and which basin holds the answer depends on how dark the scene is).
  std::vector<double> log_offset_starts = {1e-3, 1e-2, 0.1, 1.0};
  /// Fewest pixels with events of a polarity to fit that polarity's threshold on its own; with
  /// fewer, ON and OFF share one threshold. Also the fewest pixels with events that change
  /// between the frames for any calibration.
  int min_pixels = 100;
  /// A pixel is quiet in a pair when neither it nor its 8 neighbours change g by more than this
  /// fraction of the smaller threshold between the frames: its events there are background
  /// (leak, shot noise, hot pixels), not the scene's.
  double quiet_fraction = 0.05;
  /// At most this many pixels (runs of usable frames) enter the fit, >= 0; more are thinned to
  /// every k-th, in raster order. 0: all. The standard errors are those of the pixels fitted.
  int max_fit_pixels = 0;

  bool IsValid(std::string* error) const;
};

/// One calibrated value with its standard error and what carried it.
struct CalibratedValue {
  double value = 0.0;
  double standard_error = 0.0;
  int pixels = 0;  // pixels (runs of usable frames of one pixel) that informed it
  int pairs = 0;   // consecutive frame pairs they span
  bool estimated = false;
};

struct EventModelCalibration {
  CalibratedValue log_offset;          // b of g = log(I + b)
  CalibratedValue threshold_on;        // C_on, in g's units
  CalibratedValue threshold_off;       // C_off, in g's units
  CalibratedValue threshold_sigma;     // spread of the per-pixel thresholds (std dev), g units
  CalibratedValue background_rate_hz;  // events per pixel per second at quiet pixels
  bool thresholds_tied = false;        // one threshold for both polarities (too few of one)
  double residual_rms_events = 0.0;    // of the inlier residuals (|r| <= 3 events)
  int pixels_used = 0;                 // pixel observations in the fit
  int pixels_with_events = 0;          // of them, those with at least one event
  int pairs_used = 0;
  /// Several lines for the terminal, one value each with its uncertainty and counts.
  std::string description;
};

/// Calibrates from `frames` (grey values in [0, 1], in time order, at `times_ns`, strictly
/// increasing) and the events covering them. Throws InvalidArgumentError, with one line saying
/// what is missing, when the data cannot tell: fewer than two frames, no events between them, or
/// fewer than options.min_pixels usable pixels with events (frames that do not change, all dark
/// or all saturated); and for invalid options or frames of another size than the events' sensor.
EventModelCalibration CalibrateEventModel(const std::vector<Image>& frames,
                                          const std::vector<int64_t>& times_ns,
                                          const EventStream& events,
                                          const EventModelCalibrationOptions& options);

}  // namespace evfs

#endif  // EVFS_SOLVER_EVENT_MODEL_CALIBRATION_H_

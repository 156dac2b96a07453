// Whether an exposure blurred a frame, decided from the frame and the events inside its exposure.
//
// A frame exposed over [t_begin, t_end] records B = mean_t I(t), the sharp scene at mid-exposure
// I(t_mid) averaged with how it changed meanwhile. The events inside the exposure say how it
// changed: with the log model g = log(I + b), one event moves g by about one contrast threshold C,
// so at pixel p
//   B(p) + b = (I_mid(p) + b) · r(p),   r(p) = mean_t exp(C · (N_p(t) − N_p(t_mid)))
// where N_p(t) is p's signed event count up to t. The blur the events predict is the difference
// between the frame and the sharp frame, B − I_mid = (B + b)(1 − 1/r). Observing the frame over
// its exposure (a deblur) is worth its cost only where that difference stands out of the
// frame's own noise: a still scene under a long exposure, or a dark scene whose events are
// mostly noise, leaves a frame that is as sharp as it can be, and treating it as blurred hands
// the solve a looser constraint than the frame gives.
#ifndef EVFS_SCENE_EXPOSURE_BLUR_H_
#define EVFS_SCENE_EXPOSURE_BLUR_H_

#include <cstdint>
#include <string>

#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"

namespace evfs {

struct ExposureBlurOptions {
  /// C: the change of g one event stands for (a typical DAVIS contrast threshold).
  double contrast_threshold = 0.2;
  /// b of g = log(I + b), as the default event model uses it.
  double log_offset = 0.5;
  /// The frame is blurred when the RMS of the predicted blur over the frame exceeds this many
  /// times the frame's noise (NoiseSigma): 1 reads "the blur is larger than the noise".
  double noise_multiple = 1.0;
  /// Pixels whose events reverse polarity this often within the exposure flicker
  /// (FindFlickeringPixels) and do not count: their events follow the light, not the motion.
  int flicker_min_reversals = 3;
  /// Pixels firing more than this many times as often as the busy pixels are hot
  /// (MeasurePixelActivity) and do not count.
  double hot_pixel_factor = 10.0;
  /// Events that no neighbouring pixel confirms within this many milliseconds are background
  /// activity, not motion, and do not count (WithoutUnsupportedEvents): a moving edge fires
  /// its neighbours along the edge at almost the same moment. 0 counts every event.
  double support_window_ms = 2.0;

  bool IsValid(std::string* error) const;
};

/// What ExposureBlur found.
struct ExposureBlurEstimate {
  bool blurred = false;
  double predicted_blur_rms = 0.0;  // RMS over the pixels of (B + b)(1 − 1/r), intensity units
  double noise_sigma = 0.0;         // NoiseSigma of the frame
  int64_t events = 0;               // events inside the exposure that were counted
  /// One line for logs and summaries.
  std::string description;
};

/// Whether a frame's intensity (in [0, 1]) is within half an 8-bit level of black or white,
/// where the sensor clips it: such a pixel shows no noise.
inline bool IsClippedLevel(double intensity) {
  return intensity <= 0.5 / 255.0 || intensity >= 1.0 - 0.5 / 255.0;
}

/// The standard deviation of a frame's noise, estimated from the frame alone (J. Immerkær, "Fast
/// noise variance estimation", CVIU 1996): the mean absolute response to the Laplacian-difference
/// mask that cancels locally linear image content, sqrt(π/2) / (6 (W−2)(H−2)) · Σ |I ∗ M|.
/// Frames smaller than 3×3 give 0. With `leave_out_clipped`, the sum runs only over pixels
/// whose 3×3 neighbourhood has no clipped value (IsClippedLevel): a clipped region shows no
/// noise, and counted it would dilute the estimate (0 when none is left).
double NoiseSigma(const Image& frame, bool leave_out_clipped = false);

/// Whether the exposure [begin_ns, end_ns] blurred `frame`, from the events of `events` inside it
/// (events outside are ignored). Throws InvalidArgumentError for invalid options, an empty
/// exposure or a frame of another size than the events' sensor.
ExposureBlurEstimate ExposureBlur(const Image& frame, const EventStream& events, int64_t begin_ns,
                                  int64_t end_ns, const ExposureBlurOptions& options = {});

}  // namespace evfs

#endif  // EVFS_SCENE_EXPOSURE_BLUR_H_

// An event-camera simulator in the manner of ESIM: H. Rebecq, D. Gehrig, D. Scaramuzza, "ESIM:
// an Open Event Camera Simulator", CoRL 2018.
//
// Each pixel tracks L = log(I + log_eps). Between two frames L is interpolated linearly in time;
// whenever L - reference reaches +C_pos (or -C_neg) the pixel emits an ON (OFF) event at the
// interpolated crossing time and its reference moves by exactly ±C, so one frame pair may give
// several events per pixel. Thus, without noise or refractory period, after every frame
//   -C_neg < L(last frame) - (L(first frame) + C_pos · #ON - C_neg · #OFF) < C_pos
// at every pixel (the round trip ESIM is tested by).
//
// Sensor effects beyond ESIM's, each off by default, follow v2e (Y. Hu, S.-C. Liu, T. Delbruck,
// "v2e: From Video Frames to Realistic DVS Events", CVPRW 2021):
//   - leak events: ON events a pixel emits without any change of light, because junction
//     leakage slowly discharges its reference (v2e's leak_rate_hz, by default 0.1 Hz, with a
//     10 % per-pixel spread);
//   - hot pixels: the few pixels whose noise rate is orders of magnitude above the rest (v2e
//     draws per-pixel shot noise rates with a spread for the same reason);
//   - the photoreceptor's bandwidth, which falls with the light: v2e's intensity-dependent
//     first-order low-pass of log intensity,
//       L_lp ← L_lp + a · (L - L_lp),
//       a = min(1, 2π · cutoff_hz · (I + 20/255) / (1 + 20/255) · Δt),
//     so that a white pixel follows the light with the time constant 1 / (2π cutoff_hz) and a
//     black one 275/20 = 13.75 times slower (v2e adds 20 DN to the 8-bit intensity, which bounds
//     the darkest pixel's time constant).
// Flickering light sources (events/flicker.h) are sampled between frames by SimulateEvents.
#ifndef EVFS_EVENTS_SIMULATOR_H_
#define EVFS_EVENTS_SIMULATOR_H_

#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"
#include "evfs/events/flicker.h"
#include "evfs/events/random.h"

namespace evfs {

/// Sensor model of the simulator. The defaults describe a clean DAVIS-like sensor: contrast
/// thresholds of 0.2 in log intensity (DAVIS346/240 are typically set to 0.1–0.5), a 0.03
/// per-pixel threshold mismatch (the few-percent fixed-pattern spread measured on DVS pixels),
/// and neither refractory period nor background noise, so that benchmarks see realistic but
/// clean events. Benchmarks depend on these values: change them only with the benchmarks.
struct SimulatorOptions {
  double contrast_threshold_pos = 0.2;  // nominal ON threshold C_pos, in log intensity, > 0
  double contrast_threshold_neg = 0.2;  // nominal OFF threshold C_neg, in log intensity, > 0
  double threshold_sigma = 0.03;        // std dev of the per-pixel thresholds around C, >= 0
  int64_t refractory_period_ns = 0;     // events closer than this to the pixel's last are dropped
  double noise_rate_hz = 0.0;           // background events per pixel per second (random sign)
  double log_eps = 1e-3;                // offset b of L = log(I + b), > 0
  /// Leak events per pixel per second, >= 0 (v2e's leak_rate_hz; 0.1 is v2e's default): the
  /// pixel's reference falls by leak_rate_hz · C_pos per second, so a pixel under constant light
  /// emits ON events at that rate.
  double leak_rate_hz = 0.0;
  /// Per-pixel spread of the leak rate as a fraction of it, >= 0 (v2e's leak_jitter_fraction).
  double leak_jitter_fraction = 0.1;
  /// Photoreceptor cutoff frequency at full intensity in Hz, >= 0 (v2e's cutoff_hz); 0: no
  /// low-pass, the pixel follows the light at once. With it, SimulateEvents sub-steps every
  /// frame interval so that a · Δt stays small (see BandwidthMaxStepNs).
  double cutoff_hz = 0.0;
  double hot_pixel_fraction = 0.0;   // fraction of pixels that are hot, in [0, 1]
  double hot_pixel_rate_hz = 100.0;  // events per second of each hot pixel (random sign), > 0
  uint64_t seed = 42;                // seeds the thresholds, the noise, the leak and the hot pixels

  /// The longest sub-step of the low-pass, 2π · cutoff_hz · Δt <= 1/4, so that the filter's
  /// discrete steps follow its continuous response; only meaningful when cutoff_hz > 0.
  int64_t BandwidthMaxStepNs() const;
  /// Most events one Advance (and SimulateEvents in all) may produce, > 0: about 30 bytes each
  /// while simulating, so the default bounds memory near 3 GB. Background noise beyond it is
  /// refused before it is drawn (noise_rate_hz × pixels × seconds is known in advance).
  int64_t max_events = 100000000;

  /// False (with a reason in `error`, which may be null) when a field is out of range.
  bool IsValid(std::string* error) const;
};

/// Turns a sequence of frames (linear intensity, nominally [0, 1], never negative) into events.
///
/// Per-pixel thresholds are drawn once, in the constructor, from N(C, threshold_sigma) and
/// clamped to >= 0.01 (ESIM's floor). ESIM redraws them for every frame pair; a fixed draw is the
/// fixed-pattern mismatch of a real sensor.
///
/// Leak: each pixel leaks at its own rate, drawn once from N(leak_rate_hz, leak_jitter_fraction ·
/// leak_rate_hz) clamped at 0, and starts (at Reset) a uniformly drawn part of the way to its
/// first leak event, so that pixels under constant light do not fire in step. That head start
/// is an offset of up to one C_pos between L and the reference, so a pixel's first signal event
/// after Reset also comes early (ON) or late (OFF) by up to one threshold. The leak moves the
/// reference continuously and events are timed where L minus the moving reference crosses ±C.
///
/// Hot pixels: round(hot_pixel_fraction · pixels) distinct pixels, drawn once, each a Poisson
/// source of hot_pixel_rate_hz events of random sign on top of the background noise.
///
/// Refractory period: as in ESIM, an event closer than refractory_period_ns to the last event
/// the pixel emitted is dropped but the pixel's reference level still moves, so the reference
/// keeps following the signal (and the round trip holds for emitted plus dropped events, not
/// for the emitted ones alone). Noise events obey the same refractory rule and never move the
/// reference.
class EventSimulator {
 public:
  /// Throws InvalidArgumentError for invalid options or a size outside [1, 65536].
  EventSimulator(int height, int width, const SimulatorOptions& options);

  /// Starts (or restarts) the sensor at `first_frame`: every reference level is set to the
  /// frame's log intensity, the refractory memory is cleared and the noise generator reseeded,
  /// so the events after a Reset depend only on the options and the frames given since.
  void Reset(const Image& first_frame, int64_t t_ns);

  /// The events between the previous frame and `next_frame`, with timestamps in
  /// (previous t_ns, t_ns], sorted by time (ties by pixel index, then in order of generation),
  /// sensor size set. Throws InvalidArgumentError before Reset, for a frame of another size,
  /// a negative or non-finite intensity, t_ns not after the previous frame, or more than
  /// options.max_events events (expected noise events checked before drawing any).
  EventStream Advance(const Image& next_frame, int64_t t_ns);

  int height() const { return height_; }
  int width() const { return width_; }
  /// The per-pixel thresholds C_pos and C_neg (row-major), fixed in the constructor.
  const std::vector<double>& threshold_pos() const { return threshold_pos_; }
  const std::vector<double>& threshold_neg() const { return threshold_neg_; }
  /// The hot pixels (row-major indices, ascending), fixed in the constructor.
  const std::vector<int32_t>& hot_pixels() const { return hot_pixels_; }

 private:
  /// One event before sorting and the refractory filter.
  struct PendingEvent {
    int64_t t_ns;
    int32_t pixel;
    int8_t polarity;
  };

  void CheckFrame(const Image& frame, const char* caller) const;
  void AddSignalEvents(const Image& next_frame, int64_t t_ns, std::vector<PendingEvent>* out);
  void AddNoiseEvents(int64_t t_ns, std::vector<PendingEvent>* out);
  void AddHotPixelEvents(int64_t t_ns, std::vector<PendingEvent>* out);

  int height_;
  int width_;
  SimulatorOptions options_;
  std::vector<double> threshold_pos_;   // per-pixel C_pos
  std::vector<double> threshold_neg_;   // per-pixel C_neg
  std::vector<double> log_intensity_;   // L (low-passed with cutoff_hz) at the previous frame
  std::vector<double> reference_;       // the level the next crossing is measured from
  std::vector<int64_t> last_event_ns_;  // last emitted event per pixel (refractory)
  std::vector<double> leak_per_s_;      // per-pixel leak of the reference, log intensity / s
  std::vector<double> leak_start_;      // per-pixel leak at Reset (the random phase)
  std::vector<double> leak_;            // leak accumulated since Reset, added to L
  std::vector<int32_t> hot_pixels_;
  Random noise_random_;
  Random hot_pixel_random_;
  int64_t t_ns_ = 0;      // time of the previous frame
  bool started_ = false;  // Reset has been called
};

/// Simulates the events of a whole video (frame 0 starts the sensor); the stream's sensor size
/// is the video's. With light sources (`flicker` enabled) or a photoreceptor cutoff the sensor
/// sees the scene at sub-steps of at most flicker.MaxStepNs() and options.BandwidthMaxStepNs(),
/// evenly spaced in every frame interval: the frames' log intensities interpolated linearly,
/// back to linear intensity, plus the light sources at that instant. Throws InvalidArgumentError
/// for an empty video or invalid flicker options, when the expected noise, hot pixel and leak
/// events over the whole video or the events produced exceed options.max_events, or as
/// EventSimulator does.
EventStream SimulateEvents(const Video& frames, const SimulatorOptions& options,
                           const FlickerOptions& flicker = FlickerOptions());

}  // namespace evfs

#endif  // EVFS_EVENTS_SIMULATOR_H_

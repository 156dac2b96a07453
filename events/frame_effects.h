// The intensity frames a camera records of a simulated scene: an exposure window, a gain that
// saturates bright parts, fixed-pattern noise, read noise and 8-bit quantisation. The events are
// simulated from the true scene (events/simulator.h); these effects touch the frames only.
//
// Readout of one pixel p with exposed (time-averaged) intensity E_p, all in [0, 1] = [0, 255] DN:
//   v_p = gain · (1 + g_p) · E_p + o_p / 255 + n / 255
//   frame_p = round(255 · clip(v_p, 0, 1)) / 255
// with g_p ~ N(0, fpn_gain_sigma) and o_p ~ N(0, fpn_offset_dn) drawn once per sensor (the
// photo-response non-uniformity and dark-signal non-uniformity of EMVA 1288, the fixed pattern
// of a CMOS imager such as the DAVIS APS: C. Brandli et al., "A 240 × 180 130 dB 3 µs latency
// global shutter spatiotemporal vision sensor", JSSC 2014), and n ~ N(0, read_noise_dn) drawn
// anew for every pixel of every frame (temporal read noise).
#ifndef EVFS_EVENTS_FRAME_EFFECTS_H_
#define EVFS_EVENTS_FRAME_EFFECTS_H_

#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/events/flicker.h"
#include "evfs/events/random.h"

namespace evfs {

/// What happens to the frames between the scene and the file. The defaults change nothing.
struct FrameEffectsOptions {
  /// Exposure time in seconds, >= 0: a frame is the mean of the scene over
  /// [t - exposure_s / 2, t + exposure_s / 2] around its timestamp t, cut to the video's span;
  /// 0 takes the scene at t.
  double exposure_s = 0.0;
  double gain = 1.0;            // multiplies the exposed intensity before clipping at 1, > 0
  double read_noise_dn = 0.0;   // std dev of the temporal read noise in 8-bit DN, >= 0
  double fpn_offset_dn = 0.0;   // std dev of the per-pixel offset in 8-bit DN, >= 0
  double fpn_gain_sigma = 0.0;  // std dev of the per-pixel relative gain, in [0, 1)
  uint64_t seed = 42;           // seeds the fixed pattern and the read noise

  /// Whether any effect is on (a frame is then read out as above, clipped and quantised).
  bool enabled() const;

  /// False (with a reason in `error`, which may be null) when a field is out of range.
  bool IsValid(std::string* error) const;
};

/// The scene at `t_ns`: `frames` interpolated linearly in intensity (held beyond the ends) plus
/// the light sources.
Image SceneAt(const Video& frames, const FlickerOptions& flicker, int64_t t_ns);

/// The times at which an exposure over [begin_ns, end_ns] samples the scene: the midpoints of
/// n equal parts, with n the larger of 16 and the number of parts no longer than `max_step_ns`.
std::vector<int64_t> ExposureSampleTimes(int64_t begin_ns, int64_t end_ns, int64_t max_step_ns);

/// The mean of SceneAt over ExposureSampleTimes(begin_ns, end_ns, max_step_ns).
Image ExposedScene(const Video& frames, const FlickerOptions& flicker, int64_t begin_ns,
                   int64_t end_ns, int64_t max_step_ns);

/// The readout of one sensor: its fixed pattern, drawn in the constructor, and its read noise.
class FrameReadout {
 public:
  /// Throws InvalidArgumentError for invalid options or a non-positive size.
  FrameReadout(int height, int width, const FrameEffectsOptions& options);

  /// The 8-bit frame of an exposed intensity image (see the formula above); each call draws
  /// new read noise.
  Image Read(const Image& exposed);

 private:
  FrameEffectsOptions options_;
  Image gain_;    // gain · (1 + g_p)
  Image offset_;  // o_p / 255
  Random read_noise_random_;
};

/// A frame as the camera writes it.
struct RecordedFrame {
  Image image;
  bool has_exposure = false;  // exposure_s > 0: the window below is the frame's
  int64_t exposure_begin_ns = 0;
  int64_t exposure_end_ns = 0;
};

/// The frames a camera with `options` records of the scene `frames` lit by `flicker`, one per
/// frame of `frames` at its timestamp. Without light sources and without effects these are the
/// frames themselves, untouched. Throws InvalidArgumentError for invalid options or an empty
/// video.
std::vector<RecordedFrame> RecordFrames(const Video& frames, const FlickerOptions& flicker,
                                        const FrameEffectsOptions& options);

}  // namespace evfs

#endif  // EVFS_EVENTS_FRAME_EFFECTS_H_

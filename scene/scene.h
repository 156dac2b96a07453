// A reconstruction problem as data: what was observed (frames with their exposure spans, event
// frames with their latent spans) on one latent timeline (docs/design.md §1–2). Interpolation,
// prediction and deblurring are presets of this one structure; the solver never branches on
// the case.
#ifndef EVFS_SCENE_SCENE_H_
#define EVFS_SCENE_SCENE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/enum_names.h"
#include "evfs/core/event_frames.h"
#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"
#include "evfs/events/binning.h"

namespace evfs {

/// An intensity frame as recorded: sharp when exposure_begin_ns == exposure_end_ns, otherwise
/// the time average of the scene over its exposure (a motion-blurred frame).
struct TimedFrame {
  Image image;
  int64_t exposure_begin_ns = 0;
  int64_t exposure_end_ns = 0;
  std::string label;  // where it came from, for messages ("images/frame_00000070.png")
};

/// One frame observation on the latent timeline: F_j = mean(H_a … H_b).
struct FrameObservation {
  Image image;
  int latent_first = 0;
  int latent_last = 0;
  std::string label;
};

/// How events are binned into event frames (paper §3.3). Every method honours
/// max_latent_voxels: the binning is decided from counts (CountCollisionFrames) before any frame
/// is allocated, and one that would exceed it is either avoided (kAuto) or refused (kCollision,
/// kStacked: InvalidArgumentError naming the option).
struct BinningOptions {
  /// The longest noise_filter_ms accepted: an hour.
  static constexpr double kMaxNoiseFilterMs = 3.6e6;

  enum class Method {
    kAuto,       // collision binning unless it gives more steps than the limits allow
    kCollision,  // the paper's Binning 1: one step per collision frame, values in {-1, 0, 1}
    kStacked,    // the paper's Binning 2: StackedBinningOptions
  };
  Method method = Method::kAuto;
  /// kAuto: the most latent steps; above it, stacked equal-time binning with this many frames
  /// is used instead (memory and time grow linearly with latent frames).
  int max_latent_frames = 48;
  /// kAuto with collision binning: where the collision frames give fewer latent steps than
  /// this, each is split in time (BinByCollision's min_latent_steps) until the window has this
  /// many, within max_latent_frames and max_latent_voxels; 0 or 1 keeps the collision frames as
  /// they are. An explicit kCollision is never split.
  int min_latent_steps = 16;
  /// Every method: the most latent voxels (pixels × latent frames). kAuto gives larger sensors
  /// fewer steps (as many as fit, at least 1); kCollision and kStacked beyond it are refused.
  /// 12 M keeps all 48 steps up to 500×500, where fewer steps cost accuracy, within the memory
  /// of a laptop (BENCHMARKS.md, "Where the defaults come from").
  int64_t max_latent_voxels = 12000000;
  /// Every method: pixels with more than this many times the events of the scene's busy pixels
  /// are hot (MeasurePixelActivity) and their events are left out before binning, so that a
  /// stuck pixel neither multiplies the collision frames nor bends its own pixel; 0 keeps every
  /// event. 10 is more than twice the largest ratio in the shared DAVIS recordings (4.4).
  double hot_pixel_factor = 10.0;
  /// Every method: a frame pixel at or above this level (intensity in [0, 1]) is saturated
  /// (flicker_min_reversals, leave_out_saturated); > 1: none is. The default takes the top two
  /// codes of an 8-bit frame.
  double saturation_level = 0.995;
  /// Every method: leave out the events of pixels saturated in every frame of the window, where
  /// the frames cannot show the changes the events record. Off by default: on the real
  /// recordings it fires on, their events were still worth more than the frames (BENCHMARKS.md,
  /// "Real recordings"); a saturated light that flickers is taken by flicker_min_reversals.
  bool leave_out_saturated = false;
  /// Every method: pixels whose events reverse polarity at least this many times in the window
  /// with almost no net change flicker (FindFlickeringPixels: a blinking LED or a mains-powered
  /// lamp). Where such a pixel lies within two pixels of one that a frame of the window shows at
  /// or above saturation_level, the light is brighter than the frames can show and the events'
  /// amplitude disagrees with them: its events are left out, so the frames govern there. A light
  /// the frames show unsaturated keeps its events, which follow it as the frames do. 0 keeps
  /// every flickering pixel's events.
  int flicker_min_reversals = 3;
  /// Every method: after the hot pixels, events that no neighbouring pixel confirms within this
  /// many milliseconds are left out as background activity (WithoutUnsupportedEvents); 0 keeps
  /// them.
  double noise_filter_ms = 0.0;
  StackedBinningOptions stacked;  // used by kStacked

  bool IsValid(std::string* error) const;
};

/// --binning's names.
inline constexpr EnumName<BinningOptions::Method> kBinningMethodNames[] = {
    {BinningOptions::Method::kAuto, "auto", "collision binning unless it exceeds the limits"},
    {BinningOptions::Method::kCollision, "collision", "one step per collision frame"},
    {BinningOptions::Method::kStacked, "stacked", "stacked equal-time or equal-count frames"},
};

/// What binning a window gets, decided from counts alone (no frame is allocated).
struct BinningPlan {
  BinningOptions::Method method = BinningOptions::Method::kCollision;  // kCollision or kStacked
  StackedBinningOptions stacked;  // kStacked: the frames and steps used
  int num_event_frames = 0;
  int num_latent_frames = 2;
  int64_t pixels = 0;            // of the sensor
  int64_t collision_frames = 0;  // what collision binning gives, hot pixels left out
  int64_t min_latent_steps = 0;  // kCollision: BinByCollision's split (0: none)
  PixelActivity activity;        // hot pixels and counts, before leaving any out
  int64_t noise_events = 0;      // left out by the background-activity filter
  /// Pixels (row-major, ascending) whose events were left out, besides the hot ones, because
  /// a frame saturates there (saturation_level) or the pixel flickers (flicker_min_reversals),
  /// and how many events each rule left out. A pixel counts under the first rule that takes it.
  std::vector<int32_t> saturated_pixels;
  int64_t saturated_pixel_events = 0;
  std::vector<int32_t> flickering_pixels;
  int64_t flickering_pixel_events = 0;

  int64_t latent_voxels() const { return pixels * num_latent_frames; }
};

/// Decides the binning of the events in [window_begin_ns, window_end_ns) from counts, after
/// leaving out the events of hot, saturated (with leave_out_saturated: in every one of `frames`,
/// which may be empty) and flickering pixels. Throws InvalidArgumentError, naming the option to
/// change, when the binning asked for would exceed binning.max_latent_voxels (explicit collision or
/// stacked binning over it, or a sensor on which not even one latent step fits), for invalid
/// options, for a frame of another size than the sensor, or as the binning functions do.
/// Throws InvalidArgumentError, naming max_latent_voxels, when a width × height sensor cannot
/// fit the fewest latent frames `binning` allows (two; stacked binning: its frames × steps + 1)
/// within binning.max_latent_voxels. PlanBinning checks the same from the events; this check
/// needs only the declared sizes, so readers call it before decoding a frame.
void CheckSensorFitsLatentVoxels(int width, int height, const BinningOptions& binning);

BinningPlan PlanBinning(const EventStream& events, int64_t window_begin_ns, int64_t window_end_ns,
                        const BinningOptions& binning,
                        const std::vector<const Image*>& frames = {});

struct Scene {
  int height = 0;
  int width = 0;
  std::vector<FrameObservation> frames;
  /// Event frames; their spans and latent_timestamps_ns() define the latent timeline.
  EventFrames events;
  int64_t num_events = 0;  // events binned into `events`
  /// Pixels whose events were left out as hot (row-major indices), and how many events they had.
  std::vector<int32_t> hot_pixels;
  int64_t hot_pixel_events = 0;
  /// Events left out by the background-activity filter (BinningOptions::noise_filter_ms).
  int64_t noise_events = 0;
  /// Pixels whose events were left out because a frame saturates there or they flicker
  /// (BinningPlan), and how many events each rule left out.
  std::vector<int32_t> saturated_pixels;
  int64_t saturated_pixel_events = 0;
  std::vector<int32_t> flickering_pixels;
  int64_t flickering_pixel_events = 0;

  int num_latent_frames() const { return static_cast<int>(events.latent_timestamps_ns().size()); }
  const std::vector<int64_t>& latent_timestamps_ns() const { return events.latent_timestamps_ns(); }
};

/// Builds the general scene: bins `events` over [window_begin_ns, window_end_ns) as PlanBinning
/// decides, then ties each frame to the latent frames of its exposure (a sharp frame to the
/// nearest latent frame). Throws InvalidArgumentError when a frame lies outside the window,
/// sizes disagree or PlanBinning refuses.
Scene MakeScene(const std::vector<TimedFrame>& frames, const EventStream& events,
                int64_t window_begin_ns, int64_t window_end_ns, const BinningOptions& binning);

/// Interpolation (paper §3.2): sharp frames at both ends of the window.
Scene MakeInterpolationScene(const TimedFrame& first, const TimedFrame& last,
                             const EventStream& events, const BinningOptions& binning);
/// Prediction: a sharp frame at the start and events up to window_end_ns.
Scene MakePredictionScene(const TimedFrame& first, int64_t window_end_ns, const EventStream& events,
                          const BinningOptions& binning);
/// Motion deblur: one blurred frame whose exposure is the window.
Scene MakeDeblurScene(const TimedFrame& blurred, const EventStream& events,
                      const BinningOptions& binning);

/// The initialisation of docs/design.md §1: the frame observations blended linearly along the
/// latent timeline (a copy when there is only one, held constant beyond the first and last).
Video InitializeLatentVideo(const Scene& scene);

}  // namespace evfs

#endif  // EVFS_SCENE_SCENE_H_

// The unknowns of a reconstruction: which latent voxels H_t(p) are solved for, and which of them
// share one value (docs/design.md §3, "skipping what a scene does not need").
//
// Each pixel in the problem has its time series H_0(p) … H_K(p) cut into segments of
// consecutive latent frames that share one value. An active pixel starts a new segment only at
// a latent step inside an event frame that fired at the pixel: between its events the pixel
// is constant. A ring pixel (held constant) starts one where its initial value has moved more
// than a tolerance: each of its segments enters its neighbours' spatial TV as one constant, and
// every segment there cuts their TV runs, so a ring that followed every small change of a
// blended initialisation would multiply the spatial TV terms by the latent frames.
//
// Why merging quiet steps changes the reconstruction so little: at a step where the pixel did not
// fire, any change d costs λ_e|tanh(α d)| + λ_t|d| (event and temporal terms), more than the
// frame terms can gain from it (at most |d| per frame weight), so the minimiser of the full
// problem keeps the pixel constant there anyway. On slider_depth the merged layout has about a
// tenth of the unknowns, which is what the solve time follows.
//
// An active pixel that never fires is one segment, one constant over the window. Between two
// frames the frame terms pin it; after the last frame nothing does, and a constant cannot
// follow the motion its neighbours report. With `unfired_changes`, such a pixel whose 8
// neighbours hold at least two events after the last frame gets one change: a new segment at
// the event frame holding the median of those events (all of that frame's steps, so that an
// event frame stays all new segments or none). The change has no event residual (the pixel
// did not fire: it stayed under a threshold, which says little about its size); the temporal
// and spatial TV price it.
//
// Storage: a segment's value lives in the latent Video, in the voxel of its first frame, so
// a ceres::Problem over segments is a problem over voxels of that Video. Expand() copies each
// value to the rest of its segment after a solve.
#ifndef EVFS_SOLVER_LATENT_LAYOUT_H_
#define EVFS_SOLVER_LATENT_LAYOUT_H_

#include <cstdint>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/scene/scene.h"

namespace evfs {

class LatentLayout {
 public:
  struct Segment {
    int64_t pixel = 0;
    int first = 0;          // first latent frame
    int last = 0;           // last latent frame (inclusive)
    bool constant = false;  // a ring pixel's segment: held at its initial value
    /// A constant's value in the problem: the mean of the initial video over the segment.
    double held = 0.0;
    /// The segment begins with an unfired pixel's change (no event residual there).
    bool unfired_change = false;
    int length() const { return last - first + 1; }
  };

  /// Segments for every pixel the mask puts in the problem. With `merge_quiet_steps` false every
  /// voxel is its own segment (the plain per-voxel layout). `initial` is the initial latent video
  /// (for ring pixels' constants). `unfired_changes` (merged layout only): unfired pixels next to
  /// events after the last frame get one change (above). `ring_tolerance` (merged layout only):
  /// a ring pixel starts a new constant where its initial value moves more than this from the
  /// value it had where the constant began (0: wherever it changes).
  LatentLayout(const Scene& scene, const ActivityMask& mask, const Video& initial,
               bool merge_quiet_steps, bool unfired_changes = false, double ring_tolerance = 0.0);

  int num_latent_frames() const { return num_latent_frames_; }
  int64_t pixels_per_frame() const { return pixels_per_frame_; }
  int64_t num_segments() const { return static_cast<int64_t>(segments_.size()); }
  int64_t num_variable_segments() const { return num_variable_segments_; }
  const Segment& segment(int64_t s) const { return segments_[s]; }

  /// Index of the segment holding H_t(p), or -1 when pixel p is not in the problem.
  int64_t segment_at(int t, int64_t p) const {
    return segment_of_voxel_[static_cast<size_t>(t) * pixels_per_frame_ + p];
  }

  /// The storage of segment s: the voxel of its first frame inside `latent`, or for a constant
  /// its held value (a parameter block Ceres never changes; the voxels keep their own values).
  double* value(int64_t s, Video* latent) const {
    const Segment& segment = segments_[s];
    if (segment.constant) return const_cast<double*>(&segment.held);
    return latent->frame_data(segment.first) + segment.pixel;
  }

  /// Sets every variable segment's value to the mean of `latent` over the segment, so that the
  /// initialisation is a point of the merged parameter space.
  void ProjectOnto(Video* latent) const;
  /// Copies each variable segment's value to every voxel of the segment (after a solve); a ring
  /// pixel's voxels keep their own values.
  void Expand(Video* latent) const;

 private:
  int num_latent_frames_ = 0;
  int64_t pixels_per_frame_ = 0;
  std::vector<Segment> segments_;
  int64_t num_variable_segments_ = 0;
  std::vector<int32_t> segment_of_voxel_;  // t-major: [t * pixels + p]
};

}  // namespace evfs

#endif  // EVFS_SOLVER_LATENT_LAYOUT_H_

// Which pixels a scene needs to solve for (docs/design.md §3, "skipping what a scene does not
// need").
#ifndef EVFS_SCENE_ACTIVITY_MASK_H_
#define EVFS_SCENE_ACTIVITY_MASK_H_

#include <cstdint>
#include <vector>

#include "evfs/core/event_frames.h"

namespace evfs {

/// Per-pixel role in the problem:
///  * active — an event fired within `radius_px` (Chebyshev distance) somewhere in the window:
///    the pixel's whole time series is unknown;
///  * ring — not active but next to an active pixel: its values enter the spatial TV of its
///    active neighbours, held constant at the initialisation;
///  * inactive — neither: no parameter blocks, no residuals; it keeps its initial value (the
///    observed frame, or the blend of the observed frames).
class ActivityMask {
 public:
  enum class Role : uint8_t { kInactive, kRing, kActive };

  /// Every pixel active (radius_px < 0), or those within radius_px of an event.
  ActivityMask(const EventFrames& events, int radius_px);

  Role role(int64_t pixel) const { return roles_[pixel]; }
  bool active(int64_t pixel) const { return roles_[pixel] == Role::kActive; }
  /// Active or ring: the pixel has parameter blocks.
  bool in_problem(int64_t pixel) const { return roles_[pixel] != Role::kInactive; }
  int64_t num_active() const { return num_active_; }
  int64_t num_pixels() const { return static_cast<int64_t>(roles_.size()); }

  /// The pixels in the problem grouped so that no term of the objective couples two groups:
  /// the 8-connected components of the active and ring pixels (a term touches a pixel and its
  /// right, lower or diagonal neighbours, all in the problem, and ring pixels are constant).
  /// Components smaller than `min_part_pixels` are packed together, so that scattered noise
  /// events do not become thousands of tiny solves. Parts by decreasing size, each one's
  /// pixels ascending.
  std::vector<std::vector<int64_t>> IndependentParts(int64_t min_part_pixels) const;

 private:
  int height_ = 0;
  int width_ = 0;
  std::vector<Role> roles_;
  int64_t num_active_ = 0;
};

}  // namespace evfs

#endif  // EVFS_SCENE_ACTIVITY_MASK_H_

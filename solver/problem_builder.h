// Scene + options → ceres::Problem over a latent video (docs/design.md §1, §3).
#ifndef EVFS_SOLVER_PROBLEM_BUILDER_H_
#define EVFS_SOLVER_PROBLEM_BUILDER_H_

#include <ceres/ceres.h>

#include <cstdint>
#include <map>
#include <memory>
#include <unordered_set>
#include <utility>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/latent_layout.h"
#include "evfs/solver/objective_terms.h"
#include "evfs/solver/reconstruction_options.h"

namespace evfs {

/// Residual-block counts of a built problem, per term family.
struct ProblemStatistics {
  int64_t parameter_blocks = 0;           // segments of the latent layout, ring ones included
  int64_t variable_parameter_blocks = 0;  // the unknowns
  int64_t frame_residuals = 0;
  int64_t event_residuals = 0;
  int64_t spatial_tv_residuals = 0;
  int64_t temporal_tv_residuals = 0;
  int64_t log_temporal_tv_pixels = 0;  // pixels whose temporal TV is measured in g (flicker)
  int64_t prior_residuals = 0;         // the quadratic prior (plug & play), one per unknown
  int64_t distinct_cost_functions = 0;
  int64_t active_pixels = 0;    // pixels whose time series is solved for
  int64_t skipped_pixels = 0;   // pixels left at their initial value (ActivityMask)
  int64_t parts = 1;            // problems built: independent parts, or bands of one
  int64_t batches = 1;          // groups of parts built and solved at once (ProblemPlan)
  int64_t estimated_bytes = 0;  // the plan's estimate for every part at once (not summed)
  // ObjectiveTerms::shared_structure_correlation() and has_spatial_tv_offsets() (not summed).
  double shared_structure_correlation = 0.0;
  bool shared_structure_applied = false;

  int64_t residual_blocks() const {
    return frame_residuals + event_residuals + spatial_tv_residuals + temporal_tv_residuals +
           prior_residuals;
  }
  /// Sums the counts of another part of the same scene.
  ProblemStatistics& operator+=(const ProblemStatistics& part);
};

/// A Ceres problem together with the cost and loss functions it refers to. The problem does not
/// own them, so that one cost function (e.g. "event value +1, one step") and one loss per term
/// family serve millions of residual blocks.
class BuiltProblem {
 public:
  ceres::Problem& problem() { return *problem_; }
  const ProblemStatistics& statistics() const { return statistics_; }
  /// Which voxels the parameter blocks stand for (shared by every part of a scene); Expand()
  /// the latent video after a solve.
  const LatentLayout& layout() const { return *layout_; }
  /// The residual blocks that couple one pixel's unknowns only (frame, event, temporal TV and
  /// prior terms): each pixel's temporal chain, which Ceres' SUBSET preconditioner factorises.
  const std::unordered_set<ceres::ResidualBlockId>& temporal_residuals() const {
    return temporal_residuals_;
  }

 private:
  friend class ProblemBuilder;
  std::unordered_set<ceres::ResidualBlockId> temporal_residuals_;
  std::shared_ptr<const LatentLayout> layout_;
  std::vector<std::unique_ptr<ceres::CostFunction>> cost_functions_;
  std::vector<std::unique_ptr<ceres::LossFunction>> losses_;
  std::unique_ptr<ceres::Problem> problem_;  // declared last: destroyed before the functions
  ProblemStatistics statistics_;
};

/// A set of pixels solved as one Ceres problem. A whole part (ActivityMask::IndependentParts)
/// couples to nothing outside it; a band of a part too large for the memory budget solves the
/// part's pixels in rows [row_begin, row_end) and holds the part's pixels in the rows next to it,
/// which its spatial TV terms touch, constant at their current values.
struct ProblemUnit {
  std::vector<int64_t> pixels;  // ascending: the part's, or the band's with the rows around it
  bool band = false;
  int row_begin = 0;
  int row_end = 0;
  /// Memory the unit's problem will hold while it is solved (ProblemBuilder::Plan).
  int64_t estimated_bytes = 0;
};

/// Everything the units of one latent video share (activity mask, segment layout, terms), and
/// the units grouped into batches: the units of a batch are disjoint and uncoupled, built and
/// solved together; batches one after another, each within the memory budget.
class ProblemPlan {
 public:
  const LatentLayout& layout() const { return *layout_; }
  const std::vector<std::vector<ProblemUnit>>& batches() const { return batches_; }
  /// The estimate for every unit at once (what one batch would hold without a budget).
  int64_t estimated_bytes() const { return estimated_bytes_; }
  /// Pixels whose time series are solved for.
  int64_t active_pixels() const { return mask_->num_active(); }

 private:
  friend class ProblemBuilder;
  std::shared_ptr<const ActivityMask> mask_;
  std::shared_ptr<const LatentLayout> layout_;
  std::shared_ptr<const ObjectiveTerms> terms_;
  std::vector<std::vector<ProblemUnit>> batches_;
  int64_t estimated_bytes_ = 0;
};

/// Parameter layout: one scalar parameter block per segment of the LatentLayout (per voxel
/// H_t(p) when quiet steps are not merged), pointing into the latent Video, and one scalar
/// residual block per term. A prototype on this machine compared it with
/// one block per pixel time series (vector residuals): that builds faster but has 15× more
/// Jacobian non-zeros and needs ~12× more LM iterations, because folding the robust loss into
/// the residual loses Ceres' curvature correction (../shared/notes/solver-measurements.md).
class ProblemBuilder {
 public:
  ProblemBuilder(const Scene& scene, const ReconstructionOptions& options);

  /// Builds the problem over `latent` (scene.num_latent_frames() frames of the scene's size,
  /// holding the initialisation), which must outlive the returned problem. Each segment of the
  /// layout starts at the mean of its voxels. Terms with zero weight are not built. After a
  /// solve, built->layout().Expand(latent) writes the solution to every voxel.
  std::unique_ptr<BuiltProblem> Build(Video* latent) const;

  /// The same objective as independent problems, one per ActivityMask::IndependentParts(
  /// options.min_part_pixels), sharing one layout and writing disjoint voxels of `latent`: they
  /// may be solved concurrently, and their costs add up to Build()'s. Parts by decreasing size;
  /// `build_workers` threads build them.
  std::vector<std::unique_ptr<BuiltProblem>> BuildParts(Video* latent, int build_workers) const;

  /// Plans a solve whose problems hold at most `max_bytes` at once (estimated from the layout's
  /// segment counts before anything is built; < 0: no limit). The units are the independent
  /// parts when options.split_independent_parts holds, else one; when they all fit, the plan
  /// is one batch of them (BuildParts()), otherwise parts are packed into batches that fit and a
  /// part that does not fit alone is cut into overlapping bands of rows, one batch each. Each
  /// segment of the layout starts at the mean of its voxels in `latent`, which must outlive
  /// the plan and the problems built from it.
  ProblemPlan Plan(Video* latent, int64_t max_bytes) const;
  /// The problem of one unit of `plan` over `latent` (the video Plan() was given).
  std::unique_ptr<BuiltProblem> BuildUnit(const ProblemPlan& plan, const ProblemUnit& unit,
                                          Video* latent) const;

 private:
  ProblemPlan Prepare(Video* latent) const;
  // The bytes a problem holding pixel p's segments and terms needs (Plan()).
  int64_t EstimatedBytes(const ProblemPlan& prepared, int64_t p) const;
  // Cuts `part` into overlapping bands of rows of at most `max_bytes` each.
  std::vector<ProblemUnit> Bands(const ProblemPlan& prepared, const std::vector<int64_t>& part,
                                 int64_t max_bytes) const;

  const Scene& scene_;
  const ReconstructionOptions& options_;
};

}  // namespace evfs

#endif  // EVFS_SOLVER_PROBLEM_BUILDER_H_

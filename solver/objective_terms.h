// Which terms the objective of docs/design.md §1 has for a scene, and their weights: the one
// definition that ProblemBuilder (Ceres residual blocks) and FusedObjective (Adam, L-BFGS) both
// follow.
//
//   L(H) = w_f  / (hw)   · Σ_j Σ_p ρ(frame term j at p)             (Eq. 3)
//        + λ_e  / (hw)   · Σ_k Σ_p ρ(event term k at p)             (Eqs. 1–2)
//        + λ_xy / (hw·N) · Σ_t Σ_p ρ(spatial TV term at (t, p))     (Eq. 4)
//        + λ_t  / (hw)   · Σ_t Σ_p ρ(H_{t+1}(p) − H_t(p))           (Eq. 5)
//        + ρ_T  / (hw·N) · Σ_t Σ_p ½ (H_t(p) − T_t(p))²            (prior, plug & play)
//
// Rules:
// * A family with weight 0 has no terms; the temporal family has none with one latent frame.
// * Frame, event and temporal terms are summed over the active pixels (ActivityMask) only.
// * A spatial TV term exists when any pixel it touches is active; it belongs to its top-left
//   pixel. Anisotropic TV is two terms per pixel, (p, right) and (p, below); the paper and
//   isotropic forms one three-point term (p, right, below).
// * A pixel whose events reverse sign at least log_temporal_tv_reversals times (log model) has
//   its temporal terms measured in g, (0.5 + b)·(g(H_{t+1}) − g(H_t))
//   (TransformedDifferenceResidual), not H.
// * The prior is the one quadratic family: ADMM's coupling term ρ/2‖H − T‖² towards a target
//   video T (plug & play, paper §3.4), over the active voxels. Only the Ceres problem builds
//   it; the fused objective rejects it.
// * Every family is normalised by the image size h·w, so that the weights do not depend on the
//   resolution; spatial TV also by the N latent frames (a mean over frames: summed, smoothing a
//   run of m frames would save m times the TV while paying for only two temporal transitions, so
//   finer binning would blur more).
#ifndef EVFS_SOLVER_OBJECTIVE_TERMS_H_
#define EVFS_SOLVER_OBJECTIVE_TERMS_H_

#include <array>
#include <cstdint>
#include <vector>

#include "evfs/scene/activity_mask.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/reconstruction_options.h"

namespace evfs {

/// The residual families of the objective.
enum class TermFamily { kFrame, kEvent, kSpatialTv, kTemporalTv, kPrior };
constexpr int kNumTermFamilies = 5;

/// The spatial TV terms a pixel owns (as their top-left pixel).
struct SpatialTvTermsAt {
  /// Anisotropic: the term (p, p + 1). Paper and isotropic forms: the term (p, p + 1, p + w).
  bool right = false;
  /// Anisotropic only: the term (p, p + w).
  bool below = false;
};

/// What a pixel's spatial TV differences are measured from (ObjectiveOptions::
/// shared_structure_tv): r = dx H − right, dy H − below. Both 0 for plain TV.
struct SpatialTvOffset {
  double right = 0.0;  // of the difference towards (x + 1, y)
  double below = 0.0;  // of the difference towards (x, y + 1)
};

/// The resolution of the spatial TV offsets: 1/1024 of the intensity range, a quarter of an
/// 8-bit level and far below the smoothing scale, so that there are at most 2049 offsets.
inline constexpr double kSpatialTvOffsetStep = 1.0 / 1024.0;

/// The terms of the objective for one scene, activity mask and objective options. Counts are of
/// terms over voxels (one per latent frame or step, before any merging of quiet steps).
class ObjectiveTerms {
 public:
  /// `mask` must match the scene's size and outlive this object. Throws InvalidArgumentError
  /// when the objective has a prior whose target is not of the scene's latent size.
  ObjectiveTerms(const Scene& scene, const ObjectiveOptions& objective, const ActivityMask& mask);

  /// Whether the family has terms: weight > 0 (and, for temporal TV, more than one latent frame).
  bool has(TermFamily family) const { return weight(family) > 0.0; }
  /// The weight of each of the family's terms, normalisation included; 0 when it has none.
  double weight(TermFamily family) const { return weights_[static_cast<int>(family)]; }
  /// Number of the family's terms (0 when it has none).
  int64_t num_terms(TermFamily family) const { return counts_[static_cast<int>(family)]; }

  /// The spatial TV terms pixel p owns; none when the family has no terms.
  SpatialTvTermsAt spatial_tv_terms_at(int64_t p) const;
  /// Whether spatial TV is measured from the structure the scene's first and last sharp frames
  /// share: shared_structure_tv with spatial TV terms, two sharp frames at different times, and
  /// a positive shared_structure_correlation().
  bool has_spatial_tv_offsets() const { return !tv_offset_right_.empty(); }
  /// With shared_structure_tv and two sharp frames: the correlation of the two frames' forward
  /// differences over the image, Σ ∂F_first·∂F_last / sqrt(Σ ∂F_first² · Σ ∂F_last²) over both
  /// axes. Where it is not positive the frames show nothing in place that chance would not (a
  /// scene that moved more than its texture's scale) and TV stays plain. Else 0.
  double shared_structure_correlation() const { return shared_structure_correlation_; }
  /// The offsets of pixel p's spatial TV differences: minmod(F_first(q) − F_first(p),
  /// F_last(q) − F_last(p)) for q its right and lower neighbours, rounded to
  /// kSpatialTvOffsetStep (0 without a neighbour), or 0 when !has_spatial_tv_offsets().
  SpatialTvOffset spatial_tv_offset_at(int64_t p) const {
    if (!has_spatial_tv_offsets()) return {};
    return {tv_offset_right_[p], tv_offset_below_[p]};
  }

  /// Per pixel, 1 where its temporal terms are measured in g (ObjectiveOptions::
  /// log_temporal_tv_reversals: the log model, temporal terms, and at least that many
  /// PolarityReversals); empty when no pixel's are.
  const std::vector<uint8_t>& temporal_tv_in_g() const { return temporal_tv_in_g_; }
  bool temporal_tv_in_g_at(int64_t p) const {
    return !temporal_tv_in_g_.empty() && temporal_tv_in_g_[p] != 0;
  }

 private:
  void ComputeSharedStructureOffsets(const Scene& scene);

  const ActivityMask& mask_;
  int height_ = 0, width_ = 0;
  SpatialTv spatial_tv_ = SpatialTv::kAnisotropic;
  std::array<double, kNumTermFamilies> weights_{};
  std::array<int64_t, kNumTermFamilies> counts_{};
  std::vector<double> tv_offset_right_, tv_offset_below_;  // per pixel; empty: plain TV
  std::vector<uint8_t> temporal_tv_in_g_;                  // per pixel; empty: none
  double shared_structure_correlation_ = 0.0;
};

}  // namespace evfs

#endif  // EVFS_SOLVER_OBJECTIVE_TERMS_H_

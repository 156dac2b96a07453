// The objective of docs/design.md §1 and its gradient in one fused, multi-threaded pass over a
// latent video: the reference evaluation for first-order solvers (Adam, L-BFGS), on exactly the
// terms ProblemBuilder builds as Ceres residual blocks.
//
//   L(H) = w_f  / (hw)   · Σ_j Σ_p ρ(F_j(p) − mean(H_{a_j}(p) … H_{b_j}(p)))        (Eq. 3)
//        + λ_e  / (hw)   · Σ_k Σ_p ρ(E_k(p) − Σ_{s=a_k}^{b_k−1} c tanh(α Δg_s / c))  (Eqs. 1–2)
//        + λ_xy / (hw·N) · Σ_t Σ_p ρ(TVxy(H_t)(p))                                   (Eq. 4)
//        + λ_t  / (hw)   · Σ_t Σ_p ρ(H_{t+1}(p) − H_t(p))                            (Eq. 5)
//
// with Δg_s = g(H_{s+1}(p)) − g(H_s(p)), c = SaturationForCount(E_k(p), b_k − a_k)
// (event_model.h), N latent frames, and ρ either the smoothed ℓ1 sqrt(ε² + r²) − ε that the
// Ceres problem minimises (CreateWeightedL1Loss) or the paper's true ℓ1 |r|. For isotropic TV, r is
// the forward-difference gradient (∂x H, ∂y H) and ρ applies to its norm. Which terms exist and
// their weights are ObjectiveTerms', which ProblemBuilder follows too. Only active voxels are
// unknowns (ActivityMask): the gradient of ring and inactive voxels is 0.
#ifndef EVFS_SOLVER_FUSED_OBJECTIVE_H_
#define EVFS_SOLVER_FUSED_OBJECTIVE_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/reconstruction_options.h"

namespace evfs {

/// How the ℓ1 penalty ρ of every term is evaluated.
enum class L1Penalty {
  kSmoothed,  ///< ρ(r) = sqrt(ε² + r²) − ε: the Ceres problem's cost (CreateWeightedL1Loss)
  kTrueL1,    ///< ρ(r) = |r| with the subgradient sign(r) (0 at r = 0): the paper's objective
};

/// Names used by flags and summaries: "smoothed", "true_l1".
const char* L1PenaltyName(L1Penalty penalty);

struct FusedObjectiveOptions {
  /// The penalty ρ applied to every residual.
  L1Penalty penalty = L1Penalty::kSmoothed;
  /// Threads of one evaluation (OpenMP); the rows of the video are split among them.
  int num_threads = 2;

  bool IsValid(std::string* error) const;
};

/// A run of consecutive active pixels in one row of the image.
struct PixelRun {
  int64_t begin = 0;   ///< first pixel (flat index y·w + x)
  int64_t end = 0;     ///< one past the last pixel, in the same row
  int64_t offset = 0;  ///< number of active pixels before `begin` in raster order
};

/// Evaluates L(H) and ∂L/∂H over a latent video laid out as Video stores it (frame after frame,
/// each row-major). Everything that does not depend on H (pixel runs, term masks, row bands) is
/// precomputed by the constructor; an evaluation reads H once and writes the gradient once.
/// Evaluations must not run concurrently on one object (they reuse its buffers).
class FusedObjective {
 public:
  /// `scene` must outlive this object. Throws InvalidArgumentError when `objective` or `options`
  /// is invalid, when α is not > 0 (derive it first, with EstimateEventModel, as Reconstruct
  /// does), or when `mask` does not match the scene's size.
  FusedObjective(const Scene& scene, const ObjectiveOptions& objective, const ActivityMask& mask,
                 const FusedObjectiveOptions& options = FusedObjectiveOptions());
  ~FusedObjective();
  FusedObjective(const FusedObjective&) = delete;
  FusedObjective& operator=(const FusedObjective&) = delete;

  /// Returns L(latent). When `gradient` is not null it receives ∂L/∂H for every voxel (0 for
  /// ring and inactive voxels). Both hold num_voxels() values; every voxel of `latent` must be
  /// finite (ring and inactive voxels enter as constants).
  double Evaluate(const double* latent, double* gradient) const;
  /// The same on videos of the scene's size; `gradient` (may be null) is resized when needed.
  /// Throws InvalidArgumentError when `latent` has another size.
  double Evaluate(const Video& latent, Video* gradient) const;

  /// Receives the gradient of one run of active voxels in latent frame t: `gradient`,
  /// `current` and `next` point at the run's first voxel (run.end − run.begin values each).
  using StepFunction = std::function<void(int t, const PixelRun& run, const double* gradient,
                                          const double* current, double* next)>;
  /// One evaluation fused with a first-order step: returns L(latent) and hands each run's
  /// gradient to `step` while it is still in cache, for `step` to write the next iterate's values
  /// of the run into `next` (num_voxels() values; the voxels of pixels that are not active are
  /// not touched). `latent` is only read, so every call sees the gradient at `latent`. `step` is
  /// called concurrently from several threads, for disjoint runs, each (t, run) once.
  double EvaluateAndStep(const double* latent, double* next, const StepFunction& step) const;

  int height() const;
  int width() const;
  int num_latent_frames() const;
  int64_t pixels_per_frame() const;
  /// Voxels of a full latent video: num_latent_frames() · pixels_per_frame().
  int64_t num_voxels() const;
  int64_t num_active_pixels() const;
  /// Unknowns: num_active_pixels() · num_latent_frames().
  int64_t num_active_voxels() const;
  /// Active pixels as runs along rows, in raster order.
  const std::vector<PixelRun>& active_runs() const;
  const FusedObjectiveOptions& options() const;

  /// Copies the active voxels of a full video (num_voxels() values) into `active`
  /// (num_active_voxels() values: frame after frame, active pixels in raster order). With every
  /// pixel active both layouts coincide.
  void GatherActive(const double* full, double* active) const;
  /// The inverse of GatherActive: writes the active voxels of `full`, leaves the others.
  void ScatterActive(const double* active, double* full) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace evfs

#endif  // EVFS_SOLVER_FUSED_OBJECTIVE_H_

// Everything that shapes a reconstruction: the objective (docs/design.md §1), its initialisation
// and the Ceres solver settings.
#ifndef EVFS_SOLVER_RECONSTRUCTION_OPTIONS_H_
#define EVFS_SOLVER_RECONSTRUCTION_OPTIONS_H_

#include <ceres/ceres.h>

#include <memory>
#include <string>
#include <vector>

#include "evfs/core/enum_names.h"
#include "evfs/core/stop_condition.h"
#include "evfs/core/video.h"
#include "evfs/cost_functions/spatial_tv_residual.h"
#include "evfs/scene/event_model.h"
#include "evfs/scene/event_model_estimation.h"

namespace evfs {

/// The objective's weights and model. Every term is a smoothed ℓ1 penalty summed over its
/// residuals and divided by the number of pixels h·w, and the spatial TV also by the number of
/// latent frames. So the weights depend neither on the resolution nor on how finely binning
/// slices the window: the event and temporal terms sum over time (the number of events and the
/// path length of a pixel's intensity do not grow with K), the spatial TV is a mean over frames
/// (summed, it would blur more the more latent frames there are).
struct ObjectiveOptions {
  /// Largest event_model.alpha accepted. α is 1 / C for a contrast threshold C in log
  /// intensity; 1e6 is a threshold thousands of times finer than any sensor's (0.1 to 0.5),
  /// and far larger values overflow the event residuals and their derivatives.
  static constexpr double kMaxAlpha = 1e6;

  /// Weight of the frame term (paper Eq. 3), per frame observation. Smaller weights let the
  /// events pull the frames away from what was observed (sweep: BENCHMARKS.md, "Where the
  /// defaults come from").
  double frame_weight = 4.0;
  /// λ_e: weight of the event term (paper Eq. 2), per event frame. With λ_t, below, weak
  /// enough that the frames and the spatial TV hold what the events do not say, strong enough
  /// for prediction (sweep: BENCHMARKS.md, "Where the defaults come from").
  double event_weight = 0.3;
  /// λ_xy: weight of spatial total variation (paper Eq. 4), mean over latent frames.
  double spatial_tv_weight = 2.0;
  /// λ_t: weight of temporal total variation (paper Eq. 5), per latent step.
  double temporal_tv_weight = 0.85;
  /// Pixels whose events reverse polarity at least this many times in the window (a mains lamp,
  /// a blinking LED: ON and OFF events by turns) get their temporal TV measured in g, the event
  /// model's domain (TransformedDifferenceResidual), instead of |ΔH|. With the log model |ΔH|
  /// charges each brightening step more than the darkening step that undoes it, so such a pixel
  /// drifts dark a little every cycle: predicting 33 ms under a 100 Hz lamp it ended black
  /// (BENCHMARKS.md, "Flickering light"). A reversal is a change of sign between two event
  /// frames that fired, so a moving edge or texture rarely makes three: the real windows of the
  /// shared data have a handful of such pixels, and their figures barely move. 0: every
  /// pixel's temporal TV is |ΔH|. The Ceres problem and the fused objective build it alike; the
  /// linear model is unaffected.
  int log_temporal_tv_reversals = 3;
  /// g and α of the event model: by default the log model g(x) = log(x + 0.5), which matches
  /// the log-intensity events of a sensor, with α derived from the data (α <= 0,
  /// EstimateEventModel); b = 0.5 keeps DAVIS frames, whose response is nearly linear, well
  /// fitted (sweep: BENCHMARKS.md).
  EventModelParams event_model = DefaultEventModel();
  /// Form of the spatial TV.
  SpatialTv spatial_tv = SpatialTv::kAnisotropic;
  /// Between two sharp frames, measure each spatial TV difference from the structure both
  /// frames show in place: dx H − minmod(dx F_first, dx F_last), the same for dy, with minmod
  /// the smaller of the two where they have the same sign and 0 where not (ObjectiveTerms). A
  /// texture both frames show costs nothing to keep; an edge only one frame shows there is still
  /// penalised. Scenes without two sharp frames, or whose two frames' differences do not
  /// correlate positively (ObjectiveTerms::shared_structure_correlation), keep plain TV. On by
  /// default: with the step ramps it lifts every quiet window above the blend and event
  /// integration, and no measured window gets worse (benchmarks/results/model_choices.md,
  /// "Spatial TV of what the frames do not share").
  bool shared_structure_tv = true;
  /// ε of the pseudo-Huber smoothing of |r|: sqrt(ε² + r²) − ε.
  double smoothing_scale = 0.05;
  /// ρ: weight of a quadratic prior ρ/2 · mean over the solved voxels of (H_t(p) − T_t(p))²
  /// that pulls the latent video towards `prior_target` (plug & play's ADMM coupling term,
  /// paper §3.4 and Table 4); 0: no prior. Only the Ceres problem builds it.
  double prior_weight = 0.0;
  /// T: the prior's target, a video of the scene's latent size (needed when prior_weight > 0).
  std::shared_ptr<const Video> prior_target;

  bool IsValid(std::string* error) const;

 private:
  static EventModelParams DefaultEventModel() {
    EventModelParams params;
    params.model = EventModel::kLog;
    params.log_offset = 0.5;
    params.alpha = 0.0;
    params.saturation = 0.0;
    return params;
  }
};

struct ReconstructionOptions {
  ObjectiveOptions objective;
  /// How α is derived when objective.event_model.alpha <= 0.
  EventModelEstimationOptions estimation;

  /// Keep every intensity in [0, 1] (Ceres parameter bounds).
  bool bound_intensities = true;

  /// Pixels farther than this (Chebyshev distance, pixels) from every event of the window keep
  /// their initial value and get no parameter blocks or residuals; < 0 solves every pixel.
  int activity_radius_px = 2;

  /// Hold each active pixel constant between the latent steps where it fired, so that the
  /// unknowns are its segments rather than its voxels (LatentLayout; the minimiser barely
  /// changes and the problem is several times smaller). False: one unknown per voxel.
  bool merge_quiet_steps = true;

  /// With merged quiet steps, an active pixel that never fires but whose neighbours do after
  /// the last frame gets one change, at the median of their events (LatentLayout), instead of
  /// staying one constant that nothing after the last frame pins. Measured: BENCHMARKS.md,
  /// "Unfired pixels after the last frame".
  bool unfired_pixel_changes = true;

  /// With merged quiet steps, a ring pixel (held constant next to the solved ones) starts a new
  /// constant only where its initial value has moved more than this (intensity, [0, 1]) since
  /// the current one began; the problem sees each constant's mean, the output keeps the ring's
  /// own values (LatentLayout). One 8-bit grey level, what the frames resolve. 0: a new constant
  /// at every change, which for a blended initialisation is every latent frame and multiplies
  /// the spatial TV terms next to the ring by the latent frames. Ceres' problem only: the fused
  /// objective of the first-order solvers sees every ring voxel.
  double ring_tolerance = 1.0 / 255.0;

  /// Solve separately, on solver.num_threads threads, the parts of the scene that no term
  /// couples (ActivityMask::IndependentParts): each stops at its own convergence and the
  /// threads share the work. With an iteration callback the parts are solved one after another
  /// (the callback sees the whole latent video). False: one problem.
  bool split_independent_parts = true;
  /// Continuation on the smoothing scale: solve with each of these ε in turn (e.g. {0.2, 0.1}),
  /// each solution starting the next, before the objective's own. Empty (the default): one
  /// solve. The summary reports the last solve's costs and the iterations and times of all.
  std::vector<double> smoothing_continuation;

  /// Independent regions smaller than this (pixels) are packed into one part: each Ceres solve
  /// has a fixed cost (preprocessing, allocation, its summary), which scattered noise events
  /// would otherwise pay thousands of times.
  int64_t min_part_pixels = 1024;

  /// Most memory (MiB) the Ceres problems of a solve hold at once, estimated from the layout
  /// before anything is built (ProblemBuilder::Plan): parts are then built and solved in
  /// batches that fit, and a part too large alone in overlapping bands of rows, one after
  /// another. The recording, scene, latent video and layout come on top (about 560 MB for 2 M
  /// events at 640x480, where the default keeps the whole process under 1 GB; BENCHMARKS.md,
  /// "Memory bounded before allocation"). <= 0: no limit. The first-order solvers (adam,
  /// L-BFGS) build no Ceres problem and ignore it.
  int64_t max_problem_mb = 384;

  /// After the solve, a pixel that no event fired and whose consecutive sharp frames differ by
  /// less than this fraction of one event's change (in the event model's g) takes the
  /// time-weighted blend of the two between them: no event says its change stayed below the
  /// threshold, and the blend meets both frames, where the solve holds such a pixel constant at
  /// a value the ℓ1 frame terms leave undecided. 0: off (the default: at 0.5 it passes more
  /// quiet windows but costs two clips' interpolations; sweep:
  /// benchmarks/results/options_left_off.md, "Quiet pixels: how much change"). Not applied
  /// with a prior
  /// (objective.prior_weight).
  double quiet_blend_fraction = 0.0;
  static constexpr double kMaxQuietBlendFraction = 100.0;

  /// After the solve (merged quiet steps, the Ceres solvers), each step of a solved pixel
  /// becomes a linear ramp that ends at the step and lasts the time the scene takes to move
  /// this many pixels there, as the events measure it, begun no earlier than the middle of the
  /// segment before, so that the sharp frames keep their values (solver/step_ramps.h). A pixel
  /// integrates light over its area, so an edge changes it over the time it takes to cross it,
  /// and a sensor fires when a change is complete; 2 allows a pixel of blur besides the pixel's
  /// width (sweep: benchmarks/results/model_choices.md, "Steps as ramps"). Steps inside a blurred
  /// frame's exposure stay jumps. 0: steps stay jumps. Not applied with a prior
  /// (objective.prior_weight).
  double step_ramp_px = 2.0;
  /// The last stage of a reconstruction, after any denoiser (app/method.h
  /// ApplySharpFrameSeams; Reconstruct() itself leaves the solve's answer): each sharp frame's
  /// latent frame takes the frame's values and the offset fades out linearly in time to
  /// half-way to the neighbouring observation (or the window's end). The solve leaves a frame's
  /// latent frame where the event and TV terms balance, measurably off an exact frame even on a
  /// slow window, and the frames next to it inherit the offset (solver/sharp_frame_seams.h;
  /// benchmarks/results/model_choices.md, "Shared-structure TV and sharp frames met as
  /// defaults").
  bool meet_sharp_frames = true;
  static constexpr double kMaxStepRampPx = 1.0e6;
  static constexpr int64_t kMaxProblemMb = int64_t{1} << 20;

  /// Ceres settings, all of them available to library users; the defaults below are set by
  /// DefaultSolverOptions() (Levenberg–Marquardt, CGNR with a Jacobi preconditioner).
  ceres::Solver::Options solver;

  /// Ends the whole solve early — every continuation stage, batch, band and part together — at a
  /// deadline or an interrupt (core/stop_condition.h); each Ceres solve also keeps its own
  /// solver.max_solver_time_in_seconds. Default: never.
  StopCondition stop;

  ReconstructionOptions();
  bool IsValid(std::string* error) const;
};

/// The Ceres settings evfs uses by default. Per-voxel scalar parameter blocks make the normal
/// equations a 3-D grid Laplacian-like system: sparse Cholesky fills in badly on it (a
/// prototype measured nnz(L) = 1.9e7 for 45k unknowns), so an inexact Newton step with CGNR and
/// a Jacobi preconditioner is used (../shared/notes/solver-measurements.md).
ceres::Solver::Options DefaultSolverOptions();

/// Names used by flags and summaries (kEventModelNames is in scene/event_model.h).
inline constexpr EnumName<SpatialTv> kSpatialTvNames[] = {
    {SpatialTv::kPaper, "paper", "|dx+dy| (paper Eq. 4)"},
    {SpatialTv::kAnisotropic, "anisotropic", "|dx|+|dy|"},
    {SpatialTv::kIsotropic, "isotropic", "sqrt(dx^2+dy^2)"},
};

/// "paper", "anisotropic", "isotropic".
const char* SpatialTvName(SpatialTv form);
/// Parses a name of SpatialTvName; false when unknown.
bool ParseSpatialTv(const std::string& name, SpatialTv* form);
/// "linear", "log".
const char* EventModelName(EventModel model);
/// Parses a name of EventModelName; false when unknown.
bool ParseEventModel(const std::string& name, EventModel* model);

}  // namespace evfs

#endif  // EVFS_SOLVER_RECONSTRUCTION_OPTIONS_H_

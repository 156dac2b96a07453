// Every reconstruction method of evfs behind one call, so that the command line, the demo and the
// benchmarks run any of them on the same Scene and report them the same way:
//
//   ceres_lm     the default: Levenberg–Marquardt on the Ceres residual-block problem
//   ceres_lbfgs  Ceres' L-BFGS on the fused evaluation of the same (smoothed) objective
//   adam         the paper's optimiser and schedule on the paper's true-ℓ1 objective
//   adam_smooth  the same schedule on the smoothed objective Ceres minimises
//   blend, copy, integrate, cf, edi   the classical baselines of baselines/
#ifndef EVFS_APP_METHOD_H_
#define EVFS_APP_METHOD_H_

#include <atomic>
#include <string>
#include <vector>

#include "evfs/app/initialization.h"
#include "evfs/baselines/baseline.h"
#include "evfs/baselines/baseline_options.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/video.h"
#include "evfs/io/data_source.h"
#include "evfs/scene/confidence.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/first_order_solvers.h"
#include "evfs/solver/iteration_callback.h"
#include "evfs/solver/reconstruction_options.h"
#include "evfs/solver/reconstructor.h"
#include "evfs/solver/sharp_frame_seams.h"

namespace evfs {

enum class Method {
  kCeresLm,
  kCeresLbfgs,
  kAdam,
  kAdamSmooth,
  kBlend,
  kCopy,
  kIntegrate,
  kComplementaryFilter,
  kEdi,
};

/// The methods' names, in the order above.
inline constexpr EnumName<Method> kMethodNames[] = {
    {Method::kCeresLm, "ceres_lm", "Levenberg-Marquardt on the Ceres residual-block problem"},
    {Method::kCeresLbfgs, "ceres_lbfgs", "Ceres' L-BFGS on the fused smoothed objective"},
    {Method::kAdam, "adam", "the paper's Adam schedule on the true-l1 objective"},
    {Method::kAdamSmooth, "adam_smooth", "the same schedule on the smoothed objective"},
    {Method::kBlend, "blend", "baseline: the frames blended linearly in time"},
    {Method::kCopy, "copy", "baseline: the one frame copied"},
    {Method::kIntegrate, "integrate", "baseline: events integrated from a sharp frame"},
    {Method::kComplementaryFilter, "cf", "baseline: complementary filter"},
    {Method::kEdi, "edi", "baseline: Event-based Double Integral"},
};

/// "ceres_lm", "ceres_lbfgs", "adam", "adam_smooth", "blend", "copy", "integrate", "cf", "edi".
const char* MethodName(Method method);
/// The inverse of MethodName; throws InvalidArgumentError for another name, listing them.
Method ParseMethod(const std::string& name);
/// Every method, in the order above.
std::vector<Method> AllMethods();
/// True for the solvers of the objective (the first four), false for the classical baselines.
bool IsIterative(Method method);
/// True when `method` can reconstruct `scene` (baselines support only some cases); otherwise
/// false with the reason in `why_not` (may be null).
bool MethodSupports(Method method, const Scene& scene, std::string* why_not);
/// Throws InvalidArgumentError "--solver=NAME cannot reconstruct `what`: why" when `method`
/// cannot reconstruct `scene` (MethodSupports).
void CheckMethodSupports(Method method, const Scene& scene, const std::string& what);

struct MethodOptions {
  Method method = Method::kCeresLm;
  /// The objective, α's derivation, skipping and the Ceres LM settings (all iterative methods
  /// read the objective, the skipping and the bounds from here).
  ReconstructionOptions reconstruction;
  AdamOptions adam;
  LbfgsOptions lbfgs;
  /// The classical methods' parameters; also those of the events initialisation.
  BaselineOptions baseline;
  /// Where the iterative methods start.
  Initialization initialization = Initialization::kBlend;
  /// Raised by another thread to end the solve early (Python's Ctrl-C); may be null. It must
  /// outlive the solve.
  const std::atomic<bool>* interrupt = nullptr;
};

/// Most bytes the resampled frames of one output (or one video window) and their confidence maps
/// may take in memory (16 bytes a pixel) before they are written.
inline constexpr double kMaxResampledOutputBytes = 512.0 * (1 << 20);

/// Throws InvalidArgumentError, naming --fps and the largest rate that fits, when resampling
/// `span_s` seconds (`what`: "window", "longest window") of a width x height sensor at `fps`
/// would hold more than kMaxResampledOutputBytes.
void CheckResampledOutputFits(double fps, double span_s, int width, int height,
                              const std::string& what);

/// A text recording (events.txt) is parsed whole once, as `evfs info` parses it, so that every
/// command accepts and refuses the same files, whichever window it reads; the binary formats
/// (HDF5, AEDAT) check their structure when they open and each part as it is read. Throws the
/// reader's InputError.
void CheckWholeTextRecording(const DataSource& source);

/// Starts the clock of one command's (or one video window's) solve: sets
/// options->reconstruction.stop to end every solve stage that follows — the method, plug & play
/// — reconstruction.solver.max_solver_time_in_seconds (--max_time_s) from now, or when
/// options->interrupt is raised.
void StartSolveClock(MethodOptions* options);

/// One point of an iterative solve: cost, and quality when a truth frame was given.
struct Checkpoint {
  int iteration = 0;
  double time_s = 0.0;  // solve time so far, without the time taken by the checkpoints
  double cost = 0.0;
  double psnr = 0.0;  // 0 without a truth frame
  double ssim = 0.0;
};

/// A frame to score checkpoints against: `image` at latent frame `latent_index`.
struct CheckpointTruth {
  const Image* image = nullptr;
  int latent_index = -1;
};

struct MethodResult {
  Video video;  // on the scene's latent timeline
  std::string method;
  std::string initialization;  // iterative methods: what they started from
  bool solved = false;         // an iterative solve ran
  std::string message;         // why it stopped, or why it did not run
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  double build_time_s = 0.0;  // problem construction / objective set-up
  double solve_time_s = 0.0;  // the solve (or the baseline), without checkpoints and callback
  /// The Ceres LM summary (ceres_lm), or the α and skipping statistics of any iterative method.
  ReconstructionSummary reconstruction;
  /// Named numeric parameters the method used (baselines: thresholds; Adam: schedule …).
  std::vector<BaselineParameter> parameters;
  std::string threshold_source;  // baselines: how the contrast threshold was chosen
  std::vector<Checkpoint> checkpoints;
  /// What ApplySharpFrameSeams() did (nothing before it runs).
  SharpFrameSeams seams;
};

/// The confidence model's options for a method's run (scene/confidence.h): the event model's
/// change per event and log offset where the run derived them (the log model), else
/// ConfidenceOptions' defaults.
ConfidenceOptions ConfidenceFor(const MethodOptions& method, const MethodResult& run);

/// Runs `options.method` on `scene`. `progress` (may be empty) sees every iteration of an
/// iterative method. With `truth` (may be null) and `record_checkpoints`, every iteration's
/// cost, PSNR and SSIM are recorded. Throws InvalidArgumentError for invalid options or a scene
/// the method does not support.
MethodResult RunMethod(const Scene& scene, const MethodOptions& options,
                       const IterationCallback& progress = nullptr, bool record_checkpoints = false,
                       const CheckpointTruth* truth = nullptr);

/// The last stage of a reconstruction, after the solve and any denoiser (which keeps the
/// frames as the solve left them, KeepFramesConsistent): with
/// options.reconstruction.meet_sharp_frames and an iterative method that solved, every sharp
/// frame's latent frame takes the frame's values and its offset fades out around it
/// (MeetSharpFrames, solver/sharp_frame_seams.h); result->seams records it.
void ApplySharpFrameSeams(const Scene& scene, const MethodOptions& options, MethodResult* result);

}  // namespace evfs

#endif  // EVFS_APP_METHOD_H_

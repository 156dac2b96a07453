// The parameters of every classical baseline (docs/design.md §5), in one struct so that a command
// line can fill it from flags and a summary can print it. Each field says which methods read it.
#ifndef EVFS_BASELINES_BASELINE_OPTIONS_H_
#define EVFS_BASELINES_BASELINE_OPTIONS_H_

#include <string>

#include "evfs/scene/event_model_estimation.h"

namespace evfs {

/// The intensity domain events are integrated in.
enum class IntegrationDomain {
  kLog,     ///< g(I) = log(I + b): the sensor's own contrast (paper Eq. 1)
  kLinear,  ///< g(I) = I: the paper's linear model (its Eq. 2)
};

/// Which sharp frames direct event integration starts from.
enum class IntegrationDirection {
  /// Between two sharp frames: the forward and backward estimates blended with weights linear
  /// in time; outside them, the one estimate there is.
  kBoth,
  kForward,   ///< from the nearest sharp frame at or before each latent frame (else the first)
  kBackward,  ///< from the nearest sharp frame at or after each latent frame (else the last)
};

struct BaselineOptions {
  // --- The contrast threshold (integrate, cf, edi) ---

  /// Change of g one event stands for: of log(I + b) in the log domain (of log I for edi), of I
  /// in the linear domain. <= 0 derives it: integrate and cf measure it between two sharp frames
  /// as the solver does (EstimateEventModel) or assume `estimation`'s value, edi minimises its
  /// sharpness energy over [threshold_search_min, threshold_search_max].
  double contrast_threshold = 0.0;
  /// How integrate and cf derive the threshold when contrast_threshold <= 0.
  EventModelEstimationOptions estimation;
  /// Range searched for the threshold by edi's sharpness criterion and by
  /// TuneContrastThresholdOnTruth, 0 < min < max.
  double threshold_search_min = 0.01;
  double threshold_search_max = 1.0;

  // --- integrate ---

  /// Linear: on the DAVIS snippets it matches or beats the best log offset (one prediction
  /// within noise, the other two windows above; benchmarks/results/model_choices.md, "The
  /// baselines' settings"); it is also the solver's default model.
  IntegrationDomain domain = IntegrationDomain::kLinear;
  /// b of log(I + b) for integrate (log domain) and cf, > 0. 0.3: with the assumed threshold cf
  /// predicts best there on the same snippets, both smaller and larger offsets lose (same
  /// section).
  double log_offset = 0.3;
  IntegrationDirection direction = IntegrationDirection::kBoth;
  /// σ in pixels of a Gaussian blur (cv::GaussianBlur) of each integrated frame; 0 = none.
  /// Not part of the integration but a denoiser after it, which beats plain integration on the
  /// DAVIS snippets at σ = 1; blurring only the event term, leaving the frame sharp, does worse
  /// on slider (same section).
  double blur_sigma_px = 0.0;

  // --- cf (Complementary Filter) ---

  /// Crossover frequency α in rad/s: how fast the estimate is pulled towards the latest frame.
  /// 0 is pure event integration, +infinity the frame itself. The paper's value.
  double cutoff_rad_per_s = 6.283185307179586;

  // --- edi (Event-based Double Integral) ---

  /// Weight of the total-variation term against the edge term of the sharpness energy, >= 0.
  /// Chosen on simulated blur with ground truth (the synthetic scene of the tests and three
  /// clips of ../shared/data, same section): smaller weights gain a little on the busy clips and
  /// lose more on the synthetic scene, since they over-sharpen scenes with few moving edges.
  double edi_tv_weight = 0.1;
  /// Events within this fraction of the exposure on either side of the reference time make the
  /// edge map the reconstruction is compared with, in (0, 1].
  double edi_edge_window = 0.1;

  // --- all ---

  /// Clip every output intensity to [0, 1], the range of the frames and of the solver's output.
  bool clamp_to_unit_range = true;

  /// False (with the reason in `error`, which may be null) when a field is out of range.
  bool IsValid(std::string* error) const;
};

/// Throws InvalidArgumentError unless `contrast_threshold` is finite and > 0; `method` names
/// the caller in the message.
void CheckContrastThreshold(double contrast_threshold, const char* method);

/// g(I) of `domain`: log(max(I, 0) + log_offset) or I.
double ToIntegrationDomain(double intensity, IntegrationDomain domain, double log_offset);
/// The inverse of ToIntegrationDomain.
double FromIntegrationDomain(double value, IntegrationDomain domain, double log_offset);

}  // namespace evfs

#endif  // EVFS_BASELINES_BASELINE_OPTIONS_H_

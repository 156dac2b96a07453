// The Event-based Double Integral (EDI) of L. Pan, C. Scheerlinck, X. Yu, R. Hartley, M. Liu,
// Y. Dai, "Bringing a Blurry Frame Alive at High Frame-Rate with an Event Camera", CVPR 2019.
//
// A blurred frame is the mean of the latent frames over its exposure, and events relate every
// latent frame to one reference f: L(t) = L(f) exp(c E(t)), E(t) the signed event count from f
// to t. So B = L(f)/T ∫ exp(c E(t)) dt (the double integral: of events, then over time), and
//   L(t) = B · exp(c E(t)) / mean_{s in exposure} exp(c E(s))
// for any t, inside the exposure or not. On the scene's timeline the mean is over the latent
// frames of the exposure, the frame model of docs/design.md §1, so mean(L_a … L_b) = B exactly.
// E(t) is the cumulative count of the scene's event frames (CumulativeEventCount: events at the
// end of their latent step, stacked counts spread evenly over their steps).
//
// The contrast threshold c is EDI's only parameter. The paper picks it by minimising an energy
// on the sharpness of the reconstruction at the reference time (a total-variation term plus an
// edge term, the cross-correlation between the reconstruction's edges and the
// events near f), searched over one scalar. The exact form was not available to us; what is
// implemented, as we understand it:
//   energy(c) = λ_tv · TV(L_f(c)) / TV(B) − ρ(|∇L_f(c)|, M_f)
// with TV the mean anisotropic total variation, |∇·| the Sobel gradient magnitude, M_f the
// number of events per pixel within edi_edge_window · T of f, ρ Pearson's correlation, f the
// latent frame nearest the exposure's centre and λ_tv = edi_tv_weight. Both terms are taken
// over the pixels where events happened (widened by one pixel), since elsewhere L = B for every
// c. The edge term rewards edges where the events say they are at f; the TV term stops the
// ghost edges and noise of a too large c (a correctly deblurred monotone edge has the TV of its
// blurred version). c is searched over [threshold_search_min, threshold_search_max] with a log
// grid and golden-section refinement (MinimizeOnLogInterval).
#ifndef EVFS_BASELINES_EVENT_DOUBLE_INTEGRAL_H_
#define EVFS_BASELINES_EVENT_DOUBLE_INTEGRAL_H_

#include "evfs/baselines/baseline_options.h"
#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// The terms of EDI's sharpness energy for one threshold.
struct EdiSharpness {
  double energy = 0.0;             // edi_tv_weight · tv_ratio − edge_correlation
  double tv_ratio = 0.0;           // TV(L_f) / TV(B)
  double edge_correlation = 0.0;   // ρ(|∇L_f|, M_f), in [-1, 1]
  int reference_latent_frame = 0;  // f
};

/// The threshold the criterion chose, with its energy.
struct EdiThreshold {
  double contrast_threshold = 0.0;
  EdiSharpness sharpness;
  int evaluations = 0;  // energies computed by the search
};

/// The EDI video of a scene with exactly one frame observation, blurred (latent_first <
/// latent_last), for log contrast threshold `contrast_threshold` (> 0), clipped to [0, 1] when
/// options.clamp_to_unit_range. Throws InvalidArgumentError for another scene or a threshold
/// that is not positive.
Video EventDoubleIntegral(const Scene& scene, const BaselineOptions& options,
                          double contrast_threshold);

/// The sharpness energy of the EDI reconstruction at `contrast_threshold`.
EdiSharpness EdiSharpnessEnergy(const Scene& scene, const BaselineOptions& options,
                                double contrast_threshold);

/// The threshold minimising the sharpness energy over the options' search range.
EdiThreshold ChooseEdiThreshold(const Scene& scene, const BaselineOptions& options);

}  // namespace evfs

#endif  // EVFS_BASELINES_EVENT_DOUBLE_INTEGRAL_H_

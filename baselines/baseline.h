// The classical baselines of docs/design.md §5 behind one interface, so that the command line and
// the benchmarks run them on the same Scene as the solver and compare their Videos frame by frame:
//
//   name       method                                                        cases
//   blend      linear blend in time of the frames (InitializeLatentVideo)     two or more frames
//   copy       the one frame copied to every latent frame                     one frame
//   integrate  direct event integration from sharp frames (+ Gaussian blur)   a sharp frame
//   cf         Complementary Filter (Scheerlinck et al., ACCV 2018)           any frame
//   edi        Event-based Double Integral (Pan et al., CVPR 2019)            one blurred frame
//
// "Integration followed by a blur" is integrate with blur_sigma_px > 0, not a method of its own:
// it is the same integration with one more parameter.
#ifndef EVFS_BASELINES_BASELINE_H_
#define EVFS_BASELINES_BASELINE_H_

#include <string>
#include <vector>

#include "evfs/baselines/baseline_options.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

enum class BaselineMethod {
  kBlend,
  kCopy,
  kIntegrate,
  kComplementaryFilter,
  kEdi,
};

/// One parameter a baseline used, for summaries ("contrast_threshold", 0.183).
struct BaselineParameter {
  std::string name;
  double value = 0.0;
};

struct BaselineResult {
  /// H_0 … H_K on the scene's latent timeline (the timestamps of InitializeLatentVideo).
  Video video;
  /// The numeric parameters the method used, derived ones included, in a fixed order.
  std::vector<BaselineParameter> parameters;
  /// How the contrast threshold was chosen, one line ("given", "measured between the frames
  /// …", "EDI sharpness criterion …", "tuned on the truth frame …"); empty for blend and copy.
  std::string threshold_source;
};

/// The baselines' names, in the order above.
inline constexpr EnumName<BaselineMethod> kBaselineNames[] = {
    {BaselineMethod::kBlend, "blend", "the frames blended linearly in time"},
    {BaselineMethod::kCopy, "copy", "the one frame copied to every latent frame"},
    {BaselineMethod::kIntegrate, "integrate", "events integrated from a sharp frame"},
    {BaselineMethod::kComplementaryFilter, "cf", "complementary filter of frames and events"},
    {BaselineMethod::kEdi, "edi", "Event-based Double Integral of a blurred frame"},
};

/// "blend", "copy", "integrate", "cf", "edi".
const char* BaselineName(BaselineMethod method);
/// The inverse of BaselineName; throws InvalidArgumentError for another name, listing them.
BaselineMethod ParseBaseline(const std::string& name);

/// True when `method` can reconstruct `scene`; otherwise false with the reason in `why_not`
/// (which may be null).
bool BaselineSupports(BaselineMethod method, const Scene& scene, std::string* why_not);

/// Runs `method` on `scene`. Throws InvalidArgumentError for invalid options or a scene the
/// method does not support (BaselineSupports says why).
BaselineResult RunBaseline(BaselineMethod method, const Scene& scene,
                           const BaselineOptions& options);

/// Runs `method` (integrate, cf or edi) with the contrast threshold that maximises the PSNR of
/// latent frame `latent_index` against `truth`, searched over the options' threshold range.
/// An oracle for reports ("cf, threshold tuned on the truth"), never a method: it reads the
/// answer. Throws InvalidArgumentError for a method without a threshold, a truth of another size
/// or an index off the timeline, and as RunBaseline.
BaselineResult TuneContrastThresholdOnTruth(BaselineMethod method, const Scene& scene,
                                            const BaselineOptions& options, const Image& truth,
                                            int latent_index);

}  // namespace evfs

#endif  // EVFS_BASELINES_BASELINE_H_

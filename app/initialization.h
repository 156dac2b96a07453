// Where the solver starts (docs/design.md §1 table): the blend of the frames, or the classical
// event-based estimate of baselines/ for the case (event integration from a sharp frame, the
// Event-based Double Integral for a blurred one).
#ifndef EVFS_APP_INITIALIZATION_H_
#define EVFS_APP_INITIALIZATION_H_

#include <string>

#include "evfs/baselines/baseline_options.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

enum class Initialization {
  kBlend,   ///< the frames blended linearly in time (a copy when there is one)
  kEvents,  ///< integrate when the scene has a sharp frame, else edi, else the blend
};

inline constexpr EnumName<Initialization> kInitializationNames[] = {
    {Initialization::kBlend, "blend", "the frames blended linearly in time"},
    {Initialization::kEvents, "events", "integrate from a sharp frame, else edi, else blend"},
};

/// "blend", "events".
const char* InitializationName(Initialization initialization);
/// The inverse of InitializationName; throws InvalidArgumentError for another name.
Initialization ParseInitialization(const std::string& name);

/// The initial latent video of `scene` (its latent timeline). `method` receives the name of what
/// was used ("blend", "integrate", "edi").
Video InitialLatentVideo(const Scene& scene, Initialization initialization,
                         const BaselineOptions& options, std::string* method);

}  // namespace evfs

#endif  // EVFS_APP_INITIALIZATION_H_

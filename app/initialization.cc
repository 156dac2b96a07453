#include "evfs/app/initialization.h"

#include "evfs/baselines/baseline.h"
#include "evfs/core/error.h"
#include "evfs/scene/scene.h"

namespace evfs {

const char* InitializationName(Initialization initialization) {
  return NameOf(kInitializationNames, initialization);
}

Initialization ParseInitialization(const std::string& name) {
  Initialization initialization = Initialization::kBlend;
  if (!FindName(kInitializationNames, name, &initialization)) {
    throw InvalidArgumentError("unknown initialisation '" + name + "' (" +
                               NameList(kInitializationNames, ", ", " or ") + ")");
  }
  return initialization;
}

Video InitialLatentVideo(const Scene& scene, Initialization initialization,
                         const BaselineOptions& options, std::string* method) {
  if (initialization == Initialization::kEvents && scene.num_events > 0) {
    for (const BaselineMethod candidate : {BaselineMethod::kIntegrate, BaselineMethod::kEdi}) {
      if (!BaselineSupports(candidate, scene, nullptr)) continue;
      *method = BaselineName(candidate);
      return RunBaseline(candidate, scene, options).video;
    }
  }
  *method = "blend";
  return InitializeLatentVideo(scene);
}

}  // namespace evfs

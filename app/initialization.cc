#include "app/initialization.h"

#include "baselines/baseline.h"
#include "core/error.h"
#include "scene/scene.h"

namespace evfs {

const char* InitializationName(Initialization initialization) {
  return initialization == Initialization::kBlend ? "blend" : "events";
}

Initialization ParseInitialization(const std::string& name) {
  if (name == "blend") return Initialization::kBlend;
  if (name == "events") return Initialization::kEvents;
  throw InvalidArgumentError("unknown initialisation '" + name + "' (blend or events)");
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

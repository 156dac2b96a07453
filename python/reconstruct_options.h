// The `options` dictionaries of evfs.reconstruct and evfs.simulate: keys are the command line's
// flag names (without "--"), values Python numbers, booleans and strings, defaults the flags'
// defaults. They fill the same request structs of app/ that the command line fills from its
// flags; python/tests/test_evfs.py holds every key and default to `evfs COMMAND --help`.
#ifndef EVFS_PYTHON_RECONSTRUCT_OPTIONS_H_
#define EVFS_PYTHON_RECONSTRUCT_OPTIONS_H_

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "app/reconstruct_job.h"
#include "events/simulator.h"

namespace evfs {

/// What evfs.reconstruct's options set: the request, and --denoise's "auto" until resolved.
struct ReconstructSettings {
  ReconstructRequest request;
  std::string denoise = "auto";  // auto | none | once
  /// event_model given as a calibration file (FILE.json, written by `evfs calibrate`); "" for
  /// a model name.
  std::string event_model_file;
};

/// The command line's defaults (examples/evfs_main.cc's DEFINE_ lines).
ReconstructSettings DefaultReconstructSettings();

/// Sets each key of `options` (may be None); throws InvalidArgumentError for an unknown key, a
/// value of the wrong type or a name the flag does not accept, with the flag's message.
void ApplyReconstructOptions(const pybind11::handle& options, ReconstructSettings* settings);

/// Resolves denoise "auto" as the command line does: once when weights are shipped or given.
void ResolveDenoise(ReconstructSettings* settings);

/// Every key with its value in `settings`, as Python objects.
pybind11::dict ReconstructOptionValues(const ReconstructSettings& settings);

/// The same for evfs.simulate (SimulatorOptions; defaults those of `evfs simulate`).
void ApplySimulateOptions(const pybind11::handle& options, SimulatorOptions* simulator);
pybind11::dict SimulateOptionValues(const SimulatorOptions& simulator);

}  // namespace evfs

#endif  // EVFS_PYTHON_RECONSTRUCT_OPTIONS_H_

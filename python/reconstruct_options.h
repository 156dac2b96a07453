// The `options` dictionaries of evfs.reconstruct, evfs.video and evfs.simulate: keys are the
// command line's flag names (without "--"), values Python numbers, booleans, strings (a list of
// numbers for --smoothing_continuation), defaults the flags' defaults. Keys, types and defaults
// are those of the option table (app/evfs_options.h): the options fill the same OptionValues
// the command line's flags fill, and the same builders make the requests from them.
#ifndef EVFS_PYTHON_RECONSTRUCT_OPTIONS_H_
#define EVFS_PYTHON_RECONSTRUCT_OPTIONS_H_

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "evfs/app/evfs_options.h"

namespace evfs {

/// Sets each key of `options` (may be None) in `values`: the keys are the options with the
/// OptionUse bit `key_use` (kReconstructKey or kSimulateKey). Throws InvalidArgumentError for
/// an unknown key or a value of the wrong type; a name the flag does not accept is refused by
/// the builder that reads it, with the flag's message.
void ApplyPythonOptions(const pybind11::handle& options, unsigned key_use, OptionValues* values);

/// Every key of `key_use` with its default, as Python objects.
pybind11::dict PythonOptionDefaults(unsigned key_use);

}  // namespace evfs

#endif  // EVFS_PYTHON_RECONSTRUCT_OPTIONS_H_

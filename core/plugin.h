// Plug-ins: modules that evfs opens with dlopen on first use, so that the libraries behind them
// (OpenCV's videoio with FFmpeg, OpenCV's imgcodecs with GDAL) cost start-up time only to the
// commands that use them (BENCHMARKS.md, "Start-up cost"). Each plug-in exports C functions.
#ifndef EVFS_CORE_PLUGIN_H_
#define EVFS_CORE_PLUGIN_H_

#include <string>
#include <vector>

namespace evfs {

/// Opens the plug-in `file_name` and resolves `symbols` into `functions` (same order), looking
/// in $EVFS_PLUGIN_DIR, next to the binary that holds this code and in the lib/evfs/ of its
/// installation, the configured install folder, then the build tree. Returns false, with the
/// reason in `error`, when no candidate opens with every symbol. The module stays loaded for the
/// life of the process. Thread-safe: callers load once (std::call_once) and keep the pointers.
bool LoadPlugin(const std::string& file_name, const std::vector<const char*>& symbols,
                std::vector<void*>* functions, std::string* error);

}  // namespace evfs

#endif  // EVFS_CORE_PLUGIN_H_

#include "evfs/core/plugin.h"

#include <dlfcn.h>
#include <stdlib.h>

#include <filesystem>

namespace evfs {
namespace {

// Where `file_name` is looked for, in order (core/plugin.h).
std::vector<std::filesystem::path> PluginCandidates(const std::string& file_name) {
  std::vector<std::filesystem::path> candidates;
  if (const char* dir = getenv("EVFS_PLUGIN_DIR"); dir != nullptr && *dir != '\0') {
    candidates.push_back(std::filesystem::path(dir) / file_name);
  }
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&PluginCandidates), &info) != 0 && info.dli_fname) {
    std::error_code ignored;
    const std::filesystem::path binary = std::filesystem::weakly_canonical(info.dli_fname, ignored);
    candidates.push_back(binary.parent_path() / file_name);
    candidates.push_back(binary.parent_path().parent_path() / EVFS_PLUGIN_INSTALL_SUBDIR /
                         file_name);
  }
  candidates.push_back(std::filesystem::path(EVFS_PLUGIN_INSTALL_DIR) / file_name);
  candidates.push_back(std::filesystem::path(EVFS_PLUGIN_BUILD_DIR) / file_name);
  return candidates;
}

}  // namespace

bool LoadPlugin(const std::string& file_name, const std::vector<const char*>& symbols,
                std::vector<void*>* functions, std::string* error) {
  error->clear();
  for (const std::filesystem::path& candidate : PluginCandidates(file_name)) {
    std::error_code ignored;
    if (!std::filesystem::is_regular_file(candidate, ignored)) continue;
    void* module = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (module == nullptr) {
      const char* why = dlerror();
      *error = why != nullptr ? why : candidate.string();
      continue;
    }
    functions->assign(symbols.size(), nullptr);
    bool complete = true;
    for (size_t i = 0; i < symbols.size(); ++i) {
      (*functions)[i] = dlsym(module, symbols[i]);
      complete = complete && (*functions)[i] != nullptr;
    }
    if (complete) return true;
    *error = candidate.string() + " lacks the plug-in's functions";
    functions->clear();
  }
  if (error->empty()) {
    *error = "no " + file_name + " next to evfs or in " + EVFS_PLUGIN_INSTALL_DIR;
  }
  return false;
}

}  // namespace evfs

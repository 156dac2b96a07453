#include "io/output_target.h"

#include <fcntl.h>
#include <pwd.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "io/signal_cleanup.h"

namespace evfs {

const char kOutputMarkerFile[] = ".evfs-output";

namespace {

namespace fs = std::filesystem;

// Tags in the names an output takes on its way: the staging name, and the earlier output moved
// aside (only on file systems without RENAME_EXCHANGE).
constexpr char kStagingTag[] = ".evfs-tmp-";
constexpr char kAsideTag[] = ".evfs-old-";
// Digits a process id and a retry counter take in those names.
constexpr size_t kUniqueDigits = 24;
// Most bytes of a marker file read back: its one line is "evfs <command>".
constexpr std::streamsize kMaxMarkerBytes = 256;

// Absolute, normalised, without a trailing separator: "out/", "./out" and "out" are one path.
fs::path Normalized(const std::string& path) {
  std::error_code error;
  fs::path normal = fs::absolute(path, error).lexically_normal();
  if (normal.has_relative_path() && normal.filename().empty()) normal = normal.parent_path();
  return normal;
}

// `path` with every symbolic link in its existing part resolved, so that a link cannot hide
// that two names are one folder.
fs::path Resolved(const fs::path& path) {
  std::error_code error;
  fs::path resolved = fs::weakly_canonical(path, error);
  if (error) return path;
  if (resolved.has_relative_path() && resolved.filename().empty()) {
    resolved = resolved.parent_path();
  }
  return resolved;
}

// True when `inner` is `outer` or lies inside it (component by component, both resolved).
bool IsSameOrInside(const fs::path& inner, const fs::path& outer) {
  auto inner_it = inner.begin();
  for (const fs::path& component : outer) {
    if (inner_it == inner.end() || *inner_it != component) return false;
    ++inner_it;
  }
  return true;
}

// The command an output folder's marker names ("evfs reconstruct"), or "" without a readable
// marker. Only a regular file is read: a FIFO named like the marker must not block.
std::string ReadMarker(const fs::path& folder) {
  const fs::path marker = folder / kOutputMarkerFile;
  std::error_code error;
  if (!fs::is_regular_file(fs::symlink_status(marker, error))) return "";
  std::ifstream in(marker);
  std::string line(kMaxMarkerBytes, '\0');
  in.read(line.data(), kMaxMarkerBytes);
  line.resize(static_cast<size_t>(in.gcount()));
  const size_t end = line.find('\n');
  return end == std::string::npos ? "" : line.substr(0, end);
}

std::string MarkerLine(const std::string& command) { return "evfs " + command; }

[[noreturn]] void Refuse(const fs::path& path, const std::string& why) {
  throw InvalidArgumentError("refusing --out=" + path.string() + ": " + why);
}

[[noreturn]] void Unwritable(const fs::path& path, const std::string& why) {
  throw InputError(InputError::Kind::kUnwritable, path.string(), 0, why);
}

// `base` with a unique tag: ".NAME<tag><pid>-<n>" (folders) or ".STEM<tag><pid>-<n>.EXT"
// (files keep their extension, which says their format).
fs::path TaggedSibling(const fs::path& path, const char* tag, bool keep_extension, int n) {
  const std::string unique = std::to_string(::getpid()) + "-" + std::to_string(n);
  const std::string name =
      keep_extension ? "." + path.stem().string() + tag + unique + path.extension().string()
                     : "." + path.filename().string() + tag + unique;
  return path.parent_path() / name;
}

}  // namespace

std::vector<ProtectedFolder> DefaultProtectedFolders() {
  std::vector<ProtectedFolder> folders = {{"/", "the file-system root"}};
  std::error_code error;
  const fs::path current = fs::current_path(error);
  if (!error) folders.push_back({current.string(), "the current folder"});
  if (const char* home = std::getenv("HOME"); home != nullptr && home[0] != '\0') {
    folders.push_back({home, "the home folder"});
  }
  if (const passwd* entry = getpwuid(getuid()); entry != nullptr && entry->pw_dir != nullptr) {
    folders.push_back({entry->pw_dir, "the home folder"});
  }
  return folders;
}

OutputTarget::OutputTarget(OutputOptions options) : options_(std::move(options)) {
  if (options_.path.empty()) throw InvalidArgumentError("--out is empty");
  const fs::path path = Normalized(options_.path);
  path_ = path.string();
  const fs::path resolved = Resolved(path);

  // What --out must never be: a folder whose removal would take the system, the user's home,
  // the folder they work in, or the recording being read.
  for (const ProtectedFolder& folder : options_.protected_folders) {
    const fs::path protected_folder = Resolved(Normalized(folder.path));
    if (IsSameOrInside(protected_folder, resolved)) {
      Refuse(path, "it is " +
                       (protected_folder == resolved
                            ? folder.what
                            : "a parent of " + folder.what + " " + protected_folder.string()) +
                       ", which evfs never replaces");
    }
  }
  for (const std::string& input : options_.inputs) {
    if (input.empty()) continue;
    const fs::path input_path = Resolved(Normalized(input));
    if (IsSameOrInside(resolved, input_path)) {
      Refuse(path, "it is, or lies inside, the input " + input_path.string());
    }
    if (IsSameOrInside(input_path, resolved)) {
      Refuse(path, "it contains the input " + input_path.string());
    }
  }
  CheckExisting();

  // The parent must be, or become, a folder we can write in, and the temporary names must fit.
  fs::path existing = path.parent_path();
  std::vector<fs::path> missing;
  std::error_code error;
  while (!fs::exists(existing, error) && existing.has_relative_path()) {
    missing.push_back(existing);
    existing = existing.parent_path();
  }
  if (!fs::is_directory(existing, error)) {
    Unwritable(path, "cannot create the output: " + existing.string() + " is not a folder");
  }
  if (::access(existing.c_str(), W_OK | X_OK) != 0) {
    Unwritable(path, "cannot create the output: no permission to write in " + existing.string());
  }
  const long name_max = ::pathconf(existing.c_str(), _PC_NAME_MAX);
  const size_t longest_name =
      path.filename().string().size() + 1 + sizeof(kStagingTag) + kUniqueDigits;
  if (name_max > 0 && longest_name > static_cast<size_t>(name_max)) {
    Unwritable(path, "the name is too long: with its temporary suffix it takes " +
                         std::to_string(longest_name) + " bytes, the file system allows " +
                         std::to_string(name_max));
  }
  if (path.string().size() + longest_name >= PATH_MAX) {
    Unwritable(path, "the path is too long (" + std::to_string(path.string().size()) +
                         " bytes, the system allows " + std::to_string(PATH_MAX) + ")");
  }

  // Nothing has been read or computed yet: create the parents and the staging path now, so an
  // output that cannot be written fails before the work.
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (!fs::create_directory(*it, error) || error) {
      for (auto created = created_parents_.rbegin(); created != created_parents_.rend();
           ++created) {
        fs::remove(*created, error);
      }
      Unwritable(*it, "cannot create the folder (" + error.message() + ")");
    }
    created_parents_.push_back(it->string());
  }
  const bool is_file = options_.kind == OutputOptions::Kind::kFile;
  for (int attempt = 0;; ++attempt) {
    const fs::path staging = TaggedSibling(path, kStagingTag, is_file, attempt);
    staging_ = staging.string();
    cleanup_ = std::make_unique<ScopedCleanupPath>(staging_);
    bool created = false;
    int open_errno = 0;
    if (is_file) {
      const int fd = ::open(staging.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
      created = fd >= 0;
      open_errno = errno;
      if (created) ::close(fd);
    } else {
      created = fs::create_directory(staging, error) && !error;
      open_errno = error.value();
    }
    if (created) break;
    cleanup_.reset();
    if (open_errno == EEXIST && attempt < 100) continue;  // a leftover of a killed run
    staging_.clear();
    const std::string reason = std::generic_category().message(open_errno);
    for (auto created_parent = created_parents_.rbegin(); created_parent != created_parents_.rend();
         ++created_parent) {
      fs::remove(*created_parent, error);
    }
    Unwritable(path, "cannot create the output (" + reason + ")");
  }
}

OutputTarget::~OutputTarget() {
  if (committed_ || staging_.empty()) return;
  std::error_code error;
  fs::remove_all(staging_, error);
  cleanup_.reset();
  for (auto it = created_parents_.rbegin(); it != created_parents_.rend(); ++it) {
    fs::remove(*it, error);  // only while empty
  }
}

void OutputTarget::CheckExisting() const {
  const fs::path path = path_;
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  if (!fs::exists(status)) return;
  const std::string command = MarkerLine(options_.command);
  if (fs::is_symlink(status)) {
    Refuse(path, "it is a symbolic link; name a new folder or file of its own");
  }
  if (options_.kind == OutputOptions::Kind::kFolder) {
    if (!fs::is_directory(status)) {
      Refuse(path, "it exists and is not a folder ('" + command + "' writes a folder)");
    }
    if (fs::is_empty(path, error) && !error) return;
    const std::string marker = ReadMarker(path);
    if (marker.empty()) {
      Refuse(path, "the folder holds files evfs did not write (it has no " +
                       std::string(kOutputMarkerFile) + "); name a new folder");
    }
    if (marker != command) {
      Refuse(path, "the folder holds the output of '" + marker + "', not of '" + command + "'");
    }
  } else {
    if (fs::is_directory(status)) {
      Refuse(path, "it is a folder ('" + command + "' writes one file there)");
    }
    if (!fs::is_regular_file(status) || !options_.is_own_file || !options_.is_own_file(path_)) {
      Refuse(path, "the file exists and evfs did not write it; name a new file");
    }
  }
  if (!options_.overwrite) {
    Refuse(path, "it holds an earlier '" + command + "' output; pass --overwrite to replace it");
  }
}

void OutputTarget::Commit() {
  if (committed_ || staging_.empty()) {
    throw std::logic_error("OutputTarget::Commit called twice");
  }
  const fs::path path = path_;
  const bool is_file = options_.kind == OutputOptions::Kind::kFile;
  if (!is_file) {
    std::ofstream marker(fs::path(staging_) / kOutputMarkerFile);
    marker << MarkerLine(options_.command) << "\n";
    marker.close();
    if (!marker) Unwritable(path / kOutputMarkerFile, "cannot write the output marker");
  }

  CheckExisting();  // something may have appeared at path_ while we worked
  std::error_code error;
  if (is_file || !fs::exists(fs::symlink_status(path, error))) {
    fs::rename(staging_, path, error);  // a file replaces an earlier file atomically
    if (error)
      Unwritable(path, "cannot move the finished output into place (" + error.message() + ")");
    committed_ = true;
    cleanup_.reset();
    return;
  }
  // One atomic step: the new output takes the name and the staging name takes the earlier
  // output, which is removed next (still registered, so that it goes even if we die now).
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, path_.c_str(), RENAME_EXCHANGE) == 0) {
    committed_ = true;
    fs::remove_all(staging_, error);
    cleanup_.reset();
    return;
  }
  if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP) {
    Unwritable(path, std::string("cannot move the finished output into place (") +
                         std::strerror(errno) + ")");
  }
  // A file system without RENAME_EXCHANGE: move the earlier output aside, the new one in, and
  // remove the earlier one; on failure it goes back.
  fs::path aside;
  for (int attempt = 0;; ++attempt) {
    aside = TaggedSibling(path, kAsideTag, false, attempt);
    if (!fs::exists(fs::symlink_status(aside, error)) || attempt >= 100) break;
  }
  fs::rename(path, aside, error);
  if (error) Unwritable(path, "cannot move the earlier output aside (" + error.message() + ")");
  fs::rename(staging_, path, error);
  if (error) {
    const std::string reason = error.message();
    fs::rename(aside, path, error);
    Unwritable(path, "cannot move the finished output into place (" + reason + ")");
  }
  committed_ = true;
  cleanup_.reset();
  fs::remove_all(aside, error);
}

}  // namespace evfs

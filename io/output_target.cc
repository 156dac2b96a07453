#include "evfs/io/output_target.h"

#include <fcntl.h>
#include <pwd.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "evfs/core/error.h"
#include "evfs/runtime/signal_cleanup.h"

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
// Most bytes of a marker file read back: its first line and one line per path evfs wrote
// (a long video's frames take a few hundred kilobytes).
constexpr std::streamsize kMaxMarkerBytes = 64 << 20;
// Foreign paths a refusal names before it says how many more there are.
constexpr size_t kForeignPathsNamed = 3;
// The marker's lines after the first: "folder REL" and "file REL" for each path evfs wrote, and
// kUnfinishedLine in a staging folder, whose whole content is evfs's work in progress.
constexpr char kFolderEntry[] = "folder ";
constexpr char kFileEntry[] = "file ";
constexpr char kUnfinishedLine[] = "unfinished";

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

// An output folder's marker as read back.
struct Marker {
  enum class State { kMissing, kSymlink, kNotAFile, kUnreadable, kRead };
  State state = State::kMissing;
  std::string command;            // its first line: "evfs reconstruct"
  std::set<std::string> entries;  // "folder frames", "file frames/000000.png"
  bool unfinished = false;        // a staging folder's marker
};

// The marker of `folder`. Only a regular file is read: a FIFO named like the marker must not
// block, and a link could make a folder of the user's look like evfs's.
Marker ReadMarker(const fs::path& folder) {
  const fs::path path = folder / kOutputMarkerFile;
  Marker marker;
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  if (!fs::exists(status)) return marker;
  if (fs::is_symlink(status)) {
    marker.state = Marker::State::kSymlink;
    return marker;
  }
  if (!fs::is_regular_file(status)) {
    marker.state = Marker::State::kNotAFile;
    return marker;
  }
  std::ifstream in(path);
  std::string text(kMaxMarkerBytes + 1, '\0');
  in.read(text.data(), kMaxMarkerBytes + 1);
  text.resize(static_cast<size_t>(in.gcount()));
  marker.state = Marker::State::kUnreadable;
  if (in.bad() || text.size() > static_cast<size_t>(kMaxMarkerBytes)) return marker;
  const size_t end = text.find('\n');
  if (end == std::string::npos) return marker;
  marker.state = Marker::State::kRead;
  marker.command = text.substr(0, end);
  std::istringstream lines(text.substr(end + 1));
  for (std::string line; std::getline(lines, line);) {
    if (line == kUnfinishedLine) {
      marker.unfinished = true;
    } else if (!line.empty()) {
      marker.entries.insert(line);
    }
  }
  return marker;
}

// The marker's line for `relative`, the path of `status` inside the folder.
std::string EntryLine(const fs::file_status& status, const std::string& relative) {
  return (fs::is_directory(status) ? kFolderEntry : kFileEntry) + relative;
}

// Every path inside `folder` but its marker, as marker lines, in a stable order. Links are
// listed, never followed. Sets `error` when a folder cannot be listed.
std::vector<std::string> ListEntries(const fs::path& folder, std::error_code* error) {
  std::vector<std::string> entries;
  fs::recursive_directory_iterator it(folder, fs::directory_options::none, *error);
  for (; !*error && it != fs::recursive_directory_iterator(); it.increment(*error)) {
    const std::string relative = it->path().lexically_relative(folder).generic_string();
    if (relative == kOutputMarkerFile) continue;
    std::error_code status_error;
    entries.push_back(EntryLine(it->symlink_status(status_error), relative));
  }
  std::sort(entries.begin(), entries.end());
  return entries;
}

// The paths inside `folder` that its marker does not list, each as "REL" ("REL/" for a folder,
// whose content is then not listed). Sets `error` when a folder cannot be listed.
std::vector<std::string> ForeignPaths(const fs::path& folder, const Marker& marker,
                                      std::error_code* error) {
  std::vector<std::string> foreign;
  fs::recursive_directory_iterator it(folder, fs::directory_options::none, *error);
  for (; !*error && it != fs::recursive_directory_iterator(); it.increment(*error)) {
    const std::string relative = it->path().lexically_relative(folder).generic_string();
    if (relative == kOutputMarkerFile) continue;
    std::error_code status_error;
    const fs::file_status status = it->symlink_status(status_error);
    if (marker.entries.count(EntryLine(status, relative)) != 0) continue;
    const bool is_folder = fs::is_directory(status);
    foreign.push_back(relative + (is_folder ? "/" : ""));
    if (is_folder) it.disable_recursion_pending();
  }
  std::sort(foreign.begin(), foreign.end());
  return foreign;
}

// "a, b, c (and 4 more)".
std::string NameSome(const std::vector<std::string>& paths) {
  std::string names;
  for (size_t i = 0; i < paths.size() && i < kForeignPathsNamed; ++i) {
    names += (i > 0 ? ", " : "") + paths[i];
  }
  if (paths.size() > kForeignPathsNamed) {
    names += " (and " + std::to_string(paths.size() - kForeignPathsNamed) + " more)";
  }
  return names;
}

// Removes a tree evfs wrote. Folders made read-only (a user protecting frames/) would stop
// the removal of their content, so each folder is made writable by its owner first.
void RemoveOwnTree(const fs::path& path, std::error_code* error) {
  fs::remove_all(path, *error);
  if (!*error) return;
  std::error_code walk_error;
  fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, walk_error);
  for (fs::recursive_directory_iterator it(path, fs::directory_options::none, walk_error);
       !walk_error && it != fs::recursive_directory_iterator(); it.increment(walk_error)) {
    std::error_code status_error;
    if (fs::is_directory(it->symlink_status(status_error))) {
      fs::permissions(it->path(), fs::perms::owner_all, fs::perm_options::add, status_error);
    }
  }
  error->clear();
  fs::remove_all(path, *error);
}

void DefaultWarn(const std::string& message) {
  std::fprintf(stderr, "evfs: %s\n", message.c_str());
  std::fflush(stderr);
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

// The process id in `name` when it is a staging or aside name of `path` (TaggedSibling),
// else 0.
pid_t TaggedSiblingPid(const fs::path& path, const std::string& name, bool keep_extension) {
  for (const char* tag : {kStagingTag, kAsideTag}) {
    const std::string prefix =
        "." + (keep_extension ? path.stem().string() : path.filename().string()) + tag;
    const std::string suffix = keep_extension ? path.extension().string() : "";
    if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    const std::string unique =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    const size_t dash = unique.find('-');
    if (dash == 0 || dash == std::string::npos || dash + 1 == unique.size() ||
        dash > kUniqueDigits) {
      continue;
    }
    const auto digits = [](const std::string& text) {
      return std::all_of(text.begin(), text.end(),
                         [](unsigned char c) { return std::isdigit(c) != 0; });
    };
    if (!digits(unique.substr(0, dash)) || !digits(unique.substr(dash + 1))) continue;
    const long long pid = std::atoll(unique.substr(0, dash).c_str());
    if (pid > 0 && pid <= INT_MAX) return static_cast<pid_t>(pid);
  }
  return 0;
}

// True when process `pid` runs on this machine (or may: one we may not signal).
bool ProcessRuns(pid_t pid) { return ::kill(pid, 0) == 0 || errno != ESRCH; }

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
      RemoveCreatedParents();
      Unwritable(*it, "cannot create the folder (" + error.message() + ")");
    }
    created_parents_.push_back(it->string());
  }
  // Taken before anything beside OUT is removed or created: the leftovers of another run are
  // leftovers only when no run holds the lock.
  try {
    lock_ = std::make_unique<OutputLock>(path_);
  } catch (...) {
    RemoveCreatedParents();
    throw;
  }
  RemoveLeftovers();
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
    if (created && !is_file) {
      // Marked at once, so that a later run knows a folder left by a killed one as evfs's.
      std::ofstream marker(staging / kOutputMarkerFile);
      marker << MarkerLine(options_.command) << "\n" << kUnfinishedLine << "\n";
    }
    if (created) break;
    cleanup_.reset();
    if (open_errno == EEXIST && attempt < 100) continue;  // a leftover of a killed run
    staging_.clear();
    const std::string reason = std::generic_category().message(open_errno);
    lock_.reset();
    RemoveCreatedParents();
    Unwritable(path, "cannot create the output (" + reason + ")");
  }
}

OutputTarget::~OutputTarget() {
  const bool remove = !committed_ && !staging_.empty();
  std::error_code error;
  if (remove) {
    fs::remove_all(staging_, error);
    cleanup_.reset();
  }
  lock_.reset();  // its file lies in the parents
  if (remove) RemoveCreatedParents();
}

void OutputTarget::RemoveCreatedParents() const {
  std::error_code ignored;
  for (auto created = created_parents_.rbegin(); created != created_parents_.rend(); ++created) {
    fs::remove(*created, ignored);  // only while empty
  }
}

std::string OutputLock::LockPath(const std::string& out_path) {
  const fs::path path = Normalized(out_path);
  return (path.parent_path() / ("." + path.filename().string() + ".evfs-lock")).string();
}

OutputLock::OutputLock(const std::string& out_path) : path_(LockPath(out_path)) {
  // A holder removes the file as it lets go: a lock taken on a file that is no longer at
  // path_ (or was replaced meanwhile) guards nothing, so it is taken again on the new file.
  for (int attempt = 0;; ++attempt) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_ < 0) {
      throw InputError(
          InputError::Kind::kUnwritable, path_, 0,
          std::string("cannot create the lock file of the output (") + std::strerror(errno) + ")");
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int flock_errno = errno;
      char holder[32] = {0};
      const ssize_t read_bytes = ::pread(fd_, holder, sizeof(holder) - 1, 0);
      ::close(fd_);
      fd_ = -1;
      std::string pid = read_bytes > 0 ? std::string(holder, read_bytes) : "";
      while (!pid.empty() && !std::isdigit(static_cast<unsigned char>(pid.back()))) pid.pop_back();
      if (flock_errno != EWOULDBLOCK) {
        throw InputError(
            InputError::Kind::kUnwritable, path_, 0,
            std::string("cannot lock the output (") + std::strerror(flock_errno) + ")");
      }
      throw InvalidArgumentError("--out=" + Normalized(out_path).string() +
                                 " is being written by another evfs run" +
                                 (pid.empty() ? std::string() : " (process " + pid + ")") +
                                 "; wait for it to end, or choose another --out");
    }
    struct stat held = {}, named = {};
    if (::fstat(fd_, &held) == 0 && ::lstat(path_.c_str(), &named) == 0 &&
        held.st_dev == named.st_dev && held.st_ino == named.st_ino) {
      break;
    }
    ::close(fd_);
    fd_ = -1;
    if (attempt >= 100) {
      throw InputError(InputError::Kind::kUnwritable, path_, 0,
                       "cannot lock the output: its lock file keeps changing");
    }
  }
  RefuseForeignLockFile(out_path);
  cleanup_ = std::make_unique<ScopedCleanupPath>(path_);
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
    // The process id only makes a refusal clearer; the lock holds without it.
  }
}

void OutputLock::RefuseForeignLockFile(const std::string& out_path) {
  // The lock file is evfs' own only when it is a plain file that is empty (just created) or
  // holds a process id (left by a run that died): anything else is a user's file of that name,
  // which the run would overwrite and delete.
  struct stat held = {};
  char content[kMaxLockFileBytes + 1] = {0};
  const ssize_t read_bytes = ::pread(fd_, content, sizeof(content), 0);
  bool ours = ::fstat(fd_, &held) == 0 && S_ISREG(held.st_mode) && read_bytes >= 0 &&
              read_bytes <= kMaxLockFileBytes;
  for (ssize_t i = 0; ours && i < read_bytes; ++i) {
    const unsigned char c = static_cast<unsigned char>(content[i]);
    ours = std::isdigit(c) || (c == '\n' && i == read_bytes - 1);
  }
  if (ours) return;
  ::close(fd_);
  fd_ = -1;
  throw InvalidArgumentError("--out=" + Normalized(out_path).string() + " needs the name " + path_ +
                             " for its lock, and a file that is not evfs' is there; " +
                             "move it away, or choose another --out");
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  // Removed while still held, so that no other run can hold a lock on a file about to go.
  ::unlink(path_.c_str());
  ::close(fd_);
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
    const Marker marker = ReadMarker(path);
    const std::string marker_name = std::string(kOutputMarkerFile);
    switch (marker.state) {
      case Marker::State::kMissing:
        Refuse(path, "the folder holds files evfs did not write (it has no " + marker_name +
                         "); name a new folder");
      case Marker::State::kSymlink:
        Refuse(path, "its " + marker_name +
                         " is a symbolic link, not a marker evfs wrote; name a new folder");
      case Marker::State::kNotAFile:
        Refuse(path, "its " + marker_name +
                         " is not a regular file, so not a marker evfs wrote; name a new folder");
      case Marker::State::kUnreadable:
        Refuse(path, "its " + marker_name + " cannot be read as evfs's marker; name a new folder");
      case Marker::State::kRead:
        break;
    }
    if (marker.command != command) {
      Refuse(path,
             "the folder holds the output of '" + marker.command + "', not of '" + command + "'");
    }
    if (options_.overwrite) {
      // --overwrite replaces what evfs wrote, never what the user added to it.
      const std::vector<std::string> foreign = ForeignPaths(path, marker, &error);
      if (error) {
        Refuse(path, "cannot list the earlier output to replace it (" + error.message() + ")");
      }
      if (!foreign.empty()) {
        Refuse(path, "the earlier output holds what evfs did not write: " + NameSome(foreign) +
                         "; move that away or name a new folder");
      }
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
    std::error_code list_error;
    const std::vector<std::string> entries = ListEntries(staging_, &list_error);
    if (list_error) {
      Unwritable(staging_, "cannot list the new output (" + list_error.message() + ")");
    }
    std::ofstream marker(fs::path(staging_) / kOutputMarkerFile, std::ios::trunc);
    marker << MarkerLine(options_.command) << "\n";
    // A name holding a line break cannot be listed; it is then foreign to a later --overwrite.
    for (const std::string& entry : entries) {
      if (entry.find('\n') == std::string::npos) marker << entry << "\n";
    }
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
    RemoveReplaced(staging_);
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
  RemoveReplaced(aside);
}

void OutputTarget::Warn(const std::string& message) const {
  if (options_.warn) {
    options_.warn(message);
  } else {
    DefaultWarn(message);
  }
}

void OutputTarget::RemoveReplaced(const fs::path& replaced) const {
  std::error_code error;
  RemoveOwnTree(replaced, &error);
  if (error) {
    Warn("the earlier output of " + path_ + " was replaced but cannot be removed from " +
         replaced.string() + " (" + error.message() + "); a later run on " + path_ + " removes it");
  }
}

void OutputTarget::RemoveLeftovers() const {
  const fs::path path = path_;
  const bool is_file = options_.kind == OutputOptions::Kind::kFile;
  std::error_code error;
  std::vector<fs::path> leftovers;
  for (fs::directory_iterator it(path.parent_path(), error);
       !error && it != fs::directory_iterator(); it.increment(error)) {
    const pid_t pid = TaggedSiblingPid(path, it->path().filename().string(), is_file);
    if (pid != 0 && pid != ::getpid() && !ProcessRuns(pid)) leftovers.push_back(it->path());
  }
  for (const fs::path& leftover : leftovers) {
    // Only what evfs shows to be its own goes: an empty folder or file, a staging folder (its
    // marker says so), or an earlier output holding nothing but what its marker lists.
    std::error_code status_error;
    const fs::file_status status = fs::symlink_status(leftover, status_error);
    bool own = false;
    if (fs::is_directory(status)) {
      const Marker marker = ReadMarker(leftover);
      if (fs::is_empty(leftover, status_error) && !status_error) {
        own = true;
      } else if (marker.state == Marker::State::kRead && marker.command.rfind("evfs ", 0) == 0) {
        std::error_code list_error;
        own = marker.unfinished ||
              (ForeignPaths(leftover, marker, &list_error).empty() && !list_error);
      }
    } else if (fs::is_regular_file(status) && is_file) {
      // A staging file holds no marker, and a half-written one is not parsed (libhdf5 may crash
      // on it): only an empty one is known to be evfs's.
      own = fs::file_size(leftover, status_error) == 0 && !status_error;
    }
    if (!own) continue;
    std::error_code remove_error;
    RemoveOwnTree(leftover, &remove_error);
    if (remove_error) {
      Warn("cannot remove " + leftover.string() + ", left by an evfs run that ended early (" +
           remove_error.message() + ")");
    } else {
      Warn("removed " + leftover.string() + ", left by an evfs run that ended early");
    }
  }
}

}  // namespace evfs

#include "evfs/app/video_work_folder.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>
#include <vector>

#include "evfs/core/error.h"

namespace evfs {

namespace fs = std::filesystem;

namespace {

// The marker of a work folder: its first line, then the run's settings.
constexpr char kWorkMarkerFile[] = ".evfs-video-work";
constexpr char kWorkMarkerTitle[] = "evfs video work folder";

std::string ReadWholeFile(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// Whether `name` is a run of decimal digits followed by `suffix`.
bool DigitsThen(std::string_view name, std::string_view suffix) {
  if (name.size() <= suffix.size() || name.substr(name.size() - suffix.size()) != suffix) {
    return false;
  }
  const std::string_view digits = name.substr(0, name.size() - suffix.size());
  return std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Whether `relative` (inside a work folder, '/'-separated) is a path a video run writes there:
// the marker, frames/, confidence/ and windows/ with their files, and each file's temporary name
// (frames are written in place now; NNNNNN.tmp.png is what an interrupted earlier version left).
bool IsWorkFolderPath(const std::string& relative, bool is_folder) {
  if (is_folder) return relative == "frames" || relative == "confidence" || relative == "windows";
  std::string_view name = relative;
  constexpr std::string_view kTemporary = ".tmp";
  if (name.size() > kTemporary.size() && name.substr(name.size() - kTemporary.size()) == kTemporary)
    name.remove_suffix(kTemporary.size());
  if (name == kWorkMarkerFile) return true;
  for (const std::string_view folder : {"frames/", "confidence/"}) {
    if (name.substr(0, folder.size()) == folder) {
      const std::string_view file = name.substr(folder.size());
      return DigitsThen(file, ".png") || DigitsThen(file, ".tmp.png");
    }
  }
  constexpr std::string_view kWindows = "windows/";
  return name.substr(0, kWindows.size()) == kWindows &&
         DigitsThen(name.substr(kWindows.size()), ".json");
}

// The paths in a work folder that a video run does not write ("REL", "REL/" for a folder),
// and the own files when `own_files` is given. Links are listed, never followed.
std::vector<std::string> WorkFolderForeign(const fs::path& folder,
                                           std::vector<fs::path>* own_files = nullptr) {
  std::vector<std::string> foreign;
  std::error_code error;
  fs::recursive_directory_iterator it(folder, fs::directory_options::none, error);
  for (; !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    const std::string relative = it->path().lexically_relative(folder).generic_string();
    std::error_code status_error;
    const fs::file_status status = it->symlink_status(status_error);
    const bool is_folder = fs::is_directory(status);
    if (IsWorkFolderPath(relative, is_folder) && (is_folder || fs::is_regular_file(status))) {
      if (!is_folder && own_files != nullptr) own_files->push_back(it->path());
      continue;
    }
    foreign.push_back(relative + (is_folder ? "/" : ""));
    if (is_folder) it.disable_recursion_pending();
  }
  std::sort(foreign.begin(), foreign.end());
  if (error) foreign.push_back("(a folder that cannot be listed: " + error.message() + ")");
  return foreign;
}

// "a, b, c (and 4 more)".
std::string NameSome(const std::vector<std::string>& paths) {
  constexpr size_t kNamed = 3;
  std::string names;
  for (size_t i = 0; i < paths.size() && i < kNamed; ++i) names += (i > 0 ? ", " : "") + paths[i];
  if (paths.size() > kNamed) names += " (and " + std::to_string(paths.size() - kNamed) + " more)";
  return names;
}

}  // namespace

void WriteFileAtomically(const fs::path& path, const std::string& text) {
  const fs::path temporary = path.string() + ".tmp";
  std::ofstream file(temporary);
  file << text;
  file.close();
  std::error_code error;
  if (!file || (fs::rename(temporary, path, error), error)) {
    throw InputError(InputError::Kind::kUnwritable, path.string(), 0, "cannot write it");
  }
}

bool IsVideoWorkFolder(const fs::path& folder) {
  std::error_code error;
  if (fs::is_symlink(folder, error) || !fs::is_directory(folder, error)) return false;
  const fs::path marker = folder / kWorkMarkerFile;
  if (fs::is_symlink(marker, error) || !fs::is_regular_file(marker, error)) return false;
  std::ifstream file(marker);
  std::string title;
  std::getline(file, title);
  return title == kWorkMarkerTitle;
}

void ClearVideoWorkFolder(const fs::path& folder) {
  if (!IsVideoWorkFolder(folder)) return;
  std::vector<fs::path> own_files;
  std::error_code error;
  if (WorkFolderForeign(folder, &own_files).empty()) {
    fs::remove_all(folder, error);
    return;
  }
  for (const fs::path& file : own_files) fs::remove(file, error);
  for (const char* sub : {"frames", "confidence", "windows", ""}) {
    fs::remove(folder / sub, error);  // if empty
  }
}

std::map<int, VideoWindowRecord> PrepareVideoWorkFolder(const fs::path& folder,
                                                        const std::string& fingerprint,
                                                        bool resume) {
  std::error_code error;
  const bool exists = fs::exists(fs::symlink_status(folder, error));
  if (exists && !IsVideoWorkFolder(folder)) {
    throw InvalidArgumentError(folder.string() +
                               " exists and is not an evfs video work folder: evfs keeps "
                               "unfinished windows there; move it away");
  }
  if (exists) {
    // A work folder is reused or replaced whole: nothing the user added may be mixed in or lost.
    const std::vector<std::string> foreign = WorkFolderForeign(folder);
    if (!foreign.empty()) {
      throw InvalidArgumentError(folder.string() +
                                 " (the work folder of this video) holds what "
                                 "evfs did not write: " +
                                 NameSome(foreign) + "; move that away");
    }
  }
  const std::string marker_text = std::string(kWorkMarkerTitle) + "\n" + fingerprint;
  std::map<int, VideoWindowRecord> done;
  if (exists && resume) {
    if (ReadWholeFile(folder / kWorkMarkerFile) != marker_text) {
      throw InvalidArgumentError(
          "--resume: the interrupted run in " + folder.string() +
          " had other settings or data; run again without --resume to start over");
    }
    for (const auto& entry : fs::directory_iterator(folder / "windows", error)) {
      if (entry.path().extension() != ".json") continue;
      try {
        VideoWindowRecord record = VideoWindowRecord::parse(ReadWholeFile(entry.path()));
        const int index = record.at("index").get<int>();
        done[index] = std::move(record);
      } catch (const std::exception&) {
        // An unreadable record is a window to solve again.
      }
    }
    return done;
  }
  error.clear();
  if (exists) fs::remove_all(folder, error);
  if (error || !fs::create_directory(folder, error) || error ||
      !fs::create_directory(folder / "frames", error) ||
      !fs::create_directory(folder / "confidence", error) ||
      !fs::create_directory(folder / "windows", error)) {
    throw InputError(InputError::Kind::kUnwritable, folder.string(), 0,
                     "cannot create the work folder: " + error.message());
  }
  WriteFileAtomically(folder / kWorkMarkerFile, marker_text);
  return done;
}

std::string VideoWorkFolder(const std::string& out_path) {
  const fs::path out = fs::path(out_path).lexically_normal();
  const fs::path name = out.has_filename() ? out.filename() : out.parent_path().filename();
  const fs::path parent = out.has_filename() ? out.parent_path() : out.parent_path().parent_path();
  return (parent / ("." + name.string() + ".evfs-video-work")).string();
}

void RemoveVideoWorkFolder(const std::string& out_path) {
  ClearVideoWorkFolder(VideoWorkFolder(out_path));
}

}  // namespace evfs

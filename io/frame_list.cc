#include "evfs/io/frame_list.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>

#include "evfs/core/error.h"
#include "evfs/io/decimal_seconds.h"
#include "evfs/io/message_excerpt.h"
#include "evfs/io/text_file_writer.h"

namespace evfs {
namespace {

// PATH_MAX on Linux: the system opens no longer path.
constexpr size_t kMaxImagePathBytes = 4096;

std::atomic<bool> frame_paths_may_leave_folder{false};

// Why `path`, relative to the folder of images.txt, leads outside it, or "" when it stays in.
// Decided on the text alone: a link inside the folder (images/ on another disk) is the user's
// own arrangement.
std::string OutsidePathProblem(const std::string& path) {
  const std::filesystem::path given(path);
  if (given.is_absolute()) {
    return "frame path '" + MessageExcerpt(path) + "' is absolute";
  }
  const std::filesystem::path normal = given.lexically_normal();
  if (!normal.empty() && *normal.begin() == "..") {
    return "frame path '" + MessageExcerpt(path) + "' leads outside the recording's folder";
  }
  return "";
}

bool IsBlank(char c) { return c == ' ' || c == '\t'; }

std::string Trim(const std::string& text) {
  size_t begin = 0;
  size_t end = text.size();
  while (begin < end && IsBlank(text[begin])) ++begin;
  while (end > begin && (IsBlank(text[end - 1]) || text[end - 1] == '\r')) --end;
  return text.substr(begin, end - begin);
}

// Opens `path`, or throws InputError(kMissingFile).
std::ifstream OpenForReading(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     std::string("cannot read the file: ") + std::strerror(errno));
  }
  return stream;
}

// Calls `visit(line_number, content)` for every line that is neither blank nor a comment, with
// the content trimmed of surrounding blanks and a trailing '\r'.
void ForEachContentLine(std::istream& stream,
                        const std::function<void(int64_t, const std::string&)>& visit) {
  // A UTF-8 byte-order mark, which some Windows editors put first, is no part of the text.
  static const std::string kByteOrderMark = "\xEF\xBB\xBF";
  std::string line;
  for (int64_t line_number = 1; std::getline(stream, line); ++line_number) {
    if (line_number == 1 && line.compare(0, kByteOrderMark.size(), kByteOrderMark) == 0) {
      line.erase(0, kByteOrderMark.size());
    }
    const std::string content = Trim(line);
    if (content.empty() || content[0] == '#') continue;
    visit(line_number, content);
  }
}

// Parses a whole token as decimal seconds, or throws naming the file, line and field.
int64_t ParseSecondsField(const std::string& token, const std::string& field,
                          const std::string& path, int64_t line_number) {
  int64_t t_ns = 0;
  DecimalStatus status;
  const char* end = ParseDecimalSeconds(token.c_str(), &t_ns, &status);
  if (status == DecimalStatus::kOk && end != token.c_str() + token.size()) {
    status = DecimalStatus::kNotANumber;
  }
  if (status != DecimalStatus::kOk) {
    throw InputError(InputError::Kind::kMalformed, path, line_number,
                     "field '" + field + "' = '" + MessageExcerpt(token) +
                         "': " + DescribeDecimalStatus(status));
  }
  return t_ns;
}

// Splits off the first blank-separated token of a trimmed line; the rest is trimmed.
bool SplitFirst(const std::string& content, std::string* first, std::string* rest) {
  size_t blank = 0;
  while (blank < content.size() && !IsBlank(content[blank])) ++blank;
  if (blank == content.size()) return false;
  *first = content.substr(0, blank);
  *rest = Trim(content.substr(blank));
  return true;
}

// Splits off the last blank-separated token of a trimmed line; the rest is trimmed.
bool SplitLast(const std::string& content, std::string* rest, std::string* last) {
  size_t blank = content.size();
  while (blank > 0 && !IsBlank(content[blank - 1])) --blank;
  if (blank == 0) return false;
  *last = content.substr(blank);
  *rest = Trim(content.substr(0, blank));
  return true;
}

}  // namespace

void SetFramePathsMayLeaveFolder(bool allow) { frame_paths_may_leave_folder = allow; }

bool FramePathsMayLeaveFolder() { return frame_paths_may_leave_folder; }

std::string ImagePathProblem(const std::string& path) {
  if (HasControlCharacter(path)) {
    return "image path '" + MessageExcerpt(path) + "' holds a control character";
  }
  if (path.size() > kMaxImagePathBytes) {
    return "image path '" + MessageExcerpt(path) + "' is longer than " +
           std::to_string(kMaxImagePathBytes) + " bytes";
  }
  return "";
}

std::vector<FrameInfo> ReadFrameList(const std::string& images_txt) {
  std::ifstream stream = OpenForReading(images_txt);
  return ReadFrameList(stream, images_txt);
}

std::vector<FrameInfo> ReadFrameList(std::istream& stream, const std::string& images_txt) {
  std::vector<FrameInfo> frames;
  std::map<std::string, int64_t> line_of_path;
  ForEachContentLine(stream, [&](int64_t line_number, const std::string& content) {
    FrameInfo frame;
    std::string t_token;
    if (!SplitFirst(content, &t_token, &frame.path) || frame.path.empty()) {
      throw InputError(InputError::Kind::kMalformed, images_txt, line_number,
                       "expected 't path', found '" + MessageExcerpt(content) + "'");
    }
    const std::string path_problem = ImagePathProblem(frame.path);
    if (!path_problem.empty()) {
      throw InputError(InputError::Kind::kMalformed, images_txt, line_number, path_problem);
    }
    if (!FramePathsMayLeaveFolder()) {
      const std::string outside = OutsidePathProblem(frame.path);
      if (!outside.empty()) {
        throw InputError(InputError::Kind::kMalformed, images_txt, line_number,
                         outside + "; pass --allow_outside_paths to read it");
      }
    }
    frame.t_ns = ParseSecondsField(t_token, "t", images_txt, line_number);
    if (!frames.empty() && frame.t_ns <= frames.back().t_ns) {
      throw InputError(InputError::Kind::kNotMonotonic, images_txt, line_number,
                       "frame timestamps must increase strictly: " +
                           FormatDecimalSeconds(frame.t_ns, kMaxFractionDigits) + " s follows " +
                           FormatDecimalSeconds(frames.back().t_ns, kMaxFractionDigits) + " s");
    }
    const auto inserted = line_of_path.emplace(frame.path, line_number);
    if (!inserted.second) {
      throw InputError(InputError::Kind::kMalformed, images_txt, line_number,
                       "path '" + MessageExcerpt(frame.path) + "' is already listed on line " +
                           std::to_string(inserted.first->second));
    }
    frames.push_back(std::move(frame));
  });
  return frames;
}

void ReadExposures(const std::string& exposures_txt, std::vector<FrameInfo>* frames) {
  std::ifstream stream = OpenForReading(exposures_txt);
  ReadExposures(stream, exposures_txt, frames);
}

void ReadExposures(std::istream& stream, const std::string& exposures_txt,
                   std::vector<FrameInfo>* frames) {
  std::map<std::string, FrameInfo*> frame_of_path;
  for (FrameInfo& frame : *frames) frame_of_path[frame.path] = &frame;
  std::map<std::string, int64_t> line_of_path;
  ForEachContentLine(stream, [&](int64_t line_number, const std::string& content) {
    std::string rest;
    std::string path;
    std::string begin_token;
    std::string end_token;
    if (!SplitLast(content, &rest, &end_token) || !SplitLast(rest, &path, &begin_token) ||
        path.empty()) {
      throw InputError(InputError::Kind::kMalformed, exposures_txt, line_number,
                       "expected 'path t_start t_end', found '" + MessageExcerpt(content) + "'");
    }
    const int64_t begin_ns = ParseSecondsField(begin_token, "t_start", exposures_txt, line_number);
    const int64_t end_ns = ParseSecondsField(end_token, "t_end", exposures_txt, line_number);
    if (end_ns <= begin_ns) {
      throw InputError(InputError::Kind::kOutOfRange, exposures_txt, line_number,
                       "exposure must end after it starts (t_start " +
                           FormatDecimalSeconds(begin_ns, kMaxFractionDigits) + " s, t_end " +
                           FormatDecimalSeconds(end_ns, kMaxFractionDigits) + " s)");
    }
    const auto frame = frame_of_path.find(path);
    if (frame == frame_of_path.end()) {
      throw InputError(InputError::Kind::kMalformed, exposures_txt, line_number,
                       "image '" + MessageExcerpt(path) + "' is not listed in images.txt");
    }
    const auto inserted = line_of_path.emplace(path, line_number);
    if (!inserted.second) {
      throw InputError(InputError::Kind::kMalformed, exposures_txt, line_number,
                       "image '" + MessageExcerpt(path) + "' already has an exposure on line " +
                           std::to_string(inserted.first->second));
    }
    frame->second->has_exposure = true;
    frame->second->exposure_begin_ns = begin_ns;
    frame->second->exposure_end_ns = end_ns;
  });
}

void WriteFrameList(const std::string& images_txt, const std::vector<FrameInfo>& frames) {
  std::vector<int64_t> times;
  for (const FrameInfo& frame : frames) times.push_back(frame.t_ns);
  const int digits = MinimalFractionDigits(times);
  TextFileWriter writer(images_txt);
  for (const FrameInfo& frame : frames) {
    writer.Write(FormatDecimalSeconds(frame.t_ns, digits) + ' ' + frame.path + '\n');
  }
  writer.Close();
}

void WriteExposures(const std::string& exposures_txt, const std::vector<FrameInfo>& frames) {
  std::vector<int64_t> times;
  for (const FrameInfo& frame : frames) {
    if (!frame.has_exposure) continue;
    times.push_back(frame.exposure_begin_ns);
    times.push_back(frame.exposure_end_ns);
  }
  const int digits = MinimalFractionDigits(times);
  TextFileWriter writer(exposures_txt);
  writer.Write("# image t_exposure_start t_exposure_end (seconds, same clock as events.txt)\n");
  for (const FrameInfo& frame : frames) {
    if (!frame.has_exposure) continue;
    writer.Write(frame.path + ' ' + FormatDecimalSeconds(frame.exposure_begin_ns, digits) + ' ' +
                 FormatDecimalSeconds(frame.exposure_end_ns, digits) + '\n');
  }
  writer.Close();
}

}  // namespace evfs

// Typed errors for everything that is the user's fault: a bad file, a bad flag value, bad data.
// CHECK is kept for programmer errors; these exceptions are caught by the CLI and turned into
// one readable line and exit code 2.
#ifndef EVFS_CORE_ERROR_H_
#define EVFS_CORE_ERROR_H_

#include <cstdint>
#include <stdexcept>
#include <string>

namespace evfs {

/// Base class of every error evfs reports to a user.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A value given by the user (an option, a flag, an index) is outside what is accepted.
class InvalidArgumentError : public Error {
 public:
  explicit InvalidArgumentError(const std::string& message) : Error(message) {}
};

/// Something read from disk is missing or malformed. The message names the file and, where
/// there is one, the 1-based line, followed by what was expected:
///   "data/events.txt:12: expected 4 fields 't x y p', found 3"
class InputError : public Error {
 public:
  enum class Kind {
    kMissingFile,      // the file or folder does not exist or cannot be opened
    kMalformed,        // a line or record does not parse (field count, number, truncation)
    kOutOfRange,       // a value parses but is outside what is allowed (coordinates, polarity)
    kNotMonotonic,     // timestamps going backwards
    kSizeMismatch,     // an image of another size than the sensor
    kEmptyWindow,      // a requested time window or index range holds nothing
    kUnwritable,       // an output path cannot be written
  };

  /// `line` is 1-based; 0 means the error is about the file as a whole.
  InputError(Kind kind, std::string file, int64_t line, const std::string& expected);

  Kind kind() const { return kind_; }
  const std::string& file() const { return file_; }
  int64_t line() const { return line_; }

 private:
  Kind kind_;
  std::string file_;
  int64_t line_;
};

}  // namespace evfs

#endif  // EVFS_CORE_ERROR_H_

// Typed errors for everything that is the user's fault: a bad file, a bad flag value, bad data;
// and for a solver that fails on valid input. CHECK is kept for programmer errors. The CLI turns
// each into one readable line and an exit status that says whose the failure is (ExitStatus).
#ifndef EVFS_CORE_ERROR_H_
#define EVFS_CORE_ERROR_H_

#include <cstdint>
#include <stdexcept>
#include <string>

namespace evfs {

/// Exit statuses of the evfs command-line tool, by whose failure it is.
enum ExitStatus : int {
  kExitSuccess = 0,
  /// An exception evfs did not anticipate (out of memory, a file-system error): one line.
  kExitUnexpected = 1,
  /// The user's error: a bad flag, file, value or output path (InputError,
  /// InvalidArgumentError, a flag gflags cannot parse). One line naming what is wrong.
  kExitUserError = 2,
  /// A bug in evfs: a failed CHECK (or LOG(FATAL)), or a crash outside libhdf5. One line
  /// "internal error: ... please report" naming the check or the signal.
  kExitInternalError = 3,
  /// The solver failed on input that was accepted (SolverError): neither the user's fault nor
  /// a bug in evfs' own code, and the input may well solve with other settings.
  kExitSolverFailure = 4,
  // 128 + N: stopped by signal N (SIGINT, SIGTERM, SIGHUP), the unfinished output removed.
};

/// Base class of every error evfs reports to a user.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// The solver failed on a problem built from valid input: Ceres ended with FAILURE (a
/// non-finite cost or Jacobian, a linear solver that broke down). Reported with exit status
/// kExitSolverFailure, not as the user's error.
class SolverError : public Error {
 public:
  explicit SolverError(const std::string& message) : Error(message) {}
};

/// The caller asked a running job to stop (MethodOptions::interrupt, the Python module when
/// Ctrl-C arrives): the job ends at its next check, and nothing it was making is kept as if
/// complete.
class InterruptedError : public Error {
 public:
  explicit InterruptedError(const std::string& message = "interrupted") : Error(message) {}
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
    kMissingFile,   // the file or folder does not exist or cannot be opened
    kMalformed,     // a line or record does not parse (field count, number, truncation)
    kOutOfRange,    // a value parses but is outside what is allowed (coordinates, polarity)
    kNotMonotonic,  // timestamps going backwards
    kSizeMismatch,  // an image of another size than the sensor
    kEmptyWindow,   // a requested time window or index range holds nothing
    kUnwritable,    // an output path cannot be written
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

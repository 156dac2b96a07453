#include "evfs/core/error.h"

#include <utility>

namespace evfs {
namespace {

std::string FormatInputError(const std::string& file, int64_t line, const std::string& expected) {
  std::string message = file;
  if (line > 0) message += ":" + std::to_string(line);
  return message + ": " + expected;
}

}  // namespace

InputError::InputError(Kind kind, std::string file, int64_t line, const std::string& expected)
    : Error(FormatInputError(file, line, expected)),
      kind_(kind),
      file_(std::move(file)),
      line_(line) {}

}  // namespace evfs

#include "evfs/io/message_excerpt.h"

#include <algorithm>
#include <cstdio>

namespace evfs {
namespace {

bool IsControl(char c) {
  const unsigned char byte = static_cast<unsigned char>(c);
  return byte < 0x20 || byte == 0x7f;
}

}  // namespace

std::string MessageExcerpt(const char* begin, const char* end) {
  const size_t size = static_cast<size_t>(end - begin);
  const char* const cut = begin + std::min(size, kMaxExcerptBytes);
  std::string excerpt;
  for (const char* p = begin; p < cut; ++p) {
    if (IsControl(*p)) {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", static_cast<unsigned char>(*p));
      excerpt += escaped;
    } else {
      excerpt += *p;
    }
  }
  if (cut < end) excerpt += "... (" + std::to_string(size) + " bytes)";
  return excerpt;
}

std::string MessageExcerpt(const std::string& text) {
  return MessageExcerpt(text.data(), text.data() + text.size());
}

bool HasControlCharacter(const std::string& text) {
  return std::any_of(text.begin(), text.end(), IsControl);
}

}  // namespace evfs

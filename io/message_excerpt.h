// Input text quoted in error messages. A message is one line on a terminal, so a piece of a
// file is cut short and its control characters are escaped: a 1 MB line or binary garbage
// still gives a short, readable message.
#ifndef EVFS_IO_MESSAGE_EXCERPT_H_
#define EVFS_IO_MESSAGE_EXCERPT_H_

#include <cstddef>
#include <string>

namespace evfs {

/// The most bytes of input a message quotes.
constexpr size_t kMaxExcerptBytes = 40;

/// [begin, end) as a message may quote it: at most kMaxExcerptBytes, control characters
/// (bytes below 0x20, and 0x7f) written as \xNN, and "... (N bytes)" appended when cut.
std::string MessageExcerpt(const char* begin, const char* end);
std::string MessageExcerpt(const std::string& text);

/// True when `text` holds a control character (a byte below 0x20, or 0x7f).
bool HasControlCharacter(const std::string& text);

}  // namespace evfs

#endif  // EVFS_IO_MESSAGE_EXCERPT_H_

#include "evfs/io/message_excerpt.h"

#include <gtest/gtest.h>

#include <string>

namespace evfs {
namespace {

TEST(MessageExcerptTest, ShortPrintableTextIsKept) {
  EXPECT_EQ(MessageExcerpt("images/frame 1.png"), "images/frame 1.png");
  EXPECT_EQ(MessageExcerpt(""), "");
  // Bytes of UTF-8 names are not control characters.
  EXPECT_EQ(MessageExcerpt("caf\xc3\xa9.png"), "caf\xc3\xa9.png");
}

TEST(MessageExcerptTest, ControlCharactersAreEscaped) {
  EXPECT_EQ(MessageExcerpt(std::string("a\0b\x1b[2J\x7f", 8)), "a\\x00b\\x1b[2J\\x7f");
  EXPECT_TRUE(HasControlCharacter(std::string("a\0b", 3)));
  EXPECT_TRUE(HasControlCharacter("tab\there"));
  EXPECT_FALSE(HasControlCharacter("plain text, caf\xc3\xa9"));
}

TEST(MessageExcerptTest, LongTextIsCutAndItsLengthGiven) {
  const std::string text(1 << 20, '9');
  EXPECT_EQ(MessageExcerpt(text), std::string(kMaxExcerptBytes, '9') + "... (1048576 bytes)");
  const std::string exact(kMaxExcerptBytes, 'x');
  EXPECT_EQ(MessageExcerpt(exact), exact);
  EXPECT_EQ(MessageExcerpt(text.data(), text.data() + 3), "999");
}

}  // namespace
}  // namespace evfs

#include "evfs/denoiser/sha256.h"

#include <gtest/gtest.h>

#include <string>

namespace evfs {
namespace {

// FIPS 180-4's examples (one block, two blocks, a million 'a').
TEST(Sha256Test, StandardVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Lengths around the padding's block boundaries (55/56 bytes: the length still fits / spills
// into a second block; 64, 119, 120, 128), with golden values from Python's hashlib.
TEST(Sha256Test, PaddingBoundaries) {
  const auto message = [](int length) {
    std::string bytes;
    for (int i = 0; i < length; ++i) bytes += static_cast<char>((i * 7 + 3) % 256);
    return bytes;
  };
  EXPECT_EQ(Sha256Hex(message(55)),
            "e7313d333c272e639f790978283f9eb392e843d0f29b7016828bb1daa4aac70b");
  EXPECT_EQ(Sha256Hex(message(56)),
            "4324d65f3c103567f5589c710bc08f8523f929a9272e3af36fc968e52abc6c27");
  EXPECT_EQ(Sha256Hex(message(63)),
            "81c80242132f230c3bd41b3e63bbcff16107339549214a99614ff26664625055");
  EXPECT_EQ(Sha256Hex(message(64)),
            "39e3d7b6b5d075d37d053ad89b24b41bef4f3c29760c84447cab3f3be1882241");
  EXPECT_EQ(Sha256Hex(message(119)),
            "9ce7368e4daf32341631b492e80359dc9f594b48453cd0dd5bf0b19279cc177e");
  EXPECT_EQ(Sha256Hex(message(120)),
            "7836b787757e95e58b3ca5aec90b1b004e8deba1e50e9675af9cabf1a13a04b5");
  EXPECT_EQ(Sha256Hex(message(128)),
            "d2742f1f4ac6bb7ca2b239ee18402ba8b3f9f8e652d2a72973c2b9ba11c08cf6");
}

}  // namespace
}  // namespace evfs

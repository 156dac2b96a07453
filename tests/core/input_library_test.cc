#include "evfs/core/input_library.h"

#include <gtest/gtest.h>

#include <thread>

namespace evfs {
namespace {

const InputLibrary kFirst = {"libfirst", "some first files"};
const InputLibrary kSecond = {"libsecond", "some second files"};

TEST(ScopedInputLibraryRead, MarksTheCallingThreadOnlyAndNests) {
  EXPECT_EQ(InputLibraryOfThisThread(), nullptr);
  {
    const ScopedInputLibraryRead reading(kFirst);
    EXPECT_EQ(InputLibraryOfThisThread(), &kFirst);
    {
      const ScopedInputLibraryRead nested(kSecond);
      EXPECT_EQ(InputLibraryOfThisThread(), &kSecond);
    }
    EXPECT_EQ(InputLibraryOfThisThread(), &kFirst);
    const InputLibrary* on_other_thread = &kSecond;
    std::thread([&] { on_other_thread = InputLibraryOfThisThread(); }).join();
    EXPECT_EQ(on_other_thread, nullptr);
  }
  EXPECT_EQ(InputLibraryOfThisThread(), nullptr);
  // The last library run is remembered after it returned: a crash after it is "outside" it.
  EXPECT_EQ(LastInputLibrary(), &kSecond);
}

}  // namespace
}  // namespace evfs

#include "evfs/io/text_file_writer.h"

#include <gtest/gtest.h>

#include <string>

#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

TEST(TextFileWriterTest, WritesStringsAndReservedLinesInOrder) {
  const std::string path = test::ScratchDir("writer_order") + "/out.txt";
  TextFileWriter writer(path);
  writer.Write("# header\n");
  char* line = writer.Reserve();
  line[0] = '4';
  line[1] = '2';
  line[2] = '\n';
  writer.Commit(3);
  writer.Write("end\n");
  writer.Close();
  EXPECT_EQ(test::ReadFile(path), "# header\n42\nend\n");
}

TEST(TextFileWriterTest, LargeOutputSurvivesFlushes) {
  constexpr int kLines = 200000;  // several MiB: more than one flush
  const std::string path = test::ScratchDir("writer_large") + "/out.txt";
  std::string expected;
  TextFileWriter writer(path);
  for (int i = 0; i < kLines; ++i) {
    const std::string text = std::to_string(i) + "\n";
    expected += text;
    writer.Write(text);
  }
  writer.Close();
  EXPECT_EQ(test::ReadFile(path), expected);
}

TEST(TextFileWriterTest, UnwritablePathIsAnInputError) {
  const std::string path = test::ScratchDir("writer_unwritable") + "/no/such/folder/out.txt";
  test::ExpectInputError([&] { TextFileWriter writer(path); }, InputError::Kind::kUnwritable, path,
                         0);
}

}  // namespace
}  // namespace evfs

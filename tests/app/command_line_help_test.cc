#include "evfs/app/command_line_help.h"

#include <gflags/gflags.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/core/error.h"

// The flags of a small program, "tool", defined in this file like evfs' in evfs_main.cc.
DEFINE_string(help_test_path, "", "Where the tool reads from.");
DEFINE_double(help_test_rate_hz, 0.2, "Rate of the tool, in hertz.");
DEFINE_double(help_test_factor, 10.0, "A factor.");
DEFINE_int32(help_test_count, 3,
             "How many times the tool does it; a long description that the help must wrap "
             "so that no line is longer than a hundred columns, at a space between two words.");
DEFINE_bool(help_test_verbose, false, "Say more.");
DEFINE_bool(help_test_unlisted, false, "A flag that nobody gave a row.");

namespace evfs {
namespace {

// "tool read" and "tool write"; --help_test_unlisted has no row, as a forgotten flag would.
ProgramHelp ToolHelp() {
  ProgramHelp help;
  help.program = "tool";
  help.summary = "a tool for tests.";
  help.version = "1.2.3";
  help.flags_file = "command_line_help_test.cc";
  help.commands = {{"read", "--path=P [--count=N]", "Read P."},
                   {"write", "--path=P --rate_hz=R", "Write P."}};
  help.groups = {"input", "rate", "general"};
  help.notes = "P is a path.";
  help.flags = {{"help_test_path", "input", "read write"},
                {"help_test_count", "input", "read"},
                {"help_test_rate_hz", "rate", "write"},
                {"help_test_factor", "rate", "write"},
                {"help_test_verbose", "general", "*"}};
  return help;
}

ProgramHelp CompleteToolHelp() {
  ProgramHelp help = ToolHelp();
  help.flags.push_back({"help_test_unlisted", "general", "read"});
  return help;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

TEST(CommandLineHelp, UsageAlignsTheCommands) {
  EXPECT_EQ(UsageLines(ToolHelp()),
            "usage:\n"
            "  tool read  --path=P [--count=N]\n"
            "  tool write --path=P --rate_hz=R\n");
}

TEST(CommandLineHelp, OverviewListsCommandsThenFlagsByGroup) {
  const std::string text = ProgramHelpText(CompleteToolHelp());
  EXPECT_EQ(text.rfind("tool 1.2.3: a tool for tests.\n\nusage:\n", 0), 0u) << text;
  EXPECT_TRUE(Contains(text, "commands:\n  read   Read P.\n  write  Write P.\n")) << text;
  EXPECT_TRUE(Contains(text, "\nP is a path.\n")) << text;
  EXPECT_TRUE(Contains(text,
                       "input flags:\n"
                       "  --help_test_path (string, default: \"\") [read write]\n"
                       "      Where the tool reads from.\n"))
      << text;
  // The shortest decimal of a double default, not gflags' 17 digits.
  EXPECT_TRUE(Contains(text, "  --help_test_rate_hz (double, default: 0.2) [write]\n")) << text;
  EXPECT_TRUE(Contains(text, "  --help_test_factor (double, default: 10) [write]\n")) << text;
  EXPECT_TRUE(Contains(text, "  --help_test_verbose (bool, default: false) [every command]\n"))
      << text;
  // Groups in the table's order.
  const size_t input = text.find("input flags:"), rate = text.find("rate flags:"),
               general = text.find("general flags:");
  ASSERT_NE(input, std::string::npos);
  EXPECT_LT(input, rate);
  EXPECT_LT(rate, general);
  // Only this program's flags: not gflags' own, nor glog's.
  EXPECT_FALSE(Contains(text, "--flagfile")) << text;
  EXPECT_FALSE(Contains(text, "other flags:")) << text;
  EXPECT_FALSE(Contains(text, kHelpTableProblems)) << text;
}

TEST(CommandLineHelp, LongDescriptionsAreWrappedAtWordsWithin100Columns) {
  const std::string text = ProgramHelpText(CompleteToolHelp());
  for (const std::string& line : Lines(text)) EXPECT_LE(line.size(), 100u) << line;
  // The description's lines, indented under the flag, read back as the description.
  const std::vector<std::string> lines = Lines(text);
  const auto heading = std::find_if(lines.begin(), lines.end(), [](const std::string& line) {
    return line.rfind("  --help_test_count ", 0) == 0;
  });
  ASSERT_NE(heading, lines.end()) << text;
  std::string description;
  int num_lines = 0;
  for (auto line = heading + 1; line != lines.end() && line->rfind("      ", 0) == 0; ++line) {
    description += (description.empty() ? "" : " ") + line->substr(6);
    ++num_lines;
  }
  EXPECT_EQ(num_lines, 2);
  gflags::CommandLineFlagInfo info;
  ASSERT_TRUE(gflags::GetCommandLineFlagInfo("help_test_count", &info));
  EXPECT_EQ(description, info.description);
}

TEST(CommandLineHelp, CommandHelpShowsOnlyTheFlagsItReads) {
  const std::string write = CommandHelpText(CompleteToolHelp(), "write");
  EXPECT_EQ(write.rfind("tool write: Write P.\n\nusage:\n  tool write --path=P --rate_hz=R\n", 0),
            0u)
      << write;
  EXPECT_TRUE(Contains(write, "--help_test_path (string, default: \"\")\n")) << write;
  EXPECT_TRUE(Contains(write, "--help_test_rate_hz")) << write;
  EXPECT_TRUE(Contains(write, "--help_test_verbose")) << write;  // "*": every command
  EXPECT_FALSE(Contains(write, "--help_test_count")) << write;   // read's only
  EXPECT_FALSE(Contains(write, "--help_test_unlisted")) << write;
  EXPECT_FALSE(Contains(write, "commands:")) << write;

  const std::string read = CommandHelpText(CompleteToolHelp(), "read");
  EXPECT_TRUE(Contains(read, "--help_test_count")) << read;
  EXPECT_FALSE(Contains(read, "--help_test_rate_hz")) << read;
  EXPECT_FALSE(Contains(read, "rate flags:")) << read;  // a group with none of its flags
}

TEST(CommandLineHelp, UnknownCommandIsAUserError) {
  EXPECT_FALSE(IsCommand(ToolHelp(), "frobnicate"));
  EXPECT_TRUE(IsCommand(ToolHelp(), "read"));
  try {
    CommandHelpText(ToolHelp(), "frobnicate");
    ADD_FAILURE() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_TRUE(Contains(error.what(), "unknown command 'frobnicate'")) << error.what();
  }
}

TEST(CommandLineHelp, FlagWithoutRowIsShownAndReported) {
  const ProgramHelp help = ToolHelp();
  const std::string text = ProgramHelpText(help);
  EXPECT_TRUE(Contains(text, "other flags:\n  --help_test_unlisted (bool, default: false)\n"))
      << text;
  EXPECT_TRUE(Contains(text, kHelpTableProblems)) << text;
  const std::vector<std::string> problems = CheckHelpTables(help);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(Contains(problems[0], "--help_test_unlisted")) << problems[0];
  EXPECT_TRUE(Contains(problems[0], "no row")) << problems[0];
}

TEST(CommandLineHelp, CheckHelpTablesFindsEveryWrongRow) {
  EXPECT_TRUE(CheckHelpTables(CompleteToolHelp()).empty());
  const std::vector<std::pair<FlagHelp, std::string>> cases = {
      {{"help_test_pth", "input", "read"}, "a row for no such flag"},
      {{"help_test_path", "input", "read"}, "two rows"},
      {{"help_test_count", "output", "read"}, "no group 'output'"},
      {{"help_test_count", "input", "read delete"}, "no command 'delete'"},
      {{"help_test_count", "input", ""}, "read by no command"},
  };
  for (const auto& [row, expected] : cases) {
    SCOPED_TRACE(expected);
    ProgramHelp help = CompleteToolHelp();
    if (row.flag != "help_test_path") {
      // Replaces the row of the same flag, or adds one for an unknown flag.
      help.flags.erase(
          std::remove_if(help.flags.begin(), help.flags.end(),
                         [&](const FlagHelp& other) { return other.flag == row.flag; }),
          help.flags.end());
    }
    help.flags.push_back(row);
    const std::vector<std::string> problems = CheckHelpTables(help);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_TRUE(Contains(problems[0], expected)) << problems[0];
    // A row naming no flag shows nothing in the help, but the problem is at its end.
    EXPECT_TRUE(Contains(ProgramHelpText(help), expected));
  }
}

}  // namespace
}  // namespace evfs

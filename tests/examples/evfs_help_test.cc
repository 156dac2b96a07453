// `evfs --help`, `evfs COMMAND --help` and `evfs --version`, run as a user runs them.
#include "evfs/app/evfs_help.h"

#include <gtest/gtest.h>

#include <string>

#include "evfs/app/command_line_help.h"
#include "evfs/app/version_report.h"
#include "evfs/core/version.h"
#include "evfs/tests/examples/cli_test_util.h"

namespace evfs {
namespace {

using test::CommandResult;
using test::RunEvfs;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(EvfsHelp, OverviewShowsCommandsAndEvfsFlagsByGroup) {
  const CommandResult result = RunEvfs("--help");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_EQ(result.errors, "");
  const std::string& text = result.output;
  EXPECT_EQ(text.rfind(std::string("evfs ") + kVersion + ": ", 0), 0u) << text;
  for (const CommandHelp& command : EvfsHelp().commands) {
    EXPECT_TRUE(Contains(text, "\n  evfs " + command.name + " ")) << command.name;
    EXPECT_TRUE(Contains(text, "\n  " + command.name + "  ")) << command.name;
  }
  // The groups the issue names, in the table's order, before anything else.
  size_t previous = 0;
  for (const std::string& group : EvfsHelp().groups) {
    const size_t at = text.find("\n" + group + " flags:\n");
    ASSERT_NE(at, std::string::npos) << group;
    EXPECT_GT(at, previous) << group;
    previous = at;
  }
  for (const char* flag : {"--data ", "--out ", "--solver ", "--event_weight ", "--linear_solver ",
                           "--threshold_pos ", "--progress_interval_s "}) {
    EXPECT_TRUE(Contains(text, std::string("\n  ") + flag)) << flag;
  }
  // Not glog's and gflags' pages of flags.
  for (const char* flag : {"logtostderr", "minloglevel", "flagfile", "tryfromenv"}) {
    EXPECT_FALSE(Contains(text, flag)) << flag;
  }
  // Every flag of evfs_main.cc has its row (the option table, app/evfs_options.cc), and every
  // row a flag.
  EXPECT_FALSE(Contains(text, "\nother flags:\n")) << text.substr(text.find("\nother flags:"));
  EXPECT_FALSE(Contains(text, kHelpTableProblems)) << text.substr(text.find(kHelpTableProblems));
}

TEST(EvfsHelp, EveryCommandHasAHelpOfItsOwn) {
  for (const CommandHelp& command : EvfsHelp().commands) {
    SCOPED_TRACE(command.name);
    for (const std::string& arguments : {command.name + " --help", "--help " + command.name}) {
      const CommandResult result = RunEvfs(arguments);
      EXPECT_EQ(result.exit_code, 0);
      EXPECT_EQ(result.errors, "");
      EXPECT_EQ(result.output.rfind("evfs " + command.name + ": ", 0), 0u) << result.output;
      EXPECT_TRUE(Contains(result.output, "\nusage:\n  evfs " + command.name + " "))
          << result.output;
      EXPECT_FALSE(Contains(result.output, "\ncommands:\n")) << result.output;
    }
  }
}

TEST(EvfsHelp, CommandHelpShowsTheFlagsTheCommandReads) {
  const CommandResult reconstruct = RunEvfs("reconstruct --help");
  for (const char* flag : {"--data ", "--mode ", "--solver ", "--binning ", "--event_weight ",
                           "--linear_solver ", "--progress_interval_s "}) {
    EXPECT_TRUE(Contains(reconstruct.output, std::string("\n  ") + flag)) << flag;
  }
  for (const char* flag : {"--frames ", "--threshold_pos ", "--seed "}) {
    EXPECT_FALSE(Contains(reconstruct.output, flag)) << flag;
  }

  const CommandResult simulate = RunEvfs("simulate --help");
  for (const char* flag : {"--frames ", "--out ", "--threshold_pos ", "--seed "}) {
    EXPECT_TRUE(Contains(simulate.output, std::string("\n  ") + flag)) << flag;
  }
  for (const char* flag : {"--data ", "--solver ", "--linear_solver ", "--binning "}) {
    EXPECT_FALSE(Contains(simulate.output, flag)) << flag;
  }

  const CommandResult convert = RunEvfs("convert --help");
  EXPECT_TRUE(Contains(convert.output, "\n  --data ")) << convert.output;
  EXPECT_FALSE(Contains(convert.output, "model flags:")) << convert.output;
}

TEST(EvfsHelp, HelpOnAnUnknownCommandIsAUserError) {
  const CommandResult result = RunEvfs("frobnicate --help");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_EQ(result.errors, "evfs: unknown command 'frobnicate' (evfs --help lists the commands)\n");
  EXPECT_EQ(result.output, result.errors) << "printed on stdout too";

  const CommandResult run = RunEvfs("frobnicate");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(Contains(run.errors, "unknown command 'frobnicate'")) << run.errors;
}

TEST(EvfsHelp, HelpfullAddsTheLibrariesFlags) {
  const CommandResult result = RunEvfs("--helpfull");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_TRUE(Contains(result.output, "usage:")) << result.output;
  EXPECT_TRUE(Contains(result.output, "-logtostderr")) << result.output;
  EXPECT_TRUE(Contains(result.output, "-threshold_pos")) << result.output;
}

TEST(EvfsVersion, PrintsTheVersionAndTheLibraries) {
  const CommandResult result = RunEvfs("--version");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_EQ(result.errors, "");
  EXPECT_EQ(result.output.rfind(std::string("evfs ") + kVersion + "\n", 0), 0u) << result.output;
  for (const char* name : {"Ceres Solver", "OpenCV", "HDF5", "Eigen", "LZ4", "Zstandard"}) {
    EXPECT_TRUE(Contains(result.output, std::string("\n  ") + name + " ")) << result.output;
  }
  // The binary reports what the library it was linked with reports.
  EXPECT_EQ(result.output, VersionReport());
}

}  // namespace
}  // namespace evfs

// The help of a program made of commands (`evfs COMMAND --flags`), from tables rather than
// gflags' file-by-file listing, which puts glog's and gflags' own pages of flags before the
// program's and does not know which command reads which flag.
//
//   evfs --help              the commands, then every flag of the table, group by group
//   evfs reconstruct --help  that command's synopsis, then only the flags it reads
//
// A flag's type, default and description come from gflags (evfs registers its flags from its
// option table, app/evfs_options.h, which also makes its FlagHelp rows); the tables say only
// where it goes. A new command gets one CommandHelp row.
#ifndef EVFS_APP_COMMAND_LINE_HELP_H_
#define EVFS_APP_COMMAND_LINE_HELP_H_

#include <string>
#include <vector>

namespace evfs {

/// A command of the program.
struct CommandHelp {
  std::string name;      // "reconstruct"
  std::string synopsis;  // its flags in short: "--data=DIR --mode=... --out=OUT"
  std::string summary;   // one sentence: what it does
};

/// Where a flag goes in the help.
struct FlagHelp {
  std::string flag;   // its gflags name, without dashes: "data"
  std::string group;  // one of ProgramHelp::groups
  /// The commands that read it, separated by spaces ("info reconstruct"); "*" for all.
  std::string commands;
};

/// What a program's help is made of.
struct ProgramHelp {
  std::string program;  // "evfs"
  std::string summary;  // the first line, after "PROGRAM VERSION: "
  std::string version;  // "0.1.0"
  std::vector<CommandHelp> commands;
  /// Flag groups in the order they are shown ("data", "output", "method", ...).
  std::vector<std::string> groups;
  std::vector<FlagHelp> flags;
  /// Shown after the commands of the overview (what the arguments mean, an example).
  std::string notes;
  /// Where the program's own flags are defined (the end of gflags' file name: the __FILE__ of
  /// the program's flags were registered with): those without a row are shown under "other"
  /// rather than left out.
  std::string flags_file;
};

/// The heading under which ProgramHelpText lists CheckHelpTables' problems.
inline constexpr char kHelpTableProblems[] = "problems in the help tables";

/// The usage lines: "usage: PROGRAM COMMAND [flags]" and one line per command with its
/// synopsis (also gflags' usage message, which --helpfull shows).
std::string UsageLines(const ProgramHelp& help);

/// `PROGRAM --help`: summary, usage, commands, notes, then every flag of the table by group,
/// each with the commands that read it, and where the libraries' flags are.
std::string ProgramHelpText(const ProgramHelp& help);

/// `PROGRAM COMMAND --help`: the command's summary and synopsis, then the flags it reads by
/// group. Throws InvalidArgumentError for a command that is not in the table.
std::string CommandHelpText(const ProgramHelp& help, const std::string& command);

/// Whether `command` is one of the table's.
bool IsCommand(const ProgramHelp& help, const std::string& command);

/// Problems with the tables, each a line: a row for a flag gflags does not know, a row whose
/// group or command is not in the tables, a flag of `flags_file` without a row. Empty when
/// none. ProgramHelpText ends with them (under kHelpTableProblems), so that a test of the
/// program's --help catches a forgotten row; a flag without a row is shown under "other".
std::vector<std::string> CheckHelpTables(const ProgramHelp& help);

}  // namespace evfs

#endif  // EVFS_APP_COMMAND_LINE_HELP_H_

#include "evfs/app/command_line_help.h"

#include <gflags/gflags.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>

#include "evfs/core/error.h"

namespace evfs {
namespace {

// Lines are wrapped to this many columns (a terminal of 100, as the sources).
constexpr size_t kLineWidth = 100;
// A flag's description is indented under its name by this much.
constexpr char kDescriptionIndent[] = "      ";

// `text` in lines of at most kLineWidth columns (a longer word stands alone), the first starting
// with `first_prefix`, the others with `prefix`; every line ends with '\n'.
std::string Wrap(const std::string& text, const std::string& first_prefix,
                 const std::string& prefix) {
  std::istringstream words(text);
  std::string out, line = first_prefix;
  bool line_has_word = false;
  for (std::string word; words >> word;) {
    if (line_has_word && line.size() + 1 + word.size() > kLineWidth) {
      out += line + "\n";
      line = prefix;
      line_has_word = false;
    }
    if (line_has_word) line += " ";
    line += word;
    line_has_word = true;
  }
  return out + line + "\n";
}

std::vector<std::string> Words(const std::string& text) {
  std::istringstream stream(text);
  std::vector<std::string> words;
  for (std::string word; stream >> word;) words.push_back(word);
  return words;
}

bool ReadsFlag(const FlagHelp& row, const std::string& command) {
  if (row.commands == "*") return true;
  const std::vector<std::string> commands = Words(row.commands);
  return std::find(commands.begin(), commands.end(), command) != commands.end();
}

bool EndsWith(const std::string& text, const std::string& suffix) {
  return !suffix.empty() && text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::map<std::string, gflags::CommandLineFlagInfo> FlagsByName() {
  std::vector<gflags::CommandLineFlagInfo> flags;
  gflags::GetAllFlags(&flags);
  std::map<std::string, gflags::CommandLineFlagInfo> by_name;
  for (gflags::CommandLineFlagInfo& info : flags) by_name[info.name] = std::move(info);
  return by_name;
}

// gflags keeps a double's default with 17 digits ("0.20000000000000001"); shown is the shortest
// text that reads back as the same number ("0.2", "10" rather than "1e+01").
std::string ShowDefault(const gflags::CommandLineFlagInfo& info) {
  if (info.type == "string") return "\"" + info.default_value + "\"";
  if (info.type != "double") return info.default_value;
  const double value = std::strtod(info.default_value.c_str(), nullptr);
  std::string shortest = info.default_value;
  for (int digits = 1; digits <= 17; ++digits) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value && std::strlen(text) < shortest.size()) shortest = text;
  }
  return shortest;
}

// "  --name (type, default: value)[ note]" and the description wrapped under it.
std::string FlagEntry(const gflags::CommandLineFlagInfo& info, const std::string& note) {
  std::string heading = "  --" + info.name + " (" + info.type + ", default: " + ShowDefault(info) +
                        ")" + (note.empty() ? "" : " " + note) + "\n";
  return heading + Wrap(info.description, kDescriptionIndent, kDescriptionIndent);
}

// The flags of the table read by `command` ("" for every command), group by group; in the
// overview each names the commands that read it. Then the flags of help.flags_file without a
// row, under "other".
std::string FlagSections(const ProgramHelp& help, const std::string& command) {
  const std::map<std::string, gflags::CommandLineFlagInfo> flags = FlagsByName();
  std::string text;
  for (const std::string& group : help.groups) {
    std::string entries;
    for (const FlagHelp& row : help.flags) {
      const auto info = flags.find(row.flag);
      if (row.group != group || info == flags.end()) continue;
      if (!command.empty() && !ReadsFlag(row, command)) continue;
      std::string note;
      if (command.empty())
        note = row.commands == "*" ? "[every command]" : "[" + row.commands + "]";
      entries += FlagEntry(info->second, note);
    }
    if (!entries.empty()) text += "\n" + group + " flags:\n" + entries;
  }
  std::set<std::string> with_row;
  for (const FlagHelp& row : help.flags) with_row.insert(row.flag);
  std::string others;
  for (const auto& [name, info] : flags) {
    if (!help.flags_file.empty() && EndsWith(info.filename, help.flags_file) &&
        !with_row.count(name)) {
      others += FlagEntry(info, "");
    }
  }
  if (!others.empty()) text += "\nother flags:\n" + others;
  return text;
}

const CommandHelp* FindCommand(const ProgramHelp& help, const std::string& command) {
  for (const CommandHelp& entry : help.commands) {
    if (entry.name == command) return &entry;
  }
  return nullptr;
}

// "  PROGRAM NAME  SYNOPSIS", the name padded to `name_width` and the synopsis wrapped under
// itself.
std::string UsageLine(const ProgramHelp& help, const CommandHelp& command, size_t name_width) {
  std::string first = "  " + help.program + " " + command.name;
  first.resize(first.size() + name_width - command.name.size() + 1, ' ');
  return Wrap(command.synopsis, first, std::string(first.size(), ' '));
}

size_t LongestCommandName(const ProgramHelp& help) {
  size_t width = 0;
  for (const CommandHelp& command : help.commands) width = std::max(width, command.name.size());
  return width;
}

}  // namespace

std::string UsageLines(const ProgramHelp& help) {
  std::string text = "usage:\n";
  const size_t width = LongestCommandName(help);
  for (const CommandHelp& command : help.commands) text += UsageLine(help, command, width);
  return text;
}

std::string ProgramHelpText(const ProgramHelp& help) {
  std::string text = help.program + " " + help.version + ": " + help.summary + "\n\n";
  text += UsageLines(help) + "\ncommands:\n";
  const size_t width = LongestCommandName(help);
  for (const CommandHelp& command : help.commands) {
    std::string name = "  " + command.name;
    name.resize(2 + width + 2, ' ');
    text += Wrap(command.summary, name, std::string(name.size(), ' '));
  }
  if (!help.notes.empty()) text += "\n" + help.notes + (help.notes.back() == '\n' ? "" : "\n");
  text += "\n" + Wrap("Run '" + help.program + " COMMAND --help' for the flags of one command, '" +
                          help.program + " --helpfull' for these and the libraries' flags (glog, " +
                          "gflags), '" + help.program + " --version' for the versions.",
                      "", "");
  text += FlagSections(help, "");
  const std::vector<std::string> problems = CheckHelpTables(help);
  if (!problems.empty()) {
    text += "\n" + std::string(kHelpTableProblems) + " (a bug of " + help.program + "):\n";
    for (const std::string& problem : problems) text += "  " + problem + "\n";
  }
  return text;
}

std::string CommandHelpText(const ProgramHelp& help, const std::string& command) {
  const CommandHelp* entry = FindCommand(help, command);
  if (entry == nullptr) {
    throw InvalidArgumentError("unknown command '" + command + "' (" + help.program +
                               " --help lists the commands)");
  }
  std::string text = Wrap(entry->summary, help.program + " " + command + ": ", "") + "\nusage:\n";
  text += UsageLine(help, *entry, command.size());
  return text + FlagSections(help, command);
}

bool IsCommand(const ProgramHelp& help, const std::string& command) {
  return FindCommand(help, command) != nullptr;
}

std::vector<std::string> CheckHelpTables(const ProgramHelp& help) {
  const std::map<std::string, gflags::CommandLineFlagInfo> flags = FlagsByName();
  std::vector<std::string> problems;
  std::set<std::string> with_row;
  for (const FlagHelp& row : help.flags) {
    if (!with_row.insert(row.flag).second) problems.push_back("--" + row.flag + ": two rows");
    if (!flags.count(row.flag)) problems.push_back("--" + row.flag + ": a row for no such flag");
    if (std::find(help.groups.begin(), help.groups.end(), row.group) == help.groups.end()) {
      problems.push_back("--" + row.flag + ": no group '" + row.group + "'");
    }
    if (row.commands == "*") continue;
    const std::vector<std::string> commands = Words(row.commands);
    if (commands.empty()) problems.push_back("--" + row.flag + ": read by no command");
    for (const std::string& command : commands) {
      if (!IsCommand(help, command)) {
        problems.push_back("--" + row.flag + ": no command '" + command + "'");
      }
    }
  }
  for (const auto& [name, info] : flags) {
    if (!help.flags_file.empty() && EndsWith(info.filename, help.flags_file) &&
        !with_row.count(name)) {
      problems.push_back("--" + name + " (" + info.filename + "): no row in the help table");
    }
  }
  return problems;
}

}  // namespace evfs

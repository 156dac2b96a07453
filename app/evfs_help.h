// The tables of `evfs --help` (app/command_line_help.h): the commands, the flag groups and, for
// every flag of examples/evfs_main.cc, its group and the commands that read it. A new flag or
// command is one row here.
#ifndef EVFS_APP_EVFS_HELP_H_
#define EVFS_APP_EVFS_HELP_H_

#include "app/command_line_help.h"

namespace evfs {

/// The help tables of the `evfs` program.
const ProgramHelp& EvfsHelp();

}  // namespace evfs

#endif  // EVFS_APP_EVFS_HELP_H_

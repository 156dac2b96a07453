// The tables of `evfs --help` (app/command_line_help.h): the commands here, the flag groups and
// flag rows from the option table (app/evfs_options.h). A new command is one row here, a new
// flag one row of the option table.
#ifndef EVFS_APP_EVFS_HELP_H_
#define EVFS_APP_EVFS_HELP_H_

#include "evfs/app/command_line_help.h"

namespace evfs {

/// The help tables of the `evfs` program.
const ProgramHelp& EvfsHelp();

}  // namespace evfs

#endif  // EVFS_APP_EVFS_HELP_H_

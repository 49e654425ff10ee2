// Subcommands of the `geomip` program. Each add_* registers its options on the parent app and returns the
// function that runs it (called by main after a successful parse, inside main's error mapping).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace geomip::tools {

/// Process exit codes of every geomip command.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,   ///< geomip's own failure (solver, I/O on output, a bug)
  kExitBadInput = 2,  ///< the input or the command line is wrong; the message says how
};

using CommandRunner = std::function<int()>;

CommandRunner add_info_command(CLI::App& app);
CommandRunner add_repair_command(CLI::App& app);
CommandRunner add_param_command(CLI::App& app);
CommandRunner add_gimage_command(CLI::App& app);
CommandRunner add_remesh_command(CLI::App& app);
CommandRunner add_eval_command(CLI::App& app);
CommandRunner add_convert_command(CLI::App& app);
CommandRunner add_encode_command(CLI::App& app);
CommandRunner add_decode_command(CLI::App& app);
CommandRunner add_rd_command(CLI::App& app);
CommandRunner add_morph_command(CLI::App& app);

}  // namespace geomip::tools

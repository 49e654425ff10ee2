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

/// Option checks that say what is wrong (CLI11's NonNegativeNumber and PositiveNumber print their range as
/// "0.000000 to 1.79…e308", and PositiveNumber calls 0 in range): "must be >= 0" / "must be > 0".
inline CLI::Validator non_negative_number() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(value, v)) return "'" + value + "' is not a number";
        return v >= 0 ? "" : "must be >= 0, got " + value;
      },
      "NONNEGATIVE");
}
inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(value, v)) return "'" + value + "' is not a number";
        return v > 0 ? "" : "must be > 0, got " + value;
      },
      "POSITIVE");
}

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

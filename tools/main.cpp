// geomip: consistent geometry images from triangle meshes. This file maps every failure to one line on
// stderr and an exit code: 2 for bad input or usage, 1 for geomip's own failures.
#include "codec/status.h"
#include "mesh/errors.h"
#include "tools/commands.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace {

// CLI11 names a negated flag's value in the help ("--fit,--no-fit{false}"): the names alone are what a user
// types.
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_option_name(const CLI::Option* opt, bool is_positional) const override {
    const std::string name = CLI::Formatter::make_option_name(opt, is_positional);
    std::string out;
    int depth = 0;
    for (const char c : name) {
      if (c == '{') ++depth;
      if (depth == 0) out += c;
      if (c == '}' && depth > 0) --depth;
    }
    return out;
  }
};

}  // namespace

int main(int argc, char** argv) {
  using namespace geomip::tools;
  CLI::App app{"geomip — consistent geometry images from triangle meshes, streamed.\n"
               "Exit codes: 0 ok, 1 internal failure, 2 bad input or usage.",
               "geomip"};
  app.require_subcommand(1);
  app.formatter(std::make_shared<HelpFormatter>());  // subcommands added below share it
  app.set_version_flag("--version", "geomip 0.1.0");

  struct Entry {
    CLI::App* cmd;
    CommandRunner run;
  };
  std::vector<Entry> commands;
  auto add = [&](CommandRunner run) { commands.push_back({app.get_subcommands({}).back(), std::move(run)}); };
  add(add_info_command(app));
  add(add_repair_command(app));
  add(add_param_command(app));
  add(add_gimage_command(app));
  add(add_remesh_command(app));
  add(add_eval_command(app));
  add(add_convert_command(app));
  add(add_encode_command(app));
  add(add_decode_command(app));
  add(add_rd_command(app));
  add(add_morph_command(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e) == 0 ? kExitOk : kExitBadInput;  // --help, --version
    // A word where the command goes: CLI11 only says that a subcommand is required.
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands().empty()) {
      std::string names;
      for (const CLI::App* c : app.get_subcommands([](CLI::App*) { return true; }))
        names += (names.empty() ? "" : ", ") + c->get_name();
      std::cerr << "geomip: unknown command '" << geomip::codec::one_line(argv[1]) << "' (commands: " << names
                << "; see --help)\n";
      return kExitBadInput;
    }
    std::cerr << "geomip: " << geomip::codec::one_line(e.what())
              << " (see --help)\n";  // one line, as every error
    return kExitBadInput;
  }

  for (const auto& c : commands) {
    if (!c.cmd->parsed()) continue;
    const std::string name = "geomip " + c.cmd->get_name();
    try {
      const int code = c.run();
      // A report that did not reach its reader (a full disk, /dev/full, a closed pipe) is a failed run: the
      // caller would read a truncated JSON as the answer.
      errno = 0;
      std::cout.flush();
      if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
        const int error = errno;
        std::cerr << name << ": cannot write to standard output"
                  << (error != 0 ? std::string(" (") + std::strerror(error) + ")" : std::string()) << "\n";
        return code != kExitOk ? code : kExitFailure;
      }
      return code;
    } catch (const geomip::InvalidInput& e) {
      std::cerr << name << ": " << geomip::codec::one_line(e.what()) << "\n";
      return kExitBadInput;
    } catch (const geomip::IoError& e) {
      std::cerr << name << ": " << geomip::codec::one_line(e.what()) << "\n";
      return kExitFailure;
    } catch (const geomip::SolverFailure& e) {
      std::cerr << name << ": internal failure: " << geomip::codec::one_line(e.what()) << "\n";
      return kExitFailure;
    } catch (const std::bad_alloc&) {
      std::cerr << name << ": out of memory\n";
      return kExitFailure;
    } catch (const std::exception& e) {
      std::cerr << name << ": unexpected error: " << geomip::codec::one_line(e.what()) << "\n";
      return kExitFailure;
    }
  }
  return kExitBadInput;
}

// The seam command-line tool: every subcommand registers itself in command_registry.h; main only builds the
// CLI11 application, parses, and maps errors to exit codes (0 ok, 1 geometry problem, 2 bad usage or input).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/version.h"

int main(int argc, char** argv) {
  using seam::cli::kExitBadInput;
  seam::cli::startRunTimeLimit();  // the default limit from now; --time-limit moves or removes it
  try {
    CLI::App app{"seam: geometric continuity of spline surfaces", "seam"};
    app.set_version_flag("--version", std::string("seam ") + seam::kVersion, "Print the version and exit");
    app.require_subcommand(1);
    app.footer(
        "Exit codes: 0 success, 1 a problem was found in the geometry, 2 bad usage or invalid input.\n"
        "Run 'seam <command> --help' for the options of a command. --time-limit and --digits work with every command.\n");

    std::vector<seam::cli::CommandEntry> commands = seam::cli::commandRegistry();
    std::sort(
        commands.begin(), commands.end(),
        [](const seam::cli::CommandEntry& a, const seam::cli::CommandEntry& b) { return a.name < b.name; });
    seam::cli::addTimeLimitOption(app);  // before the commands: they inherit its fall-through
    seam::cli::addDigitsOption(app);
    int exitCode = seam::cli::kExitOk;
    for (const seam::cli::CommandEntry& command : commands) command.add(app, exitCode);

    try {
      app.parse(argc, argv);
    } catch (const CLI::Success& e) {  // --help, --help-all, --version
      return app.exit(e);
    } catch (const CLI::ParseError& e) {
      std::cout.flush();
      // "seam xyz": CLI11 says only "A subcommand is required"; name the word and list the commands.
      if (argc > 1 && argv[1][0] != '-' &&
          std::none_of(commands.begin(), commands.end(),
                       [&](const seam::cli::CommandEntry& c) { return c.name == argv[1]; })) {
        std::string names;
        for (const seam::cli::CommandEntry& c : commands) names += (names.empty() ? "" : ", ") + c.name;
        std::cerr << "seam: error: unknown command '" << argv[1] << "' (the commands are: " << names
                  << ")\nRun 'seam --help' for usage.\n";
        return kExitBadInput;
      }
      std::cerr << "seam: error: " << e.what()
                << "\nRun 'seam --help' or 'seam <command> --help' for usage.\n";
      return kExitBadInput;
    }
    return exitCode;
  } catch (const std::bad_alloc&) {
    // Written without allocating (memory may still be short): the file and the stage, then the problem.
    std::fflush(stdout);
    const std::string& where = seam::cli::activity();
    std::fputs("seam: error: ", stderr);
    if (!where.empty()) {
      std::fputs(where.c_str(), stderr);
      std::fputs(": ", stderr);
    }
    std::fputs("out of memory (the input is too large for the memory this process may use)\n", stderr);
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cout.flush();
    std::cerr << "seam: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (...) {
    std::cout.flush();
    std::cerr << "seam: error: unknown internal error\n";
    return kExitBadInput;
  }
}

#pragma once
// Every subcommand lives in its own apps/seam/cmd_<name>.cpp and registers itself here with a static
// CommandRegistrar, so that adding a command never edits main.cpp:
//
//   namespace { void addInfo(CLI::App& app, seam::cli::ExitCode& exit) { ... } }
//   static seam::cli::CommandRegistrar registerInfo("info", addInfo);
//
// Exit codes for every command: 0 success, 1 the command ran and found a problem in the geometry,
// 2 bad usage or unreadable/invalid input (message on stderr).
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace seam::cli {

enum ExitCode : int { kExitOk = 0, kExitGeometryProblem = 1, kExitBadInput = 2 };

/// Adds one subcommand to `app`; its callback stores the command's exit code in `exit`.
using AddCommand = std::function<void(CLI::App& app, int& exit)>;

struct CommandEntry {
  std::string name;
  AddCommand add;
};

inline std::vector<CommandEntry>& commandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

struct CommandRegistrar {
  CommandRegistrar(std::string name, AddCommand add) {
    commandRegistry().push_back({std::move(name), std::move(add)});
  }
};

}  // namespace seam::cli

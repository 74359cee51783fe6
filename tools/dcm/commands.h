// Subcommands of the `dcm` tool register themselves here, one per cmd_*.cpp:
//
//   static dcm::cli::Registration reg("render", "Render a scene with DCM",
//       [](CLI::App* app) -> std::function<int()> { ...add flags...; return [=]{ ...; return 0; }; });
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace dcm::cli {

/// Adds a subcommand's flags to `app` and returns the function that runs it
/// after parsing (its return value is the process's exit code).
using CommandSetup = std::function<std::function<int()>(CLI::App* app)>;

struct CommandEntry {
  std::string name;
  std::string description;
  CommandSetup setup;
};

std::vector<CommandEntry>& CommandRegistry();

/// A static object of this type registers a subcommand.
struct Registration {
  Registration(std::string name, std::string description, CommandSetup setup) {
    CommandRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

/// Exit codes shared by all subcommands.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,   ///< the operation failed (bad input, provider error)
  kExitUsage = 2,     ///< bad command line
};

}  // namespace dcm::cli

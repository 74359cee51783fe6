// dcm: evaluate a few percent of the pixels exactly, reconstruct the rest with
// Directional Coherence Maps.
#include <algorithm>
#include <iostream>
#include <memory>
#include <new>

#include "commands.h"
#include "flag_checks.h"
#include "common/output_transaction.h"
#include "common/output_exr.h"
#include "common/progress.h"

namespace dcm::cli {
std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}
}  // namespace dcm::cli

int main(int argc, char** argv) {
  using namespace dcm::cli;
  dcm::toolkit::StartupSeconds();  // the loader's and static initialisers' time, for end-to-end figures
  // Interrupted at any moment, a run leaves no temporary file and no child.
  dcm::toolkit::InstallSignalCleanup();
  dcm::toolkit::SetCommandLine(argc, argv);  // the provenance of every output
  CLI::App app{"dcm: image reconstruction with Directional Coherence Maps (Guo 1998, Scheel et al. 2001)"};
  const std::string version = std::string("dcm ") + DCM_VERSION;
  app.set_version_flag("--version", version);
  app.require_subcommand(1, 1);
  // Set before the subcommands are added: they copy both.
  app.formatter(std::make_shared<HelpFormatter>());
  app.footer(ExitCodesHelp());

  auto& registry = CommandRegistry();
  std::sort(registry.begin(), registry.end(),
            [](const CommandEntry& a, const CommandEntry& b) { return a.name < b.name; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> commands;
  for (const auto& entry : registry) {
    CLI::App* sub = app.add_subcommand(entry.name, entry.description);
    sub->set_version_flag("--version", version);  // `dcm COMMAND --version` too, for scripts that wrap one command
    commands.emplace_back(sub, entry.setup(sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << UsageErrorMessage(app, e);
    return kExitUsage;
  }
  for (auto& [sub, run] : commands) {
    if (sub->parsed()) {
      try {
        return run();
      } catch (const std::bad_alloc&) {
        // An allocation no header check foresaw: a message, not a terminate.
        std::cerr << "dcm " << sub->get_name() << ": error: out of memory while running 'dcm " << sub->get_name()
                  << "' (DCM_MEMORY_LIMIT bounds what one input may declare)\n";
        return kExitFailure;
      } catch (const std::exception& e) {
        std::cerr << "dcm " << sub->get_name() << ": error: " << e.what() << "\n";
        return kExitFailure;
      }
    }
  }
  return kExitUsage;
}

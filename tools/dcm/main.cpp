// dcm: evaluate a few percent of the pixels exactly, reconstruct the rest with
// Directional Coherence Maps.
#include <algorithm>
#include <iostream>

#include "commands.h"
#include "common/output_transaction.h"

namespace dcm::cli {
std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}
}  // namespace dcm::cli

int main(int argc, char** argv) {
  using namespace dcm::cli;
  // Interrupted at any moment, a run leaves no temporary file and no child.
  dcm::toolkit::InstallSignalCleanup();
  CLI::App app{"dcm: image reconstruction with Directional Coherence Maps (Guo 1998, Scheel et al. 2001)"};
  app.set_version_flag("--version", std::string("dcm ") + DCM_VERSION);
  app.require_subcommand(1, 1);

  auto& registry = CommandRegistry();
  std::sort(registry.begin(), registry.end(),
            [](const CommandEntry& a, const CommandEntry& b) { return a.name < b.name; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> commands;
  for (const auto& entry : registry) {
    CLI::App* sub = app.add_subcommand(entry.name, entry.description);
    commands.emplace_back(sub, entry.setup(sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  for (auto& [sub, run] : commands) {
    if (sub->parsed()) {
      try {
        return run();
      } catch (const std::exception& e) {
        std::cerr << "dcm " << sub->get_name() << ": error: " << e.what() << "\n";
        return kExitFailure;
      }
    }
  }
  return kExitUsage;
}

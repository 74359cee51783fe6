// What `dcm pipe` and `dcm reconstruct --provider-cmd` share: reconstructing
// with a renderer in a child process that speaks the dcm-pipe protocol
// (plugins/pipe/PROTOCOL.md). Defined in cmd_pipe.cpp, which compiles only
// with the dcm_pipe library (DCM_HAVE_PIPE).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "common/output_exr.h"
#include "engine_flags.h"
#include "tile_flags.h"

namespace dcm::cli {

/// The flags of a reconstruction through a provider command.
struct PipeFlags {
  std::string command;  ///< --provider-cmd, run with /bin/sh -c
  std::string output;
  std::string stats;
  std::string sampleMap;
  double timeout = 600.0;         ///< --provider-timeout, per answer
  double startupTimeout = 600.0;  ///< --provider-startup-timeout, for the handshake
  EngineFlags engine;
  RoundFlags rounds;  ///< --schedule and the preview schedule's flags, for a provider whose calls cost a latency
  TileFlags tiles;  ///< --tile / --region: a part of the frame for `dcm merge` (no --frames)
  toolkit::ExrFormat exr;  ///< -d, --compression, --ch (the whole frame)
  /// --estimate-from: what judges a goal on the preview schedule: auto (the
  /// preview where the child announced preview_samples= and it can tell),
  /// preview, validation.
  std::string estimateFrom = "auto";
};

/// Adds --provider-timeout and --provider-startup-timeout.
void AddProviderTimeoutFlags(CLI::App* app, PipeFlags* flags);

/// Starts the provider, reconstructs, writes the outputs; messages start with
/// "dcm CMD: error:". Returns the exit code (no output file on failure).
int RunPipe(const std::string& cmd, const PipeFlags& flags);

}  // namespace dcm::cli

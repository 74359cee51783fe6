// How outputs are stored and shown, shared by the commands that write them:
// oiiotool's -d, --compression and --ch for EXRs, --colorconfig, --display,
// --view and --look for previews.
#pragma once

#include <CLI/CLI.hpp>

#include "common/output_exr.h"
#include "common/preview.h"

namespace dcm::cli {

/// Adds -d half|float, --compression NAME and --ch NAME,... (the output
/// EXR's channels, by their names in the output). The values are checked
/// by toolkit::CheckExrFormat when the command runs.
void AddExrFormatFlags(CLI::App* app, toolkit::ExrFormat* format);

/// Adds --colorconfig FILE, --display, --view and --look (the previews'
/// display transform; checked by toolkit::CheckDisplayTransform when the
/// command runs).
void AddDisplayFlags(CLI::App* app, toolkit::DisplayTransform* transform);

}  // namespace dcm::cli

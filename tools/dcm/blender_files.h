// What `dcm blender` and `dcm bench` need of Blender before starting it: the
// executable, the scripts dcm runs inside it, a readable .blend.
#pragma once

#include <string>

#include "dcm/status.h"

namespace dcm::cli {

/// A script of plugins/blender (`file`, e.g. "child_main.py"): $`envVar` if
/// set, else installed beside the binary (../share/dcm/blender), else the
/// source tree's.
Status FindBlenderScript(const std::string& file, const char* envVar, std::string* path);

/// The Blender executable `name`: a path, or a name looked up in $PATH.
Status FindBlender(const std::string& name, std::string* path);

/// The scene must be a readable .blend: plain ("BLENDER"), gzip or zstd compressed.
Status CheckBlendFile(const std::string& path);

}  // namespace dcm::cli

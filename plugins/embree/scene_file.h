// Reading scene files (JSON, see SCENE-FORMAT.md) into a Scene.
#pragma once

#include <string>
#include <string_view>

#include "dcm/status.h"
#include "embree/scene.h"

namespace dcm::embree {

/// Reads and validates the scene file at `path`. Relative file names inside
/// (meshes, textures) are resolved against the scene file's folder, and must
/// exist. Errors name the file and the key path, syntax errors the line and
/// column.
Status LoadSceneFile(const std::string& path, Scene* scene);

/// Parses scene JSON from memory. `file` names the source in messages and
/// `baseDir` resolves relative file names.
Status ParseScene(std::string_view text, const std::string& file, const std::string& baseDir,
                  Scene* scene);

}  // namespace dcm::embree

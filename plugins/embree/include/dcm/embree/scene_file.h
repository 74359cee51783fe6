// Reading scene files (JSON, see SCENE-FORMAT.md) into a Scene.
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "dcm/status.h"
#include "dcm/embree/scene.h"

namespace dcm::embree {

/// Reads and validates the scene file at `path`. Relative file names inside
/// (meshes, textures) are resolved against the scene file's folder, and must
/// exist. Errors name the file and the key path, syntax errors the line and
/// column.
/// `overrides` are "KEY.PATH=JSON" settings applied to the file's JSON before
/// it is read (as `kick -set node.param value`): "render.samples_per_pixel=64",
/// "render.indirect={\"bounces\": 2, \"rays\": 1}", "camera.fov=30"; a value
/// that is not JSON is taken as a string. The usual validation then applies.
Status LoadSceneFile(const std::string& path, Scene* scene, std::span<const std::string> overrides = {});

/// Parses scene JSON from memory. `file` names the source in messages and
/// `baseDir` resolves relative file names.
Status ParseScene(std::string_view text, const std::string& file, const std::string& baseDir,
                  Scene* scene, std::span<const std::string> overrides = {});

}  // namespace dcm::embree

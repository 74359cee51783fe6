// Small scenes and helpers shared by the embree tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "dcm/sample_provider.h"
#include "dcm/embree/embree_provider.h"
#include "dcm/embree/scene.h"

namespace dcm::embree::testing {

/// A fresh empty folder under the system temp dir, removed by the destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  const std::string& path() const { return path_; }
  /// Writes `text` to `name` inside the folder and returns the full path.
  std::string Write(const std::string& name, const std::string& text) const;

 private:
  std::string path_;
};

/// Parses scene JSON (file name "test.json" in messages, relative files
/// resolved against `baseDir`).
Status Parse(const std::string& json, Scene* scene, const std::string& baseDir = "");

/// Parses and creates a provider; fails the current test on error.
std::unique_ptr<EmbreeProvider> MakeProvider(const std::string& json, const std::string& baseDir = "");

/// Every pixel of the working image, row by row.
std::vector<Point2i> AllPixels(const EmbreeProvider& p);

/// Evaluates `pixels` in one batch.
std::vector<ExactSample> EvaluateAll(EmbreeProvider& p, const std::vector<Point2i>& pixels, bool split);

/// A scene description with placeholders: {MATERIALS}, {OBJECTS_EXTRA},
/// {RENDER}, {LIGHTS} replaced by the given JSON fragments. The base has a
/// floor quad (material "floor"), a sphere ("ball") and a box ("block") seen
/// from above at 32x32.
std::string SceneJson(const std::string& materials, const std::string& render = "{}",
                      const std::string& lights = "",
                      const std::string& extraObjects = "");

}  // namespace dcm::embree::testing

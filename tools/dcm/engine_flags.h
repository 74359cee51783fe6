// The engine switches shared by `dcm render`, `dcm reconstruct` and `dcm plan`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "dcm/options.h"
#include "dcm/reconstructor.h"
#include "dcm/status.h"

namespace dcm::cli {

/// Flag values as parsed; turned into ReconstructionOptions by ToOptions().
struct EngineFlags {
  std::string method = "dcm";  ///< dcm | paper | guo
  float threshold = -1;        ///< <0: the method's default
  float noiseSignificance = -1;  ///< <0: the method's default
  float creaseAngle = -1;        ///< <0: the method's default
  float probeLcShare = -1;       ///< <0: the method's default
  int block = 0, minBlock = 0, directions = 0, downsample = 1, threads = 0, tile = 0;
  int neighbourDirections = -1;  ///< <0: the method's default
  int fallbackShadingChanges = -2;  ///< < -1: the method's default
  int crossingFill = -1;            ///< < 0: the method's default
  int simpleSurfaceChanges = 0;  ///< 0: the method's default
  bool noThin = false, noTextureSplit = false, noLazy = false, noFallback = false;
  bool noSurfaceAware = false, full = false;
  bool noAdaptiveBorders = false, noCentreProbe = false, noDenoise = false, fallbackFilledBorders = false;
  bool noGuideFirstOrder = false, noCheckerboard = false;
  std::string smoothRefinement;  ///< always | centre-probe | never
  std::string objectTest;      ///< none | id | id+shader
  std::string thinTest;        ///< off | none-matches | any-differs | end-differs (default)
  std::string contrast;        ///< mitchell | display
  std::string progressive;     ///< folder for an image after each refinement level
  bool verbose = false, quiet = false;
};

/// Adds --method, --threshold, --block, --min-block, --directions, --no-thin,
/// --thin-test, --neighbour-directions, --no-texture-split, --object-test, --contrast, --no-lazy,
/// --no-fallback, --no-surface-aware, --downsample, --threads, --tile-size,
/// --noise-significance, --no-denoise-samples, --crease-angle,
/// --progressive, -v, --quiet.
void AddEngineFlags(CLI::App* app, EngineFlags* flags);

/// The options the flags select. The message names the flag at fault.
Status ToOptions(const EngineFlags& flags, ReconstructionOptions* options);

/// For -v: the settings that depend on the supersampling and on the
/// provider, as the engine will use them on a provider with `caps`
/// ("contrast display-weighted, threshold 0.15, 16 directions, thin-object test
/// none-matches, crossing fill 2 (supersampled rules: --downsample 2);
/// smooth blocks: never (the guides show every hard shadow)").
std::string SettingsSummary(const ReconstructionOptions& options, const ProviderCapabilities& caps);

}  // namespace dcm::cli

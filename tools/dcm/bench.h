// dcm bench's flags and measured points, shared by its sweeps over the
// internal tracer and AOV inputs (cmd_bench.cpp) and over .blend files
// rendered by Cycles (bench_cycles.cpp).
#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_rivals.h"
#include "common/metrics.h"
#include "dcm/options.h"
#include "dcm/reconstructor.h"

namespace dcm::cli {

struct BenchFlags {
  std::vector<std::string> inputs;
  std::string out;
  bool quick = false;
  std::optional<float> scale;
  std::vector<float> thresholds;
  int threads = 0;
  bool noPlots = false;
  std::string python = "/usr/bin/python3";
  std::string plotScript;
  bool quiet = false, verbose = false;
  // AOV inputs (dense mode).
  std::string preset = "generic";
  std::vector<std::string> maps;
  int downsample = 1;
  std::optional<float> highlightLevel;  ///< empty: the AOV provider's default
  bench::JbuParams jbu;
  // Scenes and .blend files: scene overrides and the noise sweep.
  std::vector<std::string> overrides;
  std::vector<int> spp;
  std::optional<int> referenceSpp;
  // .blend files (Cycles).
  std::string reference;                 ///< a converged render to compare with (else rendered)
  std::vector<double> adaptive;          ///< Cycles' adaptive sampling at these noise thresholds
  std::vector<std::string> variants;     ///< dcm blender flags, one run per entry and spp
  std::string blender = "blender";
  int renderThreads = 0;                 ///< Cycles threads (0: Blender's choice)
  int repeat = 1;                        ///< times each run is timed (the median)
};

/// The settings of one point of the sweep.
struct Config {
  std::string method;   ///< dcm | paper | guo | bilinear | jbu | full | dcm blender | adaptive
  std::string label;    ///< unique within an input
  std::string sweeps;   ///< sweeps this point belongs to, '|'-separated
  ReconstructionOptions options;
  int supersampling = 1;
  int spp = 0;  ///< noise sweep: estimates per exact pixel (0: the scene's own)
  // Rivals: the budget (exact pixels) and the label of the point it matches.
  int64_t budget = 0;
  std::string budgetOf;
};

/// One measured point.
struct Point {
  std::string input, scene;
  Config config;
  bool rival = false;
  /// Measured from another process (Cycles, `dcm blender`): no engine settings of this one.
  bool external = false;
  int64_t exactPixels = 0, totalPixels = 0;
  double exactFraction = 0;
  double timeIllumS = 0, timeGuidesS = 0, timeEngineS = 0, timeTotalS = 0;
  toolkit::ImageError error;
  /// What the run used (ReconstructionStats::settings): the regime's
  /// threshold and thin-object test, no centre probes where the provider's
  /// guides show every hard shadow.
  ResolvedSettings settings;
  /// External points: what the run reported of itself (dcm blender's stats:
  /// estimated_psnr, the times of its phases; Cycles: the adaptive threshold).
  nlohmann::json extra = nlohmann::json::object();
};

/// `v` formatted by the printf format `fmt` (one double).
inline std::string Fmt(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

/// True for a .blend input (measured by MeasureCycles).
bool IsBlendInput(const std::string& input);

/// The noise axis for Cycles: renders `input` (a .blend) in full and through
/// `dcm blender` at each of f.spp, with Cycles' adaptive sampling at the
/// largest, each timed from the command to its EXR in a process of its own,
/// and compares all with a converged render (f.reference, or rendered at
/// f.referenceSpp with another seed). The renders and dcm's stats are written
/// into the folder `dir` (inside the caller's output transaction). Appends the
/// points, a section of the summary and the input's JSON.
Status MeasureCycles(const BenchFlags& f, const std::string& input, const std::string& dir,
                     std::vector<Point>* points, std::ostringstream* summary, nlohmann::json* inputJson);

}  // namespace dcm::cli

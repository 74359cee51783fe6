// What `dcm reconstruct` and `dcm plan` share: the AOV input flags, opening
// the provider with its notes and warnings, and running the engine with
// progress. Header-only so that both cmd_*.cpp files build only with dcm_aov.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "common/output_guard.h"
#include "common/output_transaction.h"
#include "common/progress.h"
#include "common/stats_json.h"
#include "common/tiles.h"
#include "dcm/aov/aov_provider.h"
#include "dcm/reconstructor.h"
#include "dcm/window_provider.h"
#include "engine_flags.h"
#include "flag_checks.h"
#include "tile_flags.h"

namespace dcm::cli::aov_common {

/// The AOV input flags as parsed.
struct AovFlags {
  std::vector<std::string> inputs;
  std::string preset = "generic";
  std::vector<std::string> maps;
  std::vector<std::string> textures;
  std::string layer;
  std::vector<std::string> samples;
  std::vector<std::string> secondRender;
  bool estimateVariance = false;
  bool detectNoise = true;
  float highlightLevel = aov::AovOptions{}.highlightLevel;
};

/// Adds INPUT... and --preset, --map, --texture, --layer, --samples.
/// `dcm plan` needs its inputs; `dcm reconstruct` may take --provider-cmd
/// instead (and checks that one of the two is given).
inline void AddAovFlags(CLI::App* app, AovFlags* f, bool samplesHelpForPlan) {
  app->option_defaults()->group(kGroupIo);
  auto* inputs =
      app->add_option("inputs", f->inputs, "input EXR files (one multilayer EXR or several EXRs of one size)");
  if (samplesHelpForPlan) inputs->required();
  app->add_option("--preset", f->preset, "channel names: generic or blender (Cycles passes)")
      ->check(CLI::IsMember({"generic", "blender"}))
      ->capture_default_str();
  app->add_option("--map", f->maps,
                  "ROLE=CHANNEL: override a role (id, shader, u, v, tau, N, shadow, highlight, Li, Lc, L, var, mask or one "
                  "component like tau.R); CHANNEL may be A+B, A*B or cryptomatte:LAYER")
      ->allow_extra_args(false);
  app->add_option("--texture", f->textures,
                  "SHADER=FILE: evaluate tau(u,v) of that shader ID (or Cryptomatte material name) "
                  "from a texture file; or MAP.json, an object {\"SHADER\": \"FILE\", ...} (relative files "
                  "from the JSON's folder)")
      ->allow_extra_args(false);
  app->add_option("--layer", f->layer, "Blender view layer (default: the only one in the file)");
  app->add_option("--samples", f->samples,
                  samplesHelpForPlan
                      ? "samples EXR rendered for an earlier plan (repeatable; with a 'mask' channel)"
                      : "sparse round trip: samples EXRs rendered for `dcm plan` (repeatable); the "
                        "inputs then carry the guides only")
      ->allow_extra_args(false);
  app->add_option("--highlight-level", f->highlightLevel,
                  "highlight guide: a pixel whose guide (R+G+B of direct glossy light with --preset blender) "
                  "exceeds this is a highlight, a surface of its own")
      ->transform(FiniteNumber(0))
      ->capture_default_str()
      ->group(kGroupGuides);
  app->option_defaults()->group(kGroupNoise);
  app->add_option("--second-render", f->secondRender,
                  "noisy renders: an independent render of the same frame (another seed, same channels); the "
                  "samples are the mean of both and their difference gives the variance (repeatable, as the inputs)")
      ->allow_extra_args(false);
  app->add_flag("--estimate-variance", f->estimateVariance,
                "noisy renders without a variance channel: estimate the noise from the data (docs/NOISE.md)");
  app->add_flag("!--no-detect-noise", f->detectNoise,
                "take samples without a variance channel as noise-free; by default dcm estimates their noise "
                "when the data show it (docs/NOISE.md)");
  app->option_defaults()->group(kGroupGeneral);
}

/// The bindings of a --texture MAP.json: {"SHADER": "FILE", ...}; relative
/// texture files are taken from the JSON file's folder.
inline Status ReadTextureMap(const std::string& path, std::vector<aov::TextureBinding>* out) {
  const std::string what = "--texture '" + path + "'";
  std::ifstream in(path);
  if (!in) return Status::Error(what + ": cannot open the texture map");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    return Status::Error(what + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object() || j.empty())
    return Status::Error(what + ": expected an object of SHADER: FILE pairs, e.g. {\"7\": \"wood.tx\"}");
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!it.value().is_string() || it.value().get<std::string>().empty())
      return Status::Error(what + ": \"" + it.key() + "\": expected a texture file name (a string)");
    std::filesystem::path file = it.value().get<std::string>();
    if (file.is_relative()) file = dir / file;
    out->push_back({it.key(), file.string()});
  }
  return Status::Ok();
}

/// The provider options the flags select; the message names the flag at fault.
inline Status ToAovOptions(const AovFlags& f, bool sparse, bool split, aov::AovOptions* o) {
  DCM_RETURN_IF_ERROR(aov::ParsePreset(f.preset, &o->preset));
  for (const auto& m : f.maps) DCM_RETURN_IF_ERROR(aov::ParseMapping(m, &o->mappings));
  for (const auto& t : f.textures) {
    if (t.find('=') == std::string::npos && t.size() > 5 && t.compare(t.size() - 5, 5, ".json") == 0) {
      DCM_RETURN_IF_ERROR(ReadTextureMap(t, &o->textures));
      continue;
    }
    aov::TextureBinding b;
    DCM_RETURN_IF_ERROR(aov::ParseTextureBinding(t, &b));
    o->textures.push_back(b);
  }
  o->viewLayer = f.layer;
  o->sparse = sparse;
  o->samples = f.samples;
  o->split = split;
  o->secondRender = f.secondRender;
  o->estimateVariance = f.estimateVariance;
  o->detectNoise = f.detectNoise;
  o->highlightLevel = f.highlightLevel;
  return Status::Ok();
}

/// Prints "dcm CMD: error: MESSAGE" on stderr and returns `code`.
inline int Fail(const std::string& cmd, const std::string& message, int code = kExitFailure) {
  std::cerr << "dcm " << cmd << ": error: " << message << "\n";
  return code;
}

/// Opens the provider and prints its notes and the engine's settings (-v)
/// and its warnings (unless --quiet).
inline Status OpenProvider(const std::string& cmd, const AovFlags& flags, const aov::AovOptions& options,
                           const EngineFlags& engine, const ReconstructionOptions& engineOptions,
                           std::unique_ptr<aov::AovProvider>* provider) {
  DCM_RETURN_IF_ERROR(aov::AovProvider::Open(flags.inputs, options, provider));
  if (engine.verbose) {
    const auto caps = (*provider)->Capabilities();
    std::cerr << "dcm " << cmd << ": " << caps.width << "x" << caps.height << ", "
              << ((*provider)->dense() ? "dense" : "sparse") << " input\n";
    for (const auto& n : (*provider)->Notes()) std::cerr << "dcm " << cmd << ": " << n << "\n";
    std::cerr << "dcm " << cmd << ": " << SettingsSummary(engineOptions, caps) << "\n";
  }
  if (!engine.quiet)
    for (const auto& w : (*provider)->Warnings()) std::cerr << "dcm " << cmd << ": warning: " << w << "\n";
  return Status::Ok();
}

/// --tile / --region: the region of the output frame (and the tile's name,
/// and the frame's size when `frame` is given) that the AOV `inputs`
/// ("inputs" or "guides") are cut into; parts are cut from the whole frame,
/// so the inputs must hold it. An error is a usage error.
inline Status ResolvePart(const aov::AovProvider& provider, const TileFlags& tiles,
                          const ReconstructionOptions& options, const std::string& inputs, Bounds2i* region,
                          std::string* tile, Point2i* frame = nullptr) {
  if (!(provider.DataWindow() == provider.DisplayWindow()))
    return Status::Error("--tile and --region need " + inputs +
                         " whose data window is their display window (the whole frame); these are " +
                         toolkit::RegionText(provider.DataWindow()) + " of " +
                         toolkit::RegionText(provider.DisplayWindow()));
  const ProviderCapabilities caps = provider.Capabilities();
  const Point2i size = OutputSize(caps.width, caps.height, options.downsample);
  if (frame) *frame = size;
  return ResolveRegion(tiles, size.x, size.y, TileAlignment(options), region, tile);
}

/// Runs the engine with progress on stderr (and the time per stage with -v):
/// on the whole frame, or with `region` on that part of the output frame
/// (ReconstructRegion, which fills `info`).
inline Status Run(aov::AovProvider& provider, ReconstructionOptions options, const EngineFlags& engine,
                  Reconstruction* result, std::vector<Point2i>* pending, const Bounds2i* region = nullptr,
                  RegionInfo* info = nullptr, std::optional<QualityReport>* quality = nullptr) {
  if (region && (engine.targetPsnr || engine.budget))
    return Status::Error("--target-psnr and --budget estimate the whole frame; not with --tile or --region");
  toolkit::Progress progress(!engine.quiet);
  options.progress = [&progress](float f, std::string_view stage) { progress.Update(f, stage); };
  std::optional<QualityReport> report;
  Status st = region ? ReconstructRegion(provider, options, *region, result, info, pending)
                     : ReconstructFor(provider, options, engine, result, &report, pending);
  progress.Done();
  if (st.ok() && engine.verbose) std::cerr << toolkit::StageTimesLine(result->stats) << "\n";
  if (st.ok() && engine.verbose && report) std::cerr << QualityLine(*report, engine) << "\n";
  if (st.ok() && !engine.quiet && report)
    if (const std::string w = QualityWarning(*report, engine); !w.empty()) std::cerr << "dcm: warning: " << w << "\n";
  if (quality) *quality = std::move(report);
  return st;
}

/// A command's outputs as one transaction (toolkit::OutputTransaction): made
/// before the work starts, so that every file the run writes appears at
/// Commit() or not at all.
class Outputs {
 public:
  explicit Outputs(std::string cmd) : cmd_(std::move(cmd)) {}
  /// `status` of writing an output: kExitOk, or the failure's exit code (the
  /// error printed; nothing of the run appears).
  int Write(const Status& status) { return status.ok() ? kExitOk : Fail(cmd_, status.message()); }
  /// Puts every output in place: kExitOk or the failure's exit code.
  int Commit() { return Write(transaction_.Commit()); }

 private:
  std::string cmd_;
  toolkit::OutputTransaction transaction_;
};

/// The output guard (toolkit::CheckOutputs): kExitOk, or kExitUsage with the
/// error printed.
inline int CheckFiles(const std::string& cmd, const std::vector<toolkit::FileArg>& inputs,
                      const std::vector<toolkit::FileArg>& outputs) {
  const Status st = toolkit::CheckOutputs(inputs, outputs);
  return st.ok() ? kExitOk : Fail(cmd, st.message(), kExitUsage);
}

/// The input files of the AOV flags (inputs, --samples, --second-render, --texture).
inline std::vector<toolkit::FileArg> InputArgs(const AovFlags& f) {
  std::vector<toolkit::FileArg> args;
  for (const auto& p : f.inputs) args.push_back({"input", p});
  for (const auto& p : f.samples) args.push_back({"--samples", p});
  for (const auto& p : f.secondRender) args.push_back({"--second-render", p});
  for (const auto& t : f.textures) args.push_back(toolkit::TextureArg(t));
  return args;
}

}  // namespace dcm::cli::aov_common

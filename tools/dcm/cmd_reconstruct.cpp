// dcm reconstruct: DCM reconstruction from a renderer's EXR AOVs.
//
//   dcm reconstruct IN.exr [IN2.exr ...] [--preset blender|generic] [--map ROLE=CH]
//       -o OUT.exr [--stats S.json] [--sample-map M.png] [--preview P.png]
//       [--error-map E.png] [--reference REF.exr] [--samples S.exr ...] + engine flags
//
// Dense input (the expensive channels for every pixel): reconstructs from the
// pixels the engine asks for and reports the error against the full input.
// With --samples (the file-based round trip): the inputs carry the guides and
// the samples files the pixels rendered for `dcm plan`.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "dcm/downsample.h"
#include "aov_common.h"
#include "common/image_io.h"
#include "common/metrics.h"
#include "common/preview.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "common/tiles.h"
#include "pipe_run.h"
#include "tile_flags.h"

namespace dcm::cli {
namespace {

struct ReconstructFlags {
  aov_common::AovFlags aov;
  EngineFlags engine;
  std::string output, stats, sampleMap, preview, errorMap, reference;
  bool alpha = false;
  TileFlags tiles;
  PipeFlags pipe;  ///< --provider-cmd: a renderer in a child process instead of EXR inputs
};

nlohmann::json ErrorJson(const toolkit::ImageError& e) {
  nlohmann::json j;
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  j["psnr"] = num(e.psnr);  // null: identical images (infinite PSNR)
  j["rmse"] = num(e.rmse);
  j["relmse"] = num(e.relmse);
  j["ssim"] = num(e.ssim);
  j["non_finite_pixels"] = e.nonFinite;
  return j;
}

std::string PsnrText(double psnr) {
  if (std::isinf(psnr)) return "inf (identical)";
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << psnr << " dB";
  return s.str();
}

/// The statistics of a whole reconstruction and of a part alike.
nlohmann::json StatsJson(const std::string& cmd, const ReconstructFlags& f, const aov::AovProvider& provider,
                         const Reconstruction& r, const ReconstructionOptions& options, double wallS) {
  nlohmann::json stats = toolkit::StatsToJson(r.stats);
  stats["command"] = cmd;
  stats["inputs"] = f.aov.inputs;
  if (!f.aov.samples.empty()) stats["samples"] = f.aov.samples;
  stats["mode"] = provider.dense() ? "dense" : "sparse";
  stats["method"] = f.engine.method;
  stats["width"] = r.width;
  stats["height"] = r.height;
  stats["work_width"] = r.workWidth;
  stats["work_height"] = r.workHeight;
  stats["time_reconstruct_s"] = wallS;
  stats["options"] = toolkit::OptionsToJson(options);
  stats["warnings"] = provider.Warnings();
  return stats;
}

/// The provenance every output EXR carries in its metadata.
toolkit::Metadata ProvenanceMetadata(const ReconstructFlags& f, const aov::AovProvider& provider,
                                     const ReconstructionOptions& options) {
  toolkit::Metadata meta;
  meta.strings.push_back({"Software", std::string("dcm ") + DCM_VERSION});
  meta.strings.push_back({"dcm:method", f.engine.method});
  meta.strings.push_back({"dcm:mode", provider.dense() ? "dense" : "sparse"});
  meta.strings.push_back({"dcm:settings", toolkit::OptionsToJson(options).dump()});
  std::string inputs;
  for (const auto& in : f.aov.inputs) inputs += (inputs.empty() ? "" : " ") + in;
  meta.strings.push_back({"dcm:inputs", inputs});
  return meta;
}

/// The sparse round trip ran out of samples: how many of the pixels the
/// engine asked for (`forWhat`: " for this part" or "") were not rendered.
int FailMissingSamples(const aov::AovProvider& provider, const std::vector<Point2i>& pending,
                       const std::string& forWhat) {
  int64_t missing = 0;
  for (const auto& p : pending) missing += provider.HasSample(p) ? 0 : 1;
  return aov_common::Fail("reconstruct", "the samples lack " + std::to_string(missing) +
                                             " pixels the engine needs" + forWhat +
                                             "; run `dcm plan` with the same inputs, flags and samples, render what "
                                             "it asks for, and repeat");
}

/// The output's place in the frame: the inputs' data and display windows (a
/// render region stays a region of its frame, overscan stays overscan), at
/// the output resolution of --downsample N.
Status OutputWindows(const aov::AovProvider& provider, int n, Bounds2i* display, Bounds2i* data) {
  *display = provider.DisplayWindow();
  *data = provider.DataWindow();
  if (n <= 1) return Status::Ok();
  const bool whole = *display == *data;
  // A region must sit on the N-pixel lattice of its frame; a whole frame
  // only needs its origin there (its size is rounded as the image's is).
  std::vector<int> onLattice = {display->min.x, display->min.y, data->min.x, data->min.y};
  if (!whole) onLattice.insert(onLattice.end(), {display->max.x, display->max.y, data->max.x, data->max.y});
  for (int v : onLattice)
    if (v % n != 0)
      return Status::Error("--downsample " + std::to_string(n) + ": the inputs' data window (" +
                           toolkit::RegionText(*data) + ") or display window (" + toolkit::RegionText(*display) +
                           ") does not lie on a multiple of " + std::to_string(n) + " pixels");
  const Point2i size = OutputSize(data->width(), data->height(), n);
  *data = {{data->min.x / n, data->min.y / n}, {data->min.x / n + size.x, data->min.y / n + size.y}};
  *display = whole ? *data
                   : Bounds2i{{display->min.x / n, display->min.y / n},
                              {display->max.x / n, display->max.y / n}};
  return Status::Ok();
}

/// --tile / --region: the region of the frame, written as a part for `dcm merge`.
int RunReconstructPart(const ReconstructFlags& f, ReconstructionOptions options, aov::AovProvider& provider) {
  const std::string cmd = "reconstruct";
  if (!f.engine.progressive.empty())
    return aov_common::Fail(cmd, "--progressive needs the whole frame; not with --tile or --region", kExitUsage);
  if (!f.reference.empty() || !f.errorMap.empty())
    return aov_common::Fail(cmd, "--reference and --error-map need the whole frame; not with --tile or --region "
                                 "(compare the merged frame)", kExitUsage);
  Bounds2i region;
  std::string tile;
  Point2i frame;
  Status st = aov_common::ResolvePart(provider, f.tiles, options, "inputs", &region, &tile, &frame);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);

  // What decides the pixels besides the options: the input files by content
  // and the flags that read them.
  nlohmann::json identity;
  for (const auto& [key, list] : {std::pair{"inputs", &f.aov.inputs}, std::pair{"samples", &f.aov.samples},
                                   std::pair{"second_render", &f.aov.secondRender}}) {
    nlohmann::json hashes = nlohmann::json::array();
    for (const auto& path : *list) {
      uint64_t h = 0;
      if (st = toolkit::HashFile(path, &h); !st.ok()) return aov_common::Fail(cmd, st.message());
      hashes.push_back(toolkit::HexHash(h));
    }
    identity[key] = hashes;
  }
  identity["estimate_variance"] = f.aov.estimateVariance;
  identity["preset"] = f.aov.preset;
  identity["map"] = f.aov.maps;
  identity["texture"] = f.aov.textures;
  identity["layer"] = f.aov.layer;
  identity["highlight_level"] = f.aov.highlightLevel;
  identity["alpha"] = f.alpha;
  const nlohmann::json settings = toolkit::PartSettings(cmd, DCM_VERSION, options, identity);

  aov_common::Outputs outputs(cmd);
  Reconstruction r;
  RegionInfo info;
  std::vector<Point2i> pending;
  const auto t0 = std::chrono::steady_clock::now();
  st = aov_common::Run(provider, options, f.engine, &r, &pending, &region, &info);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (st.pending()) {
    return FailMissingSamples(provider, pending, " for this part");
  }
  if (!st.ok()) return aov_common::Fail(cmd, st.message());

  // Dense input: the error against the same region of the full input.
  bool haveRef = false;
  toolkit::ImageError error;
  if (provider.dense()) {
    int w = 0, h = 0;
    const std::vector<RGB> full =
        dcm::BoxDownsample(provider.Beauty(), provider.width(), provider.height(), options.downsample, &w, &h);
    if (w == frame.x && h == frame.y) {
      std::vector<RGB> ref;
      ref.reserve(size_t(region.area()));
      for (int y = region.min.y; y < region.max.y; ++y)
        for (int x = region.min.x; x < region.max.x; ++x) ref.push_back(full[size_t(y) * size_t(w) + size_t(x)]);
      error = toolkit::Compare(r.image, ref, r.width, r.height);
      haveRef = true;
    }
  }

  nlohmann::json stats = StatsJson(cmd, f, provider, r, options, wall);
  stats["part"] = PartJson(tile, info);
  if (haveRef) stats["reference"] = ErrorJson(error);

  toolkit::Metadata meta = ProvenanceMetadata(f, provider, options);
  AddPartMetadata(tile, region, settings, r, info, &meta);

  int rc = outputs.Write(toolkit::WritePartExr(f.output, frame.x, frame.y, region, r.image, meta, f.alpha));
  if (rc) return rc;
  if (!f.sampleMap.empty() && (rc = outputs.Write(toolkit::WriteSampleMap(f.sampleMap, r)))) return rc;
  if (!f.preview.empty() && (rc = outputs.Write(toolkit::WritePreview(f.preview, r.width, r.height, r.image))))
    return rc;
  if (!f.stats.empty() && (rc = outputs.Write(toolkit::WriteJson(f.stats, stats)))) return rc;
  if ((rc = outputs.Commit())) return rc;
  if (!f.engine.quiet) {
    std::ostringstream s;
    s << "dcm " << cmd << ": " << (tile.empty() ? "region " + toolkit::RegionText(region) : "tile " + tile)
      << " of " << frame.x << "x" << frame.y << " (window " << info.window.width() << "x" << info.window.height()
      << "), " << r.stats.exactPixels << " exact pixels (" << std::fixed << std::setprecision(2)
      << 100.0 * r.stats.exactFraction() << " %)";
    if (haveRef) s << ", PSNR " << PsnrText(error.psnr);
    s << " -> " << f.output;
    std::cerr << s.str() << "\n";
  }
  return kExitOk;
}

int RunReconstruct(const ReconstructFlags& f) {
  const std::string cmd = "reconstruct";
  if (!f.pipe.command.empty()) {
#ifdef DCM_HAVE_PIPE
    if (!f.aov.inputs.empty())
      return aov_common::Fail(cmd, "--provider-cmd replaces the input files; give one or the other", kExitUsage);
    if (!f.aov.samples.empty() || !f.aov.secondRender.empty() || f.aov.estimateVariance || !f.reference.empty() ||
        !f.errorMap.empty() || !f.preview.empty() || f.alpha)
      return aov_common::Fail(cmd,
                              "with --provider-cmd only -o, --stats, --sample-map, --tile/--region, the provider "
                              "timeouts and the engine flags apply (the provider reports its own variance and guides)",
                              kExitUsage);
    PipeFlags p = f.pipe;
    p.output = f.output;
    p.stats = f.stats;
    p.sampleMap = f.sampleMap;
    p.engine = f.engine;
    p.tiles = f.tiles;
    p.tiles.frames.clear();  // RunReconstructFrames ran the frames
    return RunPipe(cmd, p);
#else
    return aov_common::Fail(cmd, "--provider-cmd needs plugins/pipe, which this build does not have", kExitUsage);
#endif
  }
  if (f.aov.inputs.empty())
    return aov_common::Fail(cmd, "no input files (EXR AOVs), and no --provider-cmd", kExitUsage);
  std::vector<toolkit::FileArg> inputs = aov_common::InputArgs(f.aov);
  inputs.push_back({"--reference", f.reference});
  if (int rc = aov_common::CheckFiles(cmd, inputs,
                                      {{"-o", f.output},
                                       {"--stats", f.stats},
                                       {"--sample-map", f.sampleMap},
                                       {"--preview", f.preview},
                                       {"--error-map", f.errorMap},
                                       toolkit::ProgressiveArg(f.engine.progressive)}))
    return rc;
  ReconstructionOptions options;
  Status st = ToOptions(f.engine, &options);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);
  const bool sparse = !f.aov.samples.empty();
  aov::AovOptions aovOptions;
  st = aov_common::ToAovOptions(f.aov, sparse, options.textureSplit, &aovOptions);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);
  if (sparse && !f.errorMap.empty() && f.reference.empty())
    return aov_common::Fail(cmd, "--error-map needs dense input or --reference", kExitUsage);

  std::unique_ptr<aov::AovProvider> provider;
  st = aov_common::OpenProvider(cmd, f.aov, aovOptions, f.engine, options, &provider);
  if (!st.ok()) return aov_common::Fail(cmd, st.message());
  if (IsPartial(f.tiles)) return RunReconstructPart(f, options, *provider);
  Bounds2i display, data;
  st = OutputWindows(*provider, options.downsample, &display, &data);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);

  // An explicit reference is read (and checked) before the work starts.
  std::vector<RGB> reference;
  int refW = 0, refH = 0;
  if (!f.reference.empty()) {
    st = toolkit::ReadRgb(f.reference, &refW, &refH, &reference);
    if (!st.ok()) return aov_common::Fail(cmd, st.message());
  }

  aov_common::Outputs outputs(cmd);  // before the run: --progressive writes during it
  Reconstruction r;
  std::vector<Point2i> pending;
  const auto t0 = std::chrono::steady_clock::now();
  st = aov_common::Run(*provider, options, f.engine, &r, &pending);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (st.pending()) {
    return FailMissingSamples(*provider, pending, "");
  }
  if (!st.ok()) return aov_common::Fail(cmd, st.message());

  // The error against the full input (dense mode) or an explicit reference,
  // at the output resolution.
  bool haveRef = false;
  if (!reference.empty()) {
    if (refW != r.width || refH != r.height)
      return aov_common::Fail(cmd, "reference '" + f.reference + "' is " + std::to_string(refW) + "x" +
                                       std::to_string(refH) + ", the output is " +
                                       std::to_string(r.width) + "x" + std::to_string(r.height));
    haveRef = true;
  } else if (provider->dense()) {
    int w = 0, h = 0;
    reference = dcm::BoxDownsample(provider->Beauty(), provider->width(), provider->height(),
                                       options.downsample, &w, &h);
    haveRef = (w == r.width && h == r.height);
  }
  toolkit::ImageError error;
  if (haveRef) error = toolkit::Compare(r.image, reference, r.width, r.height);

  nlohmann::json stats = StatsJson(cmd, f, *provider, r, options, wall);
  const auto caps = provider->Capabilities();
  stats["capabilities"] = {{"object_id", caps.objectId}, {"shader_id", caps.shaderId},
                           {"texture", caps.texture},    {"split_radiance", caps.splitRadiance},
                           {"variance", caps.variance},  {"hard_shadows_guided", caps.hardShadowsGuided}};
  if (haveRef) stats["reference"] = ErrorJson(error);

  toolkit::Metadata meta = ProvenanceMetadata(f, *provider, options);
  meta.floats.push_back({"dcm:exact_fraction", float(r.stats.exactFraction())});
  if (haveRef && std::isfinite(error.psnr)) meta.floats.push_back({"dcm:psnr", float(error.psnr)});

  // All outputs appear together at Commit(), or none.
  int rc = outputs.Write(toolkit::WriteRgbExr(f.output, display, data, r.image, meta, f.alpha));
  if (rc) return rc;
  if (!f.sampleMap.empty() && (rc = outputs.Write(toolkit::WriteSampleMap(f.sampleMap, r)))) return rc;
  if (!f.preview.empty() && (rc = outputs.Write(toolkit::WritePreview(f.preview, r.width, r.height, r.image))))
    return rc;
  if (!f.errorMap.empty() &&
      (rc = outputs.Write(toolkit::WriteErrorMap(f.errorMap, r.image, reference, r.width, r.height))))
    return rc;
  if (!f.stats.empty() && (rc = outputs.Write(toolkit::WriteJson(f.stats, stats)))) return rc;
  if ((rc = outputs.Commit())) return rc;

  if (!f.engine.quiet) {
    std::ostringstream s;
    s << "dcm " << cmd << ": " << r.workWidth << "x" << r.workHeight << ", " << r.stats.exactPixels
      << " exact pixels (" << std::fixed << std::setprecision(2) << 100.0 * r.stats.exactFraction()
      << " %)";
    if (haveRef) s << ", PSNR " << PsnrText(error.psnr) << ", RMSE " << std::setprecision(5) << error.rmse;
    s << ", engine " << std::setprecision(3) << r.stats.timeEngineS << " s -> " << f.output;
    std::cerr << s.str() << "\n";
    for (const auto& w : toolkit::SampleWarnings(r.stats)) std::cerr << "dcm " << cmd << ": warning: " << w << "\n";
  }
  return kExitOk;
}

/// --frames: one reconstruction per frame, '#' in the file names replaced by
/// the frame number.
int RunReconstructFrames(const ReconstructFlags& f) {
  return RunPerFrame<ReconstructFlags>(
      "reconstruct", f, f.tiles,
      [](ReconstructFlags* g, const std::function<void(std::string*)>& each) {
        for (auto* list : {&g->aov.inputs, &g->aov.samples, &g->aov.secondRender})
          for (auto& name : *list) each(&name);
        for (auto* name : {&g->output, &g->stats, &g->sampleMap, &g->preview, &g->errorMap, &g->reference}) each(name);
      },
      RunReconstruct);
}

Registration reg("reconstruct", "Reconstruct an image from a renderer's EXR AOVs with DCM",
                 [](CLI::App* app) -> std::function<int()> {
                   auto f = std::make_shared<ReconstructFlags>();
                   aov_common::AddAovFlags(app, &f->aov, false);
                   app->add_option("-o,--output", f->output, "output EXR (float RGB)")->required();
                   app->add_option("--stats", f->stats, "statistics as JSON");
                   app->add_option("--sample-map", f->sampleMap, "PNG: which pixels were exact and why");
                   app->add_option("--preview", f->preview, "PNG through OpenColorIO ($OCIO or sRGB)");
                   app->add_option("--error-map", f->errorMap, "PNG heat map of the error (dense or --reference)");
                   app->add_option("--reference", f->reference, "compare with this EXR instead of the full input");
                   app->add_flag("--alpha", f->alpha, "write RGBA with A = 1");
                   AddEngineFlags(app, &f->engine);
                   AddTileFlags(app, &f->tiles);
                   app->add_option("--provider-cmd", f->pipe.command,
                                   "instead of input files: a renderer started as a child process that speaks the "
                                   "dcm-pipe protocol (plugins/pipe/PROTOCOL.md; as dcm pipe)");
#ifdef DCM_HAVE_PIPE
                   AddProviderTimeoutFlags(app, &f->pipe);
#endif
                   return [f] { return RunReconstructFrames(*f); };
                 });

}  // namespace
}  // namespace dcm::cli

// dcm reconstruct: DCM reconstruction from a renderer's EXR AOVs.
//
//   dcm reconstruct IN.exr [IN2.exr ...] [--preset blender|generic] [--map ROLE=CH]
//       -o OUT.exr [--stats S.json] [--sample-map M.png] [--preview P.png]
//       [--error-map E.png] [--reference REF.exr] [--samples S.exr ...]
//       [-d half|float] [--compression C] [--ch NAME,...] [--colorconfig F] [--display D] [--view V]
//       [--look L] + engine flags
//
// Dense input (the expensive channels for every pixel): reconstructs from the
// pixels the engine asks for and reports the error against the full input.
// With --samples (the file-based round trip): the inputs carry the guides and
// the samples files the pixels rendered for `dcm plan`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "dcm/downsample.h"
#include "aov_common.h"
#include "reconstruct_exr.h"
#include "common/elapsed.h"
#include "common/image_io.h"
#include "common/metrics.h"
#include "common/preview.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "common/tiles.h"
#include "flag_checks.h"
#include "output_flags.h"
#include "pipe_run.h"
#include "tile_flags.h"

namespace dcm::cli {
namespace {

struct ReconstructFlags {
  aov_common::AovFlags aov;
  EngineFlags engine;
  std::string output, stats, sampleMap, preview, errorMap, reference;
  bool alpha = false;
  toolkit::ExrFormat exr;  ///< -d, --compression, --ch
  toolkit::DisplayTransform display;  ///< --colorconfig, --display, --view, --look
  std::string displayText;            ///< which transform the preview uses (RunReconstruct)
  TileFlags tiles;
  PipeFlags pipe;  ///< --provider-cmd: a renderer in a child process instead of EXR inputs
};

std::string PsnrText(double psnr) {
  if (std::isinf(psnr)) return "inf (identical)";
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << psnr << " dB";
  return s.str();
}

/// The provenance every output EXR carries in its metadata.
toolkit::Metadata ProvenanceMetadata(const ReconstructFlags& f, const aov::AovProvider& provider,
                                     const ReconstructionOptions& options) {
  toolkit::Metadata meta;
  meta.strings.push_back({"Software", std::string("dcm ") + DCM_VERSION});
  meta.strings.push_back({"dcm:version", DCM_VERSION});
  meta.strings.push_back({"dcm:command_line", toolkit::CommandLine()});
  meta.strings.push_back({"dcm:method", f.engine.method});
  meta.strings.push_back({"dcm:mode", provider.dense() ? "dense" : "sparse"});
  meta.strings.push_back({"dcm:settings", toolkit::OptionsToJson(options).dump()});
  std::string inputs;
  for (const auto& in : f.aov.inputs) inputs += (inputs.empty() ? "" : " ") + in;
  meta.strings.push_back({"dcm:inputs", inputs});
  meta.strings.push_back({"dcm:variance", provider.Noise().variance});
  if (std::isfinite(provider.Noise().detectedPsnr))
    meta.floats.push_back({"dcm:detected_noise_psnr", float(provider.Noise().detectedPsnr)});
  return meta;
}

/// --tile / --region: the region of the frame, written as a part for `dcm merge`.
int RunReconstructPart(const ReconstructFlags& f, ReconstructionOptions options, aov::AovProvider& provider) {
  const std::string cmd = "reconstruct";
  if (!f.engine.progressive.empty())
    return aov_common::Fail(cmd, "--progressive needs the whole frame; not with --tile or --region", kExitUsage);
  if (!f.reference.empty() || !f.errorMap.empty())
    return aov_common::Fail(cmd, "--reference and --error-map need the whole frame; not with --tile or --region "
                                 "(compare the merged frame)", kExitUsage);
  if (!f.exr.dataType.empty() || !f.exr.channels.empty() || f.exr.compression != toolkit::ExrFormat{}.compression)
    return aov_common::Fail(cmd, "-d, --compression and --ch shape the whole frame; give them to `dcm merge`",
                            kExitUsage);
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
  identity["detect_noise"] = f.aov.detectNoise;
  identity["preset"] = f.aov.preset;
  identity["map"] = f.aov.maps;
  identity["texture"] = f.aov.textures;
  identity["layer"] = f.aov.layer;
  identity["highlight_level"] = f.aov.highlightLevel;
  identity["alpha"] = f.alpha;
  const nlohmann::json settings = toolkit::PartSettings(cmd, DCM_VERSION, options, identity);

  // The part keeps the inputs' layout (beauty names, alpha, passes cut to
  // the region, metadata) so that the merged frame is the whole run's.
  OutputLayout layout;
  if (st = PlanOutputLayout(provider, f.aov.inputs, f.aov.samples, f.alpha, options.downsample, &layout); !st.ok())
    return aov_common::Fail(cmd, st.message());
  options.recordInterpolation = layout.Reconstructs();

  aov_common::Outputs outputs(cmd);
  Reconstruction r;
  RegionInfo info;
  std::vector<Point2i> pending;
  const auto t0 = std::chrono::steady_clock::now();
  st = aov_common::Run(provider, options, f.engine, &r, &pending, &region, &info);
  const double wall = toolkit::SecondsSince(t0);
  if (st.pending()) {
    return aov_common::Fail(cmd, MissingSamplesMessage(provider, pending, " for this part"));
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

  nlohmann::json stats = ExrStatsJson(cmd, f.aov, f.engine, provider, r, options, wall);
  stats["part"] = PartJson(tile, info);
  if (haveRef) stats["reference"] = ErrorJson(error);
  if (!f.preview.empty()) stats["preview_transform"] = f.displayText;

  toolkit::Metadata meta = ProvenanceMetadata(f, provider, options);
  AddPartMetadata(tile, region, settings, r, info, &meta);

  ExrReconstruction run;
  run.result = r;
  run.display = run.data = {{0, 0}, {frame.x, frame.y}};
  toolkit::OutputImage image;
  st = BuildOutputImage(provider, layout, f.aov.inputs, run, options.downsample, {}, &image, &region);
  int rc = outputs.Write(st.ok() ? toolkit::WritePartImage(f.output, std::move(image), meta) : st);
  if (rc) return rc;
  if (!f.sampleMap.empty() && (rc = outputs.Write(toolkit::WriteSampleMap(f.sampleMap, r)))) return rc;
  if (!f.preview.empty() &&
      (rc = outputs.Write(toolkit::WritePreview(f.preview, r.width, r.height, r.image, f.display))))
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
    std::cout << s.str() << "\n";
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
    p.exr = f.exr;
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
  Status st = toolkit::CheckExrFormat(f.exr);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);
  ReconstructFlags g = f;  // with the preview's transform resolved
  if (st = toolkit::CheckDisplayTransform(f.display, &g.displayText); !st.ok())
    return aov_common::Fail(cmd, st.message(), kExitUsage);
  if (f.engine.verbose && !f.preview.empty()) std::cerr << "dcm " << cmd << ": preview: " << g.displayText << "\n";
  ReconstructionOptions options;
  st = ToOptions(f.engine, &options);
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
  st = CheckDownsample(provider->width(), provider->height(), options.downsample, "the inputs' data window");
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);
  if (IsPartial(f.tiles) && (f.engine.targetPsnr || f.engine.budget))
    return aov_common::Fail(cmd, "--target-psnr and --budget estimate the whole frame; not with --tile or --region",
                            kExitUsage);
  if (IsPartial(f.tiles)) return RunReconstructPart(g, options, *provider);
  // The output's channels are known from the headers: --ch is checked
  // before the engine runs.
  OutputLayout layout;
  st = PlanOutputLayout(*provider, f.aov.inputs, f.aov.samples, f.alpha, options.downsample, &layout);
  if (!st.ok()) return aov_common::Fail(cmd, st.message());
  std::vector<size_t> order;
  if (st = toolkit::SelectChannels(layout.Names(), f.exr.channels, &order); !st.ok())
    return aov_common::Fail(cmd, st.message(), kExitUsage);
  // Only the channels written are built: a pass left out is neither read
  // nor reconstructed (the engine keeps no record for it).
  if (!f.exr.channels.empty()) {
    std::vector<OutputLayout::Channel> kept;
    std::sort(order.begin(), order.end());
    for (size_t i : order) kept.push_back(layout.channels[i]);
    layout.channels = std::move(kept);
  }
  options.recordInterpolation = layout.Reconstructs();
  if (f.engine.verbose)
    for (const auto& note : layout.notes) std::cerr << "dcm " << cmd << ": " << note << "\n";
  EngineFlags engine = f.engine;
  if (ApplyNoisyDefaultGoal(*provider, sparse, &engine) && engine.verbose)
    std::cerr << "dcm " << cmd << ": noisy samples: refining until the result is estimated at least as close to "
              << "the converged image as the render itself, with at most " << 100 * kNoisyDefaultBudget
              << " % of the pixels exact (--target-psnr render --budget " << kNoisyDefaultBudget
              << "; --target-psnr render alone spends more, --threshold T gives one threshold's result)\n";
  aov_common::Outputs outputs(cmd);  // before the run: --progressive writes during it
  ExrReconstruction run;
  bool usage = false;
  st = ReconstructWholeExr(cmd, *provider, f.aov, engine, options, f.reference, &run, &usage);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), usage ? kExitUsage : kExitFailure);
  const Reconstruction& r = run.result;
  const bool haveRef = run.haveReference;
  const toolkit::ImageError& error = run.error;

  toolkit::Metadata meta = ProvenanceMetadata(f, *provider, options);
  meta.floats.push_back({"dcm:exact_fraction", float(r.stats.exactFraction())});
  if (haveRef && std::isfinite(error.psnr)) meta.floats.push_back({"dcm:psnr", float(error.psnr)});
  if (run.quality) toolkit::AddQualityMetadata(*run.quality, &meta);

  // All outputs appear together at Commit(), or none.
  toolkit::OutputImage image;
  st = BuildOutputImage(*provider, layout, f.aov.inputs, run, options.downsample, meta, &image);
  int rc = outputs.Write(st.ok() ? toolkit::WriteOutputExr(f.output, image, f.exr) : st);
  if (rc) return rc;
  if (!f.sampleMap.empty() && (rc = outputs.Write(toolkit::WriteSampleMap(f.sampleMap, r)))) return rc;
  if (!f.preview.empty() &&
      (rc = outputs.Write(toolkit::WritePreview(f.preview, r.width, r.height, r.image, f.display))))
    return rc;
  if (!f.errorMap.empty() &&
      (rc = outputs.Write(toolkit::WriteErrorMap(f.errorMap, r.image, run.reference, r.width, r.height))))
    return rc;
  if (!f.preview.empty()) run.stats["preview_transform"] = g.displayText;
  if (!f.stats.empty() && (rc = outputs.Write(toolkit::WriteJson(f.stats, run.stats)))) return rc;
  if ((rc = outputs.Commit())) return rc;

  if (!f.engine.quiet) {
    std::ostringstream s;
    s << "dcm " << cmd << ": " << r.workWidth << "x" << r.workHeight << ", " << r.stats.exactPixels
      << " exact pixels (" << std::fixed << std::setprecision(2) << 100.0 * r.stats.exactFraction()
      << " %)";
    if (haveRef) s << ", PSNR " << PsnrText(error.psnr) << ", RMSE " << std::setprecision(5) << error.rmse;
    if (run.quality) s << ", estimated PSNR " << PsnrText(run.quality->estimate.psnr);
    s << ", engine " << std::setprecision(3) << r.stats.timeEngineS << " s -> " << f.output;
    std::cout << s.str() << "\n";
  }
  for (const auto& w : toolkit::SampleWarnings(r.stats)) std::cerr << "dcm " << cmd << ": warning: " << w << "\n";
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
                   app->option_defaults()->group(kGroupIo);
                   app->add_option("-o,--output", f->output, "output EXR (the inputs' layout)")->required();
                   app->add_option("--stats", f->stats, "statistics as JSON");
                   app->add_option("--sample-map", f->sampleMap, "PNG: which pixels were exact and why");
                   app->add_option("--preview", f->preview, "PNG through OpenColorIO ($OCIO or sRGB)");
                   app->add_option("--error-map", f->errorMap, "PNG heat map of the error (dense or --reference)");
                   app->add_option("--reference", f->reference, "compare with this EXR instead of the full input");
                   app->add_flag("--alpha", f->alpha, "write alpha even if the inputs have none (A = 1)");
                   AddExrFormatFlags(app, &f->exr);
                   AddDisplayFlags(app, &f->display);
                   app->add_option("--provider-cmd", f->pipe.command,
                                   "instead of input files: a renderer started as a child process that speaks the "
                                   "dcm-pipe protocol (plugins/pipe/PROTOCOL.md; as dcm pipe)");
#ifdef DCM_HAVE_PIPE
                   AddProviderTimeoutFlags(app, &f->pipe);
#endif
                   app->option_defaults()->group(kGroupGeneral);
                   AddEngineFlags(app, &f->engine);
                   AddTileFlags(app, &f->tiles);
                   return [f] { return RunReconstructFrames(*f); };
                 });

}  // namespace
}  // namespace dcm::cli

// dcm render: ray trace a scene file with the internal Embree renderer,
// evaluating only a few percent of the pixels exactly and reconstructing the
// rest with DCM; optionally also the full (baseline) render, for the speed-up
// and the error.
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "commands.h"
#include "common/elapsed.h"
#include "common/image_io.h"
#include "common/metrics.h"
#include "common/output_guard.h"
#include "common/preview.h"
#include "common/progress.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "common/summary.h"
#include "common/tiles.h"
#include "dcm/reconstructor.h"
#include "dcm/embree/embree_provider.h"
#include "dcm/embree/scene_file.h"
#include "engine_flags.h"
#include "flag_checks.h"
#include "output_flags.h"
#include "render_preview.h"
#include "tile_flags.h"

namespace dcm::cli {
namespace {

struct RenderFlags {
  std::string scene;
  std::string output;
  std::string compare;
  std::string stats;
  std::string sampleMap;
  std::string preview;
  std::string size;
  std::optional<float> scale;
  std::optional<int> supersampling, spp;
  std::vector<std::string> overrides;
  std::optional<int64_t> seed;
  bool withReference = false;
  std::string referenceOut;
  std::string estimateFrom = "validation";
  EngineFlags engine;
  TileFlags tiles;
  toolkit::ExrFormat exr;  ///< -d, --compression, --ch
  toolkit::DisplayTransform display;  ///< --colorconfig, --display, --view, --look
};

/// --size WIDTHxHEIGHT, each from 1 to 16384.
Status ParseSize(const std::string& s, int* w, int* h) {
  const size_t x = s.find_first_of("xX");
  int a = 0, b = 0;
  auto whole = [](const char* first, const char* last, int* v) {
    const auto [end, ec] = std::from_chars(first, last, *v);
    return first != last && ec == std::errc() && end == last;
  };
  if (x == std::string::npos || !whole(s.data(), s.data() + x, &a) ||
      !whole(s.data() + x + 1, s.data() + s.size(), &b) || a < 1 || b < 1 || a > 16384 || b > 16384)
    return Status::Error("expected WIDTHxHEIGHT, each from 1 to 16384 (e.g. 256x256), got '" + s + "'");
  *w = a;
  *h = b;
  return Status::Ok();
}

nlohmann::json RaysToJson(const embree::RayCounts& c) {
  return {{"primary", c.primary}, {"guide", c.guide},   {"shadow", c.shadow}, {"glossy", c.glossy},
          {"mirror", c.mirror},   {"indirect", c.indirect}, {"total", c.total()}};
}

nlohmann::json ErrorToJson(const toolkit::ImageError& e) {
  return {{"psnr", e.psnr}, {"rmse", e.rmse}, {"relmse", e.relmse}, {"ssim", e.ssim}, {"non_finite", e.nonFinite}};
}

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& e : v) s += (s.empty() ? "" : ",") + e;
  return s.empty() ? "none" : s;
}

/// One reconstruction with its wall-clock time and the rays it cost.
struct Run {
  Reconstruction rec;
  double wallS = 0;
  embree::RayCounts rays;
  std::optional<QualityReport> quality;  ///< with --target-psnr / --budget
  std::optional<TracerPreviewRun> preview;  ///< the goal judged by the tracer's preview
};

/// One reconstruction as `engine` asks (to a target or budget when given,
/// judged by the tracer's preview where `fromPreview`: RunRender checked that it can).
Status RunOnce(embree::EmbreeProvider& provider, const ReconstructionOptions& options, const EngineFlags& engine,
               bool fromPreview, Run* run) {
  provider.ResetRayCounts();
  auto t0 = std::chrono::steady_clock::now();
  QualityGoal goal;
  Status st;
  if (fromPreview && QualityGoalOf(engine, &goal)) {
    TracerPreviewRun preview;
    QualityReport report;
    bool judged = false;
    std::string why;
    st = ReconstructFromTracerPreview(provider, options, goal, &run->rec, &report, &preview, &judged, &why);
    if (st.ok() && !judged) st = Status::Error("--estimate-from preview: " + why);
    if (st.ok()) {
      run->quality = std::move(report);
      run->preview = std::move(preview);
    }
  } else {
    st = ReconstructFor(provider, options, engine, &run->rec, &run->quality);
  }
  run->wallS = toolkit::SecondsSince(t0);
  run->rays = provider.rayCounts();
  return st;
}

int Fail(const Status& st) {
  std::cerr << "dcm render: error: " << st.message() << "\n";
  return kExitFailure;
}

/// The provenance every render output carries in its EXR metadata.
toolkit::Metadata RenderMetadata(const std::string& scene, const std::string& method,
                                 const ReconstructionOptions& options, const std::vector<std::string>& effects) {
  toolkit::Metadata meta;
  meta.strings.push_back({"dcm:scene", scene});
  meta.strings.push_back({"dcm:method", method});
  meta.strings.push_back({"dcm:options", toolkit::OptionsToJson(options).dump()});
  meta.strings.push_back({"dcm:effects", Join(effects)});
  meta.strings.push_back({"dcm:provider", "embree"});
  return meta;
}

/// --tile / --region: the region of the frame, written as a part for `dcm merge`.
int RunRenderPart(const RenderFlags& f, const embree::Scene& scene, ReconstructionOptions options,
                  embree::EmbreeProvider& provider, toolkit::Progress& progress, toolkit::OutputTransaction& outputs) {
  auto usage = [](const std::string& message) {
    std::cerr << "dcm render: " << message << "\n";
    return kExitUsage;
  };
  if (f.withReference || !f.referenceOut.empty() || !f.compare.empty())
    return usage("--with-reference, --reference-out and --compare need the whole frame; not with --tile or "
                 "--region (compare the merged frame)");
  if (!f.engine.progressive.empty()) return usage("--progressive needs the whole frame; not with --tile or --region");
  if (f.engine.targetPsnr || f.engine.budget)
    return usage("--target-psnr and --budget estimate the whole frame; not with --tile or --region");
  const ProviderCapabilities caps = provider.Capabilities();
  const Point2i frame = OutputSize(caps.width, caps.height, options.downsample);
  Bounds2i region;
  std::string tile;
  if (Status st = ResolveRegion(f.tiles, frame.x, frame.y, TileAlignment(options), &region, &tile); !st.ok())
    return usage(st.message());
  uint64_t sceneHash = 0;
  if (Status st = toolkit::HashFile(f.scene, &sceneHash); !st.ok()) return Fail(st);
  const nlohmann::json settings = toolkit::PartSettings(
      "render", DCM_VERSION, options,
      {{"scene_hash", toolkit::HexHash(sceneHash)}, {"width", scene.camera.width}, {"height", scene.camera.height},
       {"supersampling", scene.render.supersampling}, {"samples_per_pixel", scene.render.samplesPerPixel},
       {"seed", scene.render.seed}, {"overrides", f.overrides}});

  options.progress = [&](float v, std::string_view stage) { progress.Update(v, stage); };
  provider.ResetRayCounts();
  const auto t0 = std::chrono::steady_clock::now();
  Reconstruction rec;
  RegionInfo info;
  if (Status st = ReconstructRegion(provider, options, region, &rec, &info); !st.ok()) return Fail(st);
  const double wallS = toolkit::SecondsSince(t0);
  const embree::RayCounts rays = provider.rayCounts();
  progress.Done();

  const std::string method = options.fullEvaluation ? "full" : f.engine.method;
  const auto effects = provider.effects().Names();
  toolkit::Metadata meta = RenderMetadata(f.scene, method, options, effects);
  AddPartMetadata(tile, region, settings, rec, info, &meta);
  if (Status st = toolkit::WritePartExr(f.output, frame.x, frame.y, region, rec.image, meta); !st.ok())
    return Fail(st);
  if (!f.sampleMap.empty()) {
    if (Status st = toolkit::WriteSampleMap(f.sampleMap, rec); !st.ok()) return Fail(st);
  }
  if (!f.preview.empty()) {
    if (Status st = toolkit::WritePreview(f.preview, rec.width, rec.height, rec.image, f.display); !st.ok()) return Fail(st);
  }
  if (!f.stats.empty()) {
    nlohmann::json j = toolkit::RunToJson(rec, method, options, wallS);
    j["scene"] = f.scene;
    j["effects"] = effects;
    j["rays"] = RaysToJson(rays);
    j["part"] = PartJson(tile, info);
    if (Status st = toolkit::WriteJson(f.stats, j); !st.ok()) return Fail(st);
  }
  if (Status st = outputs.Commit(); !st.ok()) return Fail(st);
  const toolkit::Summary say(!f.engine.quiet);
  say("%s: %s %s of %dx%d (window %dx%d working pixels), %s\n", f.scene.c_str(),
      tile.empty() ? "region" : "tile", tile.empty() ? toolkit::RegionText(region).c_str() : tile.c_str(),
      frame.x, frame.y, info.window.width(), info.window.height(), method.c_str());
  say("  region         %s -> %s\n", toolkit::RegionText(region).c_str(), f.output.c_str());
  say("  exact pixels   %.2f %% of the region, %.2f %% of the window\n", 100.0 * rec.stats.exactFraction(),
      100.0 * info.windowStats.exactFraction());
  say("  time           illumination %.2f s, DCM %.2f s, guides %.2f s, total %.2f s\n",
      info.windowStats.timeProviderS, info.windowStats.timeEngineS, info.windowStats.timeGuidesS, wallS);
  say("  rays           %llu\n", static_cast<unsigned long long>(rays.total()));
  return kExitOk;
}

int RunRender(const RenderFlags& f, CLI::App* app) {
  const std::vector<toolkit::FileArg> outputFiles{{"-o", f.output},
                                                  {"--stats", f.stats},
                                                  {"--sample-map", f.sampleMap},
                                                  {"--preview", f.preview},
                                                  {"--reference-out", f.referenceOut},
                                                  toolkit::ProgressiveArg(f.engine.progressive)};
  if (Status st = toolkit::CheckOutputs({{"scene", f.scene}, {"--compare", f.compare}}, outputFiles); !st.ok()) {
    std::cerr << "dcm render: error: " << st.message() << "\n";
    return kExitUsage;
  }
  // Every output of the run appears at its Commit(), or none (--progressive too).
  toolkit::OutputTransaction outputs;
  // Scene and its overrides.
  embree::Scene scene;
  if (Status st = embree::LoadSceneFile(f.scene, &scene, f.overrides); !st.ok()) return Fail(st);
  // The meshes and textures the scene names are inputs too.
  std::vector<toolkit::FileArg> sceneFiles;
  for (const embree::ObjectDesc& o : scene.objects)
    if (!o.file.empty()) sceneFiles.push_back({"the scene's " + o.path, o.file});
  for (const embree::MaterialDesc& m : scene.materials)
    if (m.texture && !m.texture->file.empty()) sceneFiles.push_back({"the texture of the scene's material '" + m.name + "'", m.texture->file});
  if (Status st = toolkit::CheckOutputs(sceneFiles, outputFiles); !st.ok()) {
    std::cerr << "dcm render: error: " << st.message() << "\n";
    return kExitUsage;
  }
  if (!f.size.empty()) {
    if (Status st = ParseSize(f.size, &scene.camera.width, &scene.camera.height); !st.ok()) {
      std::cerr << "dcm render: --size: " << st.message() << "\n";
      return kExitUsage;
    }
  } else if (f.scale) {
    scene.camera.width = std::max(1, int(std::lround(float(scene.camera.width) * *f.scale)));
    scene.camera.height = std::max(1, int(std::lround(float(scene.camera.height) * *f.scale)));
  }
  if (f.supersampling) scene.render.supersampling = *f.supersampling;
  if (f.spp) scene.render.samplesPerPixel = *f.spp;
  if (f.seed) scene.render.seed = uint32_t(*f.seed);

  ReconstructionOptions options;
  if (Status st = ToOptions(f.engine, &options); !st.ok()) {
    std::cerr << "dcm render: " << st.message() << "\n";
    return kExitUsage;
  }
  if (Status st = toolkit::CheckExrFormat(f.exr); !st.ok()) {
    std::cerr << "dcm render: " << st.message() << "\n";
    return kExitUsage;
  }
  if (IsPartial(f.tiles) && !(f.exr.dataType.empty() && f.exr.channels.empty() &&
                              f.exr.compression == toolkit::ExrFormat{}.compression)) {
    std::cerr << "dcm render: -d, --compression and --ch shape the whole frame; give them to `dcm merge`\n";
    return kExitUsage;
  }
  std::string displayText;
  if (Status st = toolkit::CheckDisplayTransform(f.display, &displayText); !st.ok()) {
    std::cerr << "dcm render: " << st.message() << "\n";
    return kExitUsage;
  }
  if (f.engine.verbose && !f.preview.empty()) std::cerr << "preview: " << displayText << "\n";
  if (app->count("--downsample") && f.engine.downsample != scene.render.supersampling) {
    std::cerr << "dcm render: --downsample is the scene's render.supersampling ("
              << scene.render.supersampling << "); use --supersampling to change it\n";
    return kExitUsage;
  }
  options.downsample = scene.render.supersampling;
  if (Status st = options.Validate(); !st.ok()) {
    std::cerr << "dcm render: " << st.message() << "\n";
    return kExitUsage;
  }

  toolkit::Progress progress(!f.engine.quiet);
  std::unique_ptr<embree::EmbreeProvider> provider;
  if (Status st = embree::EmbreeProvider::Create(scene, &provider); !st.ok()) return Fail(st);
  if (f.engine.verbose) {
    std::cerr << "scene " << f.scene << ": " << scene.objects.size() << " objects, "
              << provider->triangleCount() << " triangles, " << scene.lights.size() << " lights; working image "
              << provider->workWidth() << "x" << provider->workHeight() << "; effects "
              << Join(provider->effects().Names()) << "\n"
              << "engine settings: " << SettingsSummary(options, provider->Capabilities()) << "\n";
  }
  if (IsPartial(f.tiles)) return RunRenderPart(f, scene, options, *provider, progress, outputs);
  const bool fromPreview = f.estimateFrom == "preview";
  if (std::string why; fromPreview && !TracerPreviewApplies(*provider, options, f.engine, &why)) {
    std::cerr << "dcm render: --estimate-from preview: " << why << "\n";
    return kExitUsage;
  }

  // The reference compared against, from a file or rendered in this run.
  std::optional<std::vector<RGB>> reference;
  if (!f.compare.empty()) {
    int rw = 0, rh = 0;
    std::vector<RGB> px;
    if (Status st = toolkit::ReadRgb(f.compare, &rw, &rh, &px); !st.ok()) return Fail(st);
    if (rw != scene.camera.width || rh != scene.camera.height) {
      return Fail(Status::Error(f.compare + ": reference is " + std::to_string(rw) + "x" + std::to_string(rh) +
                                ", the render " + std::to_string(scene.camera.width) + "x" +
                                std::to_string(scene.camera.height)));
    }
    reference = std::move(px);
  }

  const bool wantReference = (f.withReference || !f.referenceOut.empty()) && !options.fullEvaluation;
  std::optional<Run> full;
  if (wantReference) {
    ReconstructionOptions fo = options;
    fo.fullEvaluation = true;
    fo.progress = [&](float v, std::string_view stage) { progress.Update(v, "full render: " + std::string(stage)); };
    Run r;
    if (Status st = RunOnce(*provider, fo, EngineFlags{}, false, &r); !st.ok()) return Fail(st);
    full = std::move(r);
  }

  options.progress = [&](float v, std::string_view stage) { progress.Update(v, stage); };
  Run run;
  if (Status st = RunOnce(*provider, options, f.engine, fromPreview, &run); !st.ok()) return Fail(st);
  progress.Done();
  if (f.engine.verbose && run.preview) {
    char line[240];
    std::snprintf(line, sizeof line, "render: %s judged by the preview's estimate (every pixel at 1/%d of the scene's "
                  "rays, twice: %llu rays, %.2f s, its own noise %.2f dB)\n",
                  f.engine.targetPsnr ? "--target-psnr" : "--budget", kTracerPreviewDivisor,
                  static_cast<unsigned long long>(run.preview->previewRays.total()), run.preview->previewS,
                  run.preview->previewPsnr);
    std::cerr << line;
  }
  const Reconstruction& rec = run.rec;
  const ReconstructionStats& stats = rec.stats;
  if (f.engine.verbose) std::cerr << toolkit::StageTimesLine(stats) << "\n";
  if (f.engine.verbose && run.quality) std::cerr << QualityLine(*run.quality, f.engine) << "\n";
  if (full && !reference) reference = full->rec.image;

  const std::string method = options.fullEvaluation ? "full" : f.engine.method;
  const auto effects = provider->effects().Names();
  toolkit::Metadata meta = RenderMetadata(f.scene, method, options, effects);
  meta.floats.push_back({"dcm:exact_fraction", float(stats.exactFraction())});
  meta.floats.push_back({"dcm:time_illum_s", float(stats.timeProviderS)});
  meta.floats.push_back({"dcm:time_dcm_s", float(stats.timeEngineS)});
  if (run.quality) toolkit::AddQualityMetadata(*run.quality, &meta);
  const Bounds2i whole{{0, 0}, {rec.width, rec.height}};
  if (Status st = toolkit::WriteRgbExr(f.output, whole, whole, rec.image, meta, false, f.exr); !st.ok())
    return Fail(st);
  if (full && !f.referenceOut.empty()) {
    toolkit::Metadata fm = meta;
    fm.strings[1].second = "full";
    fm.floats = {{"dcm:exact_fraction", 1.f}, {"dcm:time_illum_s", float(full->rec.stats.timeProviderS)}};
    const Bounds2i fullFrame{{0, 0}, {full->rec.width, full->rec.height}};
    if (Status st = toolkit::WriteRgbExr(f.referenceOut, fullFrame, fullFrame, full->rec.image, fm, false, f.exr);
        !st.ok()) {
      return Fail(st);
    }
  }
  if (!f.sampleMap.empty()) {
    if (Status st = toolkit::WriteSampleMap(f.sampleMap, rec); !st.ok()) return Fail(st);
  }
  if (!f.preview.empty()) {
    if (Status st = toolkit::WritePreview(f.preview, rec.width, rec.height, rec.image, f.display); !st.ok()) return Fail(st);
  }

  std::optional<toolkit::ImageError> error;
  if (reference) error = toolkit::Compare(rec.image, *reference, rec.width, rec.height);

  // End to end, as two processes would take: this one's time so far less the
  // other run's (each then pays the start-up, the scene and the outputs; the
  // comparison and the second output count in both, a little against dcm).
  struct EndToEnd {
    double dcmS, fullS, startupS;
  };
  std::optional<EndToEnd> e2e;
  if (full) {
    const double total = toolkit::ProcessSeconds();
    if (std::isfinite(total) && total > full->wallS + run.wallS)
      e2e = EndToEnd{total - full->wallS, total - run.wallS, toolkit::StartupSeconds()};
  }

  if (!f.stats.empty()) {
    nlohmann::json j = toolkit::RunToJson(rec, method, options, run.wallS);
    j["scene"] = f.scene;
    j["time_dcm_s"] = stats.timeEngineS;  // the name for the engine time ("time_s")
    j["effects"] = effects;
    j["rays"] = RaysToJson(run.rays);
    if (error) j["reference"] = ErrorToJson(*error);
    if (run.quality)
      toolkit::AddQualityJson(*run.quality, f.engine.targetPsnr.value_or(0), f.engine.budget.value_or(0), &j);
    if (run.preview) {
      j["quality"]["preview"] = {{"rays", RaysToJson(run.preview->previewRays)},
                                 {"time_s", run.preview->previewS},
                                 {"noise_psnr", run.preview->previewPsnr},
                                 {"ray_divisor", kTracerPreviewDivisor}};
      toolkit::AddLadderJson(run.preview->ladder, &j["quality"]);
    }
    if (!f.preview.empty()) j["preview_transform"] = displayText;
    if (full) {
      j["full"] = {{"time_illum_s", full->rec.stats.timeProviderS},
                   {"time_wall_s", full->wallS},
                   {"rays", RaysToJson(full->rays)}};
      j["speedup"] = run.wallS > 0 ? full->wallS / run.wallS : 0.0;
      if (e2e) j["end_to_end"] = {{"dcm_s", e2e->dcmS}, {"full_s", e2e->fullS}, {"speedup", e2e->fullS / e2e->dcmS},
                                  {"startup_s", e2e->startupS}};
    }
    if (Status st = toolkit::WriteJson(f.stats, j); !st.ok()) return Fail(st);
  }
  if (Status st = outputs.Commit(); !st.ok()) return Fail(st);

  const toolkit::Summary say(!f.engine.quiet);
  say("%s: %dx%d (working %dx%d), %s\n", f.scene.c_str(), rec.width, rec.height, rec.workWidth,
      rec.workHeight, method.c_str());
  say("  effects        %s\n", Join(effects).c_str());
  say("  exact pixels   %.2f %% (%lld of %lld)\n", 100.0 * stats.exactFraction(),
      static_cast<long long>(stats.exactPixels), static_cast<long long>(stats.totalPixels));
  say("  time           illumination %.2f s, DCM %.2f s, guides %.2f s, total %.2f s\n",
      stats.timeProviderS, stats.timeEngineS, stats.timeGuidesS, run.wallS);
  say("  rays           %llu (shadow %llu, glossy %llu, mirror %llu, indirect %llu)\n",
      static_cast<unsigned long long>(run.rays.total()), static_cast<unsigned long long>(run.rays.shadow),
      static_cast<unsigned long long>(run.rays.glossy), static_cast<unsigned long long>(run.rays.mirror),
      static_cast<unsigned long long>(run.rays.indirect));
  if (run.quality) say("  quality        %s\n", QualityLine(*run.quality, f.engine).c_str());
  for (const auto& w : toolkit::SampleWarnings(stats)) std::cerr << "dcm render: warning: " << w << "\n";
  if (run.quality)
    if (const std::string w = QualityWarning(*run.quality, f.engine); !w.empty())
      std::cerr << "dcm render: warning: " << w << "\n";
  if (full) {
    say("  full render    illumination %.2f s, total %.2f s, %llu rays\n", full->rec.stats.timeProviderS,
        full->wallS, static_cast<unsigned long long>(full->rays.total()));
    say("  speed-up       %.2fx (wall clock), %.2fx (rays)\n", run.wallS > 0 ? full->wallS / run.wallS : 0.0,
        run.rays.total() ? double(full->rays.total()) / double(run.rays.total()) : 0.0);
    if (e2e)
      say("  end to end     dcm %.2f s, full render %.2f s: %.2fx (each as its own process: start-up %.2f s, "
          "scene, outputs)\n", e2e->dcmS, e2e->fullS, e2e->fullS / e2e->dcmS, e2e->startupS);
  }
  if (error) {
    say("  error          PSNR %.2f dB, RMSE %.5f, relMSE %.6f, SSIM %.4f (against %s)\n", error->psnr,
        error->rmse, error->relmse, error->ssim, f.compare.empty() ? "the full render" : f.compare.c_str());
  }
  return kExitOk;
}

/// --frames: one render per frame, '#' in the file names replaced by the frame.
int RunRenderFrames(const RenderFlags& f, CLI::App* app) {
  return RunPerFrame<RenderFlags>(
      "render", f, f.tiles,
      [](RenderFlags* g, const std::function<void(std::string*)>& each) {
        for (auto* name : {&g->scene, &g->output, &g->compare, &g->stats, &g->sampleMap, &g->preview, &g->referenceOut})
          each(name);
      },
      [app](const RenderFlags& g) { return RunRender(g, app); });
}

Registration reg("render", "Ray trace a scene file (Embree) with DCM: a few percent of the pixels exact",
                 [](CLI::App* app) -> std::function<int()> {
                   auto f = std::make_shared<RenderFlags>();
                   app->option_defaults()->group(kGroupIo);
                   app->add_option("scene", f->scene, "scene file (JSON, see plugins/embree/SCENE-FORMAT.md)")
                       ->required();
                   app->add_option("-o,--output", f->output, "output image (EXR)")->required();
                   app->add_option("--compare", f->compare, "reference image (EXR) to report the error against");
                   app->add_option("--stats", f->stats, "write statistics (JSON)");
                   app->add_option("--sample-map", f->sampleMap, "write the sample map (PNG): which pixels were exact, why");
                   app->add_option("--preview", f->preview, "write a display image (PNG) through OpenColorIO");
                   app->add_flag("--with-reference", f->withReference,
                                 "also render the full image in this run: prints the speed-up and the error");
                   app->add_option("--reference-out", f->referenceOut,
                                   "write the full render (EXR); implies --with-reference");
                   auto* size = app->add_option("--size", f->size, "override the resolution, WIDTHxHEIGHT (1 to 16384 each)")
                                    ->check(Parsed("", [](const std::string& s) {
                                      int w = 0, h = 0;
                                      return ParseSize(s, &w, &h);
                                    }));
                   app->add_option("--scale", f->scale, "scale the scene's resolution (e.g. 0.25 for a quick preview)")
                       ->transform(FiniteNumber(1e-3, 16))
                       ->excludes(size);
                   app->add_option("--set", f->overrides,
                                   "override a scene setting before it is read, KEY.PATH=JSON (repeatable), "
                                   "e.g. --set render.shadow_rays=1 --set 'render.indirect={\"bounces\":2,\"rays\":1}'")
                       ->allow_extra_args(false);
                   app->add_option("--seed", f->seed, "override render.seed (an independent render of the same scene)")
                       ->transform(Integer(0, UINT32_MAX));
                   app->add_option("--supersampling", f->supersampling,
                                   "override render.supersampling (samples per output pixel per axis)")
                       ->transform(Integer(1, 16))
                       ->group(kGroupQuality);
                   app->add_option("--estimate-from", f->estimateFrom,
                                   "what judges --target-psnr and --budget: validation pixels traced exactly, or a "
                                   "preview of every pixel at 1/32 of the scene's rays (fewer exact pixels and an "
                                   "estimate that sees every pixel, for the preview's rays and more engine time; "
                                   "final resolution, noise-free exact samples; docs/QUALITY.md)")
                       ->check(CLI::IsMember({"preview", "validation"}))
                       ->capture_default_str()
                       ->group(kGroupQuality);
                   app->add_option("--spp", f->spp,
                                   "override render.samples_per_pixel (independent estimates per exact pixel; "
                                   "from 2 on, samples carry their variance)")
                       ->transform(Integer(1, 1 << 20))
                       ->group(kGroupNoise);
                   app->option_defaults()->group(kGroupIo);
                   AddExrFormatFlags(app, &f->exr);
                   AddDisplayFlags(app, &f->display);
                   app->option_defaults()->group(kGroupGeneral);
                   AddEngineFlags(app, &f->engine);
                   AddTileFlags(app, &f->tiles);
                   return [f, app] { return RunRenderFrames(*f, app); };
                 });

}  // namespace
}  // namespace dcm::cli

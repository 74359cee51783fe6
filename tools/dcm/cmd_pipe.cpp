// dcm pipe: an out-of-process renderer as the provider. dcm starts
// --provider-cmd as a child process and speaks the dcm-pipe protocol
// (plugins/pipe/PROTOCOL.md) on its stdin/stdout: guides once, then batches of
// pixels to evaluate exactly. Any failure of the child ends the command with a
// message, exit status 1 and no output file.
//
// Compiles to nothing unless the dcm_pipe library is linked (DCM_HAVE_PIPE).
#ifdef DCM_HAVE_PIPE

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "common/elapsed.h"
#include "common/image_io.h"
#include "common/output_guard.h"
#include "common/output_transaction.h"
#include "common/progress.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "common/summary.h"
#include "common/tiles.h"
#include "dcm/pipe/pipe_provider.h"
#include "dcm/preview_target.h"
#include "dcm/quality_preview.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"
#include "dcm/window_provider.h"
#include "engine_flags.h"
#include "flag_checks.h"
#include "output_flags.h"
#include "pipe_run.h"

namespace dcm::cli {

void AddProviderTimeoutFlags(CLI::App* app, PipeFlags* f) {
  app->add_option("--provider-timeout", f->timeout,
                  "seconds to wait for any later answer of the provider and for its exit")
      ->transform(FiniteNumber(0, kMaxTimeoutSeconds, /*above=*/true))
      ->capture_default_str()
      ->group(kGroupIo);
  app->add_option("--provider-startup-timeout", f->startupTimeout, "seconds to wait for the provider's handshake")
      ->transform(FiniteNumber(0, kMaxTimeoutSeconds, /*above=*/true))
      ->capture_default_str()
      ->group(kGroupIo);
}

namespace {

/// What the preview schedule did.
struct PreviewRun {
  double previewS = 0;                       ///< fetching the preview
  std::vector<int64_t> pixelsPerCall;        ///< exact pixels of each call, whichever way the goal was judged
  int64_t standIns = 0;                      ///< wanted pixels left at their preview value
  std::optional<PreviewTargetStats> ladder;  ///< a goal judged by the preview
};

/// Why the preview cannot judge the goal of `f` (empty: it can, as far as
/// the flags and the handshake tell; CanTargetFromPreview asks its noise).
std::string PreviewCannotJudge(const pipe::PipeProvider& provider, const ReconstructionOptions& options,
                               const PipeFlags& f) {
  if (f.engine.TargetsRender()) return "--target-psnr render: validation pixels judge the render's own noise";
  if (!f.engine.targetPsnr && !f.engine.budget) return "it judges --target-psnr or --budget, and neither is given";
  if (provider.previewSamples() <= 0)
    return "the provider did not announce preview_samples= (a preview of the same image at fewer samples, "
           "with its variance; plugins/pipe/PROTOCOL.md)";
  if (provider.Capabilities().variance)
    return "the exact samples are noisy, and validation pixels judge them against the converged image";
  if (options.downsample != 1) return "--downsample: the preview estimates at final resolution only";
  if (f.engine.method != "dcm") return "--method " + f.engine.method + ": the preview plans dcm's runs";
  if (f.rounds.previewCorrection < 1) return "--preview-correction 0: the correction makes the estimate";
  return "";
}

/// Reconstructs on the provider's preview (RoundSchedule::kPreview): the
/// preview fetched once, with its variance where the provider gives one (the
/// preview correction needs it), then a few large calls for the exact pixels.
/// With a goal: judged by the preview's estimate where the child announced
/// preview_samples= and the preview can tell (ReconstructToTargetFromPreview,
/// as `dcm blender`), else the validation search in rounds, each run in two
/// calls at most (ReconstructToQualityWithPreview, as `dcm povray`).
Status ReconstructOnPreview(pipe::PipeProvider& provider, const ReconstructionOptions& options, const PipeFlags& f,
                            Reconstruction* rec, std::optional<QualityReport>* quality, PreviewRun* run) {
  const ProviderCapabilities caps = provider.Capabilities();
  PreviewScheduleOptions so;
  std::unique_ptr<SampleProvider> preview;
  const auto t0 = std::chrono::steady_clock::now();
  DCM_RETURN_IF_ERROR(provider.FetchPreview(
      {options.textureSplit && caps.splitRadiance, provider.previewHasVariance()}, &preview,
      VariancePoolRadius(options, caps), &so.previewOwnVariance, &so.previewTextureCovariance));
  run->previewS = toolkit::SecondsSince(t0);
  ApplyRoundFlags(f.rounds, &so);
  QualityGoal goal;
  if (!QualityGoalOf(f.engine, &goal)) {
    PreviewScheduleStats sched;
    DCM_RETURN_IF_ERROR(ReconstructWithPreview(provider, *preview, options, so, rec, &sched));
    run->pixelsPerCall = sched.pixelsPerRound;
    run->standIns = sched.previewStandIns;
    return Status::Ok();
  }
  if (f.estimateFrom != "validation") {
    std::string why = PreviewCannotJudge(provider, options, f);
    if (why.empty() && CanTargetFromPreview(*preview, so, &why)) {
      if (f.engine.verbose) std::cerr << "the goal is judged by the preview's estimate\n";
      QualityReport report;
      PreviewTargetStats ladder;
      DCM_RETURN_IF_ERROR(ReconstructToTargetFromPreview(provider, *preview, options, goal, so, rec, &report, &ladder));
      run->pixelsPerCall = ladder.pixelsPerRound;
      run->standIns = ladder.last.previewStandIns;
      run->ladder = std::move(ladder);
      *quality = std::move(report);
      return Status::Ok();
    }
    if (f.estimateFrom == "preview") return Status::Error("--estimate-from preview: " + why);
    if (f.engine.verbose) std::cerr << "the goal is judged by validation pixels: " << why << "\n";
  }
  LimitRoundsForValidation(&so);
  QualityReport report;
  QualityRoundStats rounds;
  DCM_RETURN_IF_ERROR(ReconstructToQualityWithPreview(provider, *preview, options, goal, so, rec, &report, &rounds));
  run->pixelsPerCall = rounds.pixelsPerRound;
  run->standIns = rounds.previewStandIns;
  *quality = std::move(report);
  return Status::Ok();
}

}  // namespace

int RunPipe(const std::string& cmd, const PipeFlags& f) {
  auto Fail = [&cmd](const std::string& message, int code = kExitFailure) {
    std::cerr << "dcm " << cmd << ": error: " << message << "\n";
    return code;
  };
  ReconstructionOptions options;
  if (Status st = ToOptions(f.engine, &options); !st.ok()) return Fail(st.message(), kExitUsage);
  if (!f.tiles.frames.empty())
    return Fail("--frames is not for a provider command (run one dcm pipe per frame)", kExitUsage);
  const bool partial = IsPartial(f.tiles);
  if (Status st = toolkit::CheckExrFormat(f.exr); !st.ok()) return Fail(st.message(), kExitUsage);
  if (partial && !(f.exr.dataType.empty() && f.exr.channels.empty() &&
                   f.exr.compression == toolkit::ExrFormat{}.compression))
    return Fail("-d, --compression and --ch shape the whole frame; give them to `dcm merge`", kExitUsage);
  if (partial && !f.engine.progressive.empty())
    return Fail("--progressive needs the whole frame; not with --tile or --region", kExitUsage);
  if (partial && (f.engine.targetPsnr || f.engine.budget))
    return Fail("--target-psnr and --budget estimate the whole frame; not with --tile or --region", kExitUsage);

  if (Status st = toolkit::CheckOutputs({}, {{"-o", f.output},
                                             {"--stats", f.stats},
                                             {"--sample-map", f.sampleMap},
                                             toolkit::ProgressiveArg(f.engine.progressive)});
      !st.ok())
    return Fail(st.message(), kExitUsage);
  // Every output of the run appears at its Commit(), or none; a signal ends the child too.
  toolkit::OutputTransaction outputs;
  toolkit::SetSignalHook(pipe::KillAllChildren);

  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<pipe::PipeProvider> provider;
  pipe::PipeOptions po;
  po.command = f.command;
  po.timeoutSeconds = f.timeout;
  po.startupTimeoutSeconds = f.startupTimeout;
  if (Status st = pipe::PipeProvider::Start(po, &provider); !st.ok()) return Fail(st.message());
  const ProviderCapabilities caps = provider->Capabilities();
  if (f.engine.verbose) {
    std::cerr << "provider '" << caps.name << "' (dcm-pipe " << provider->childProtocolVersion() << "): "
              << caps.width << "x" << caps.height << (caps.objectId ? ", object IDs" : "")
              << (caps.shaderId ? ", shader IDs" : "") << (caps.texture ? ", texture" : "")
              << (caps.splitRadiance ? ", split radiance" : "") << "\n"
              << "engine settings: " << SettingsSummary(options, caps) << "\n";
  }
  if (Status st = CheckDownsample(caps.width, caps.height, options.downsample, "the provider's image"); !st.ok())
    return Fail(st.message(), kExitUsage);

  // --tile / --region: the part of the frame, its window asked of the child.
  const Point2i frame = OutputSize(caps.width, caps.height, options.downsample);
  Bounds2i region;
  std::string tile;
  if (partial) {
    if (Status st = ResolveRegion(f.tiles, frame.x, frame.y, TileAlignment(options), &region, &tile); !st.ok())
      return Fail(st.message(), kExitUsage);
  }
  // A provider whose calls cost a latency: its exact pixels planned on its
  // preview, in a few calls. A part of the frame and --progressive follow the
  // levels, whose steps they are made of.
  RoundSchedule schedule = RoundSchedule::kLevels;
  if (!partial && f.engine.progressive.empty() && !options.fullEvaluation) {
    if (Status st = ScheduleFor(f.rounds, provider->roundCost(), provider->hasPreview(), &schedule); !st.ok())
      return Fail(st.message(), kExitUsage);
  } else if (f.rounds.schedule == "preview") {
    return Fail("--schedule preview: not with --tile, --region, --progressive or --full (they follow the levels)",
                kExitUsage);
  }
  if (f.estimateFrom == "preview" && schedule != RoundSchedule::kPreview)
    return Fail("--estimate-from preview: needs the preview schedule (a provider that announced a round_latency and "
                "a preview, or --schedule preview; not with --tile, --region, --progressive or --full)",
                kExitUsage);
  if (f.engine.verbose && schedule == RoundSchedule::kPreview)
    std::cerr << "schedule preview: a call costs " << provider->roundCost().latencyS << " s besides "
              << provider->roundCost().perSampleS << " s a pixel; the exact pixels are chosen on the preview and "
              << "asked for in at most " << f.rounds.maxRounds << " calls\n";
  toolkit::Progress progress(!f.engine.quiet);
  options.progress = [&](float v, std::string_view stage) { progress.Update(v, stage); };
  Reconstruction rec;
  RegionInfo info;
  std::optional<QualityReport> quality;
  PreviewRun previewRun;
  Status st = partial ? ReconstructRegion(*provider, options, region, &rec, &info)
              : schedule == RoundSchedule::kPreview
                  ? ReconstructOnPreview(*provider, options, f, &rec, &quality, &previewRun)
                  : ReconstructFor(*provider, options, f.engine, &rec, &quality);
  progress.Done();
  if (!st.ok()) return Fail(st.message());
  // The child must end cleanly before anything is written.
  if (Status fin = provider->Finish(); !fin.ok()) return Fail(fin.message());
  const double wallS = toolkit::SecondsSince(t0);
  const ReconstructionStats& stats = rec.stats;
  if (f.engine.verbose) std::cerr << toolkit::StageTimesLine(stats) << "\n";
  if (f.engine.verbose && quality) std::cerr << QualityLine(*quality, f.engine) << "\n";
  const std::string method = options.fullEvaluation ? "full" : f.engine.method;

  toolkit::Metadata meta;
  meta.strings.push_back({"dcm:provider", "pipe"});
  meta.strings.push_back({"dcm:provider_name", caps.name});
  meta.strings.push_back({"dcm:method", method});
  meta.strings.push_back({"dcm:options", toolkit::OptionsToJson(options).dump()});
  meta.floats.push_back({"dcm:exact_fraction", float(stats.exactFraction())});
  meta.floats.push_back({"dcm:time_illum_s", float(stats.timeProviderS)});
  meta.floats.push_back({"dcm:time_dcm_s", float(stats.timeEngineS)});
  if (quality) toolkit::AddQualityMetadata(*quality, &meta);
  if (partial) {
    // What decides the pixels besides the options: the provider command (so
    // every tile must run the same one) and what the provider announced. The
    // same for `dcm pipe` and `dcm reconstruct --provider-cmd`, which are one
    // computation.
    const nlohmann::json settings = toolkit::PartSettings(
        "pipe", DCM_VERSION, options,
        {{"provider_cmd", f.command}, {"provider_name", caps.name}, {"width", caps.width}, {"height", caps.height},
         {"object_id", caps.objectId}, {"shader_id", caps.shaderId}, {"texture", caps.texture},
         {"split", caps.splitRadiance}, {"variance", caps.variance}, {"hard_shadows_guided", caps.hardShadowsGuided}});
    AddPartMetadata(tile, region, settings, rec, info, &meta);
    if (Status w = toolkit::WritePartExr(f.output, frame.x, frame.y, region, rec.image, meta); !w.ok())
      return Fail(w.message());
  } else if (Status w = toolkit::WriteRgbExr(f.output, Bounds2i{{0, 0}, {rec.width, rec.height}},
                                             Bounds2i{{0, 0}, {rec.width, rec.height}}, rec.image, meta, false, f.exr);
             !w.ok()) {
    return Fail(w.message());
  }
  if (!f.sampleMap.empty()) {
    if (Status w = toolkit::WriteSampleMap(f.sampleMap, rec); !w.ok()) return Fail(w.message());
  }
  if (!f.stats.empty()) {
    nlohmann::json j = toolkit::RunToJson(rec, method, options, wallS);
    j["provider"] = "pipe";
    j["provider_name"] = caps.name;
    j["provider_cmd"] = f.command;
    if (partial) j["part"] = PartJson(tile, info);
    j["schedule"] = std::string(ToString(schedule));
    if (schedule == RoundSchedule::kPreview) {
      j["preview"] = {{"time_s", previewRun.previewS},
                      {"pixels_per_call", previewRun.pixelsPerCall},
                      {"stand_ins", previewRun.standIns}};
    }
    if (quality) toolkit::AddQualityJson(*quality, f.engine.targetPsnr.value_or(0), f.engine.budget.value_or(0), &j);
    if (quality && previewRun.ladder) toolkit::AddLadderJson(*previewRun.ladder, &j["quality"]);
    if (Status w = toolkit::WriteJson(f.stats, j); !w.ok()) return Fail(w.message());
  }
  if (Status w = outputs.Commit(); !w.ok()) return Fail(w.message());

  const toolkit::Summary say(!f.engine.quiet);
  if (partial)
    say("%s: %s %s of %dx%d (window %dx%d working pixels), %s, provider '%s'\n", f.output.c_str(),
        tile.empty() ? "region" : "tile", tile.empty() ? toolkit::RegionText(region).c_str() : tile.c_str(),
        frame.x, frame.y, info.window.width(), info.window.height(), method.c_str(), caps.name.c_str());
  else
    say("%s: %dx%d (working %dx%d), %s, provider '%s'\n", f.output.c_str(), rec.width, rec.height,
        rec.workWidth, rec.workHeight, method.c_str(), caps.name.c_str());
  say("  exact pixels   %.2f %% (%lld of %lld)\n", 100.0 * stats.exactFraction(),
      static_cast<long long>(stats.exactPixels), static_cast<long long>(stats.totalPixels));
  say("  time           provider %.2f s, DCM %.2f s, guides %.2f s, total %.2f s\n", stats.timeProviderS,
      stats.timeEngineS, stats.timeGuidesS, wallS);
  say("  provider calls %lld\n", static_cast<long long>(stats.providerCalls));
  if (quality) say("  quality        %s\n", QualityLine(*quality, f.engine).c_str());
  if (quality)
    if (const std::string w = QualityWarning(*quality, f.engine); !w.empty())
      std::cerr << "dcm " << cmd << ": warning: " << w << "\n";
  for (const auto& w : toolkit::SampleWarnings(stats)) std::cerr << "dcm " << cmd << ": warning: " << w << "\n";
  return kExitOk;
}

namespace {

Registration reg("pipe", "Reconstruct with an external renderer as a child process (dcm-pipe protocol)",
                 [](CLI::App* app) -> std::function<int()> {
                   auto f = std::make_shared<PipeFlags>();
                   app->option_defaults()->group(kGroupIo);
                   app->add_option("--provider-cmd", f->command,
                                   "shell command of the provider (run with /bin/sh -c; see plugins/pipe/PROTOCOL.md)")
                       ->required();
                   app->add_option("-o,--output", f->output, "output image (EXR)")->required();
                   app->add_option("--stats", f->stats, "write statistics (JSON)");
                   app->add_option("--sample-map", f->sampleMap, "write the sample map (PNG): which pixels were exact, why");
                   app->option_defaults()->group(kGroupGeneral);
                   AddProviderTimeoutFlags(app, f.get());
                   AddExrFormatFlags(app, &f->exr);
                   AddEngineFlags(app, &f->engine);
                   AddRoundFlags(app, &f->rounds);
                   app->add_option("--estimate-from", f->estimateFrom,
                                   "what judges --target-psnr and --budget on the preview schedule: the preview's "
                                   "estimate at every pixel (a child that announced preview_samples=, noise-free "
                                   "exact samples), validation pixels rendered exactly, or auto (the preview where "
                                   "it can tell)")
                       ->check(CLI::IsMember({"auto", "preview", "validation"}))
                       ->capture_default_str();
                   AddTileFlags(app, &f->tiles);
                   return [f] { return RunPipe("pipe", *f); };
                 });

}  // namespace
}  // namespace dcm::cli

#endif  // DCM_HAVE_PIPE

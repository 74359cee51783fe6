// dcm povray: a POV-Ray 3.7 render of a scene written with the pass
// convention (docs/POVRAY.md), made by rendering only the pixels DCM needs.
//
//   dcm povray SCENE.pov -o OUT.exr --size WxH [--full] [--povray PATH]
//       [--stats S.json] [--sample-map M.png] [--reference REF.exr]
//       [--schedule auto|preview|levels] [--max-rounds N] [--preview-scale N] [--preview-passes P]
//       [-d half|float] [--compression C] [--ch NAME,...] + engine flags
//
// The guide passes (IDs, tau, normal, highlight mask) are rendered in full,
// and with them the illumination pass (--preview-passes) at 1/N resolution
// as a preview; the engine plans its exact pixels on the preview and POV-Ray
// renders them through the scene's mesh camera in a few rounds
// (RoundSchedule::kPreview). --full renders the beauty pass in full instead:
// the baseline.
//
// Compiles to nothing unless the dcm_povray library is linked (DCM_HAVE_POVRAY).
#ifdef DCM_HAVE_POVRAY

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "commands.h"
#include "common/elapsed.h"
#include "common/image_io.h"
#include "common/metrics.h"
#include "common/output_guard.h"
#include "common/output_transaction.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "common/summary.h"
#include "dcm/downsample.h"
#include "dcm/povray/povray_preview.h"
#include "dcm/povray/povray_provider.h"
#include "dcm/quality_preview.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"
#include "engine_flags.h"
#include "flag_checks.h"
#include "output_flags.h"

namespace dcm::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct PovrayFlags {
  std::string scene, output, stats, sampleMap, reference, size;
  std::string povray = "povray";
  std::string previewPasses = "illumination";  ///< the lit passes the preview renders
  int previewScale = 8;  ///< the preview's pixels are N x N working pixels
  RoundFlags rounds{"auto", 2};  ///< --schedule, --max-rounds: 2 rounds keep the lit passes to 5 processes
  int processes = 2;     ///< POV-Ray processes at a time
  EngineFlags engine;
  toolkit::ExrFormat exr;
};

int Fail(const std::string& message, int code = kExitFailure) {
  std::cerr << "dcm povray: error: " << message << "\n";
  return code;
}

/// "WxH" into positive integers.
Status ParseSize(const std::string& s, int* w, int* h) {
  const size_t x = s.find('x');
  auto number = [](const std::string& t, int* v) {
    if (t.empty() || t.size() > 5 || t.find_first_not_of("0123456789") != std::string::npos) return false;
    *v = std::stoi(t);
    return *v >= 1;
  };
  if (x == std::string::npos || !number(s.substr(0, x), w) || !number(s.substr(x + 1), h))
    return Status::Error("--size: must be WIDTHxHEIGHT in pixels, 1 to 99999 each (e.g. 512x512), got '" + s + "'");
  return Status::Ok();
}

/// The preview's L_i and L_c at its pixels from the lit passes it rendered
/// (`beauty`, `Li`: either may be empty), with tau at the working pixel under
/// the preview pixel's centre. Both passes: L_c = L - L_i*tau, never below
/// zero (tau is sampled half a pixel away from the preview's ray at a texture
/// edge). One pass: L_c = 0 (the preview has no highlights; the exact rounds
/// do), and from the beauty alone L_i = L/tau.
void PreviewSplit(const std::vector<RGB>& beauty, std::vector<RGB>* Li, int pw, int ph, int W, int H,
                  const std::vector<RGB>& tau, std::vector<RGB>* Lc) {
  const size_t n = size_t(pw) * size_t(ph);
  const bool haveL = !beauty.empty(), haveLi = !Li->empty();
  Li->resize(n);
  Lc->assign(n, RGB{});
  if (!haveL) return;
  for (int y = 0; y < ph; ++y)
    for (int x = 0; x < pw; ++x) {
      const int fx = std::min(W - 1, int((x + 0.5) * W / pw)), fy = std::min(H - 1, int((y + 0.5) * H / ph));
      const size_t i = size_t(y) * size_t(pw) + size_t(x);
      const RGB t = tau[size_t(fy) * size_t(W) + size_t(fx)];
      if (haveLi) {
        const RGB d = beauty[i] - (*Li)[i] * t;
        (*Lc)[i] = RGB{std::max(0.f, d.r), std::max(0.f, d.g), std::max(0.f, d.b)};
      } else {
        for (int c = 0; c < 3; ++c) (*Li)[i][c] = t[c] > 1e-4f ? beauty[i][c] / t[c] : 0.f;
      }
    }
}

/// Fails before any rendering when an output's folder cannot take a file: the
/// output transaction would find out only after the whole render.
Status CheckOutputFolders(std::initializer_list<std::pair<const char*, std::string>> outputs) {
  for (const auto& [flag, path] : outputs) {
    if (path.empty()) continue;
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    const std::string dir = parent.empty() ? "." : parent.string();
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
      return Status::Error(std::string(flag) + ": cannot write '" + path + "': its folder " + dir + ": " +
                           std::strerror(errno));
  }
  return Status::Ok();
}

int RunPovray(const PovrayFlags& f) {
  const auto t0 = Clock::now();
  int outW = 0, outH = 0;
  if (Status st = ParseSize(f.size, &outW, &outH); !st.ok()) return Fail(st.message(), kExitUsage);
  ReconstructionOptions options;
  if (Status st = ToOptions(f.engine, &options); !st.ok()) return Fail(st.message(), kExitUsage);
  if (Status st = toolkit::CheckExrFormat(f.exr); !st.ok()) return Fail(st.message(), kExitUsage);
  const bool full = options.fullEvaluation;
  if (full && !f.sampleMap.empty())
    return Fail("--sample-map: with --full every pixel is rendered, there is no sample map", kExitUsage);
  const int W = outW * options.downsample, H = outH * options.downsample;
  if (Status st = toolkit::CheckOutputs({{"SCENE", f.scene}, {"--reference", f.reference}},
                                        {{"-o", f.output}, {"--stats", f.stats}, {"--sample-map", f.sampleMap}});
      !st.ok())
    return Fail(st.message(), kExitUsage);

  if (Status st = CheckOutputFolders({{"-o", f.output}, {"--stats", f.stats}, {"--sample-map", f.sampleMap}});
      !st.ok())
    return Fail(st.message());
  // Every output appears at Commit(), or none; a signal ends POV-Ray and
  // removes the scratch folder too.
  toolkit::OutputTransaction outputs;
  toolkit::SetSignalHook(povray::SignalCleanup);
  std::unique_ptr<povray::PovrayProvider> provider;
  povray::PovrayOptions po;
  po.scene = f.scene;
  po.povray = f.povray;
  po.width = W;
  po.height = H;
  po.concurrency = f.processes;
  if (Status st = povray::PovrayProvider::Open(po, &provider); !st.ok()) return Fail(st.message());
  RoundSchedule schedule{};
  if (Status st = ScheduleFor(f.rounds, provider->Cost(), /*previewAvailable=*/true, &schedule); !st.ok())
    return Fail(st.message(), kExitUsage);

  Reconstruction rec;
  PreviewScheduleStats sched;
  // --target-psnr / --budget: the quality search, each run planned on the preview.
  QualityGoal goal;
  const bool haveGoal = QualityGoalOf(f.engine, &goal);
  std::optional<QualityReport> quality;
  QualityRoundStats qrounds;
  double denseS = 0, engineS = 0;
  int64_t previewPixels = 0;
  if (full) {
    // The baseline: the beauty pass in full, as a POV-Ray user renders it.
    const auto td = Clock::now();
    std::vector<std::vector<RGB>> beauty;
    const povray::Pass pass[] = {povray::Pass::kBeauty};
    if (Status st = provider->RenderDense(pass, W, H, &beauty); !st.ok()) return Fail(st.message());
    denseS = toolkit::SecondsSince(td);
    rec.image = BoxDownsample(beauty[0], W, H, options.downsample, &rec.width, &rec.height);
    rec.workWidth = W;
    rec.workHeight = H;
    rec.stats.totalPixels = rec.stats.exactPixels = int64_t(W) * H;
  } else {
    const auto td = Clock::now();
    const int pw = (W + f.previewScale - 1) / f.previewScale, ph = (H + f.previewScale - 1) / f.previewScale;
    std::vector<std::vector<RGB>> preview;
    std::vector<povray::Pass> lit;
    if (schedule == RoundSchedule::kPreview) {
      if (f.previewPasses != "illumination") lit.push_back(povray::Pass::kBeauty);
      if (f.previewPasses != "beauty") lit.push_back(povray::Pass::kIllumination);
    }
    Status st = provider->RenderGuides(lit, pw, ph, &preview);
    if (!st.ok()) return Fail(st.message());
    denseS = toolkit::SecondsSince(td);
    if (f.engine.verbose)
      std::cerr << "dcm povray: engine settings: " << SettingsSummary(options, provider->Capabilities()) << "\n"
                << "dcm povray: highlight mask (pass 6): "
                << (provider->haveHighlightMask() ? "found, L_i rendered only where it marks"
                                                  : "not in the scene, L_i rendered for every exact pixel")
                << "\n";
    const auto te = Clock::now();
    if (schedule == RoundSchedule::kPreview) {
      previewPixels = int64_t(pw) * ph;
      GuideImage g;
      GuideRequest want;
      want.texture = true;
      if (st = provider->Guides(Bounds2i{{0, 0}, {W, H}}, want, &g); !st.ok()) return Fail(st.message());
      std::vector<RGB> L, Li, Lc;
      for (size_t i = 0; i < lit.size(); ++i) (lit[i] == povray::Pass::kBeauty ? L : Li) = std::move(preview[i]);
      PreviewSplit(L, &Li, pw, ph, W, H, g.texture, &Lc);
      // With a goal, stand-ins from the preview alone: one that borrowed from
      // rendered neighbours would take a validation pixel's own exact value,
      // and the estimate would err high.
      povray::PovrayPreview previewProvider(*provider, pw, ph, std::move(Li), std::move(Lc), haveGoal ? -1 : 2);
      PreviewScheduleOptions so;
      ApplyRoundFlags(f.rounds, &so);
      if (haveGoal) {
        LimitRoundsForValidation(&so);
        QualityReport report;
        st = ReconstructToQualityWithPreview(*provider, previewProvider, options, goal, so, &rec, &report, &qrounds);
        if (st.ok()) quality = std::move(report);
        sched.previewStandIns = qrounds.previewStandIns;
      } else {
        st = ReconstructWithPreview(*provider, previewProvider, options, so, &rec, &sched);
      }
    } else {
      st = ReconstructFor(*provider, options, f.engine, &rec, &quality);
    }
    if (!st.ok()) return Fail(st.message());
    engineS = toolkit::SecondsSince(te);
    for (double s : provider->runStats().roundS) engineS -= s;
  }
  const povray::PovrayRunStats runs = provider->runStats();

  nlohmann::json j = toolkit::RunToJson(rec, full ? "full" : f.engine.method, options, 0);
  toolkit::ImageError error;
  const bool haveRef = !f.reference.empty();
  if (haveRef) {
    int rw = 0, rh = 0;
    std::vector<RGB> ref;
    if (Status st = toolkit::ReadRgb(f.reference, &rw, &rh, &ref); !st.ok()) return Fail(st.message());
    if (rw != rec.width || rh != rec.height)
      return Fail("--reference " + f.reference + " is " + std::to_string(rw) + "x" + std::to_string(rh) +
                  ", the output " + std::to_string(rec.width) + "x" + std::to_string(rec.height));
    error = toolkit::Compare(rec.image, ref, rec.width, rec.height);
    j["reference"] = {{"file", f.reference}, {"psnr", error.psnr}, {"rmse", error.rmse}};
  }
  j["provider"] = "povray";
  j["scene"] = f.scene;
  j["schedule"] = full ? "full" : std::string(ToString(schedule));
  nlohmann::json p;
  p["invocations"] = runs.invocations;
  p["lit_invocations"] = runs.litInvocations;
  p["rounds"] = runs.roundS.size();
  p["round_pixels"] = runs.roundPixels;
  p["illumination_pixels"] = runs.illuminationPixels;
  p["highlight_mask"] = !full && provider->haveHighlightMask();
  p["preview_scale"] = full || schedule != RoundSchedule::kPreview ? 0 : f.previewScale;
  p["preview_pixels"] = previewPixels;
  p["preview_passes"] = full || schedule != RoundSchedule::kPreview ? "" : f.previewPasses;
  // The engine counts the stand-ins among its exact pixels (exact_pixels).
  p["preview_stand_ins"] = sched.previewStandIns;
  // The quality search counts only what was rendered.
  p["exact_pixels_rendered"] = quality && schedule == RoundSchedule::kPreview
                                   ? qrounds.renderedPixels
                                   : rec.stats.exactPixels - sched.previewStandIns;
  p["processes_at_a_time"] = f.processes;
  nlohmann::json phases;
  phases[full ? "full_s" : "guides_and_preview_s"] = denseS;
  phases["rounds_s"] = runs.roundS;
  phases["engine_s"] = engineS;
  p["phases_s"] = phases;
  j["povray"] = p;
  if (quality) {
    toolkit::AddQualityJson(*quality, f.engine.targetPsnr.value_or(0), f.engine.budget.value_or(0), &j);
    if (schedule == RoundSchedule::kPreview) j["quality"]["searches"] = qrounds.passes;
  }

  toolkit::Metadata meta;
  meta.strings.push_back({"dcm:provider", "povray"});
  meta.strings.push_back({"dcm:scene", f.scene});
  meta.strings.push_back({"dcm:command_line", toolkit::CommandLine()});
  meta.strings.push_back({"dcm:method", full ? "full" : f.engine.method});
  meta.strings.push_back({"dcm:options", toolkit::OptionsToJson(options).dump()});
  meta.floats.push_back({"dcm:exact_fraction", float(rec.stats.exactFraction())});
  if (quality) toolkit::AddQualityMetadata(*quality, &meta);
  const Bounds2i frame{{0, 0}, {rec.width, rec.height}};
  if (Status w = toolkit::WriteRgbExr(f.output, frame, frame, rec.image, meta, false, f.exr); !w.ok())
    return Fail(w.message());
  if (!f.sampleMap.empty())
    if (Status w = toolkit::WriteSampleMap(f.sampleMap, rec); !w.ok()) return Fail(w.message());
  // The wall clock up to the outputs' commit, the process's own start-up not included.
  j["time_wall_s"] = toolkit::SecondsSince(t0);
  if (!f.stats.empty())
    if (Status w = toolkit::WriteJson(f.stats, j); !w.ok()) return Fail(w.message());
  if (Status w = outputs.Commit(); !w.ok()) return Fail(w.message());
  provider.reset();  // the scratch folder goes before the summary

  const toolkit::Summary say(!f.engine.quiet);
  say("%s: %dx%d, %s, %d POV-Ray processes (%d lit), %.2f s\n", f.output.c_str(), rec.width, rec.height,
      full ? "full render" : "dcm", runs.invocations, runs.litInvocations, toolkit::SecondsSince(t0));
  if (!full) {
    say("  exact pixels   %.2f %% (%lld of %lld) in %zu rounds", 100.0 * rec.stats.exactFraction(),
        static_cast<long long>(rec.stats.exactPixels), static_cast<long long>(rec.stats.totalPixels),
        runs.roundS.size());
    if (sched.previewStandIns) say(", %lld preview stand-ins", static_cast<long long>(sched.previewStandIns));
    say("\n  time           guides+preview %.2f s, rounds", denseS);
    for (double s : runs.roundS) say(" %.2f", s);
    say(" s, engine %.2f s\n", engineS);
  }
  if (quality) say("  quality        %s\n", QualityLine(*quality, f.engine).c_str());
  if (haveRef) say("  PSNR           %.2f dB against %s\n", error.psnr, f.reference.c_str());
  if (quality) {
    if (f.engine.verbose) std::cerr << QualityLine(*quality, f.engine) << "\n";
    if (const std::string w = QualityWarning(*quality, f.engine); !w.empty())
      std::cerr << "dcm povray: warning: " << w << "\n";
  }
  return kExitOk;
}

Registration reg("povray", "Render a POV-Ray scene (the pass convention of docs/POVRAY.md) with DCM",
                 [](CLI::App* app) -> std::function<int()> {
                   auto f = std::make_shared<PovrayFlags>();
                   app->option_defaults()->group(kGroupIo);
                   app->add_option("SCENE", f->scene, "the scene (.pov) with the pass convention")->required();
                   app->add_option("-o,--output", f->output, "output image (EXR: R, G, B)")->required();
                   app->add_option("--size", f->size, "the frame, WIDTHxHEIGHT pixels (e.g. 1024x1024)")->required();
                   app->add_option("--povray", f->povray, "the POV-Ray 3.7 executable (a path, or a name on PATH)")
                       ->capture_default_str();
                   app->add_option("--stats", f->stats, "statistics as JSON: exact fraction, POV-Ray processes, "
                                                        "seconds per phase");
                   app->add_option("--sample-map", f->sampleMap, "PNG: which pixels were rendered, and why");
                   app->add_option("--reference", f->reference, "an EXR to compare the output with (PSNR in --stats)");
                   app->add_option("--processes", f->processes, "POV-Ray processes at a time")
                       ->transform(Integer(1, 64))
                       ->capture_default_str();
                   AddRoundFlags(app, &f->rounds);
                   app->option_defaults()->group(kGroupRounds);
                   app->add_option("--preview-scale", f->previewScale,
                                   "the preview renders 1/N of the width and of the height")
                       ->transform(Integer(1, 64))
                       ->capture_default_str();
                   app->add_option("--preview-passes", f->previewPasses,
                                   "the lit passes the preview renders: illumination (L = L_i*tau, one process), "
                                   "beauty (L_i = L/tau), or both (two processes)")
                       ->check(CLI::IsMember({"illumination", "beauty", "both"}))
                       ->capture_default_str();
                   app->option_defaults()->group(kGroupGeneral);
                   AddExrFormatFlags(app, &f->exr);
                   AddEngineFlags(app, &f->engine);
                   app->get_option("--full")->description("render the beauty pass in full (the baseline)");
                   app->get_option("--downsample")
                       ->description("render N times --size per axis and box-filter the result down (antialiasing)");
                   // The preview schedule runs the engine several times: no level images.
                   app->remove_option(app->get_option("--progressive"));
                   return [f] { return RunPovray(*f); };
                 });

}  // namespace
}  // namespace dcm::cli

#endif  // DCM_HAVE_POVRAY

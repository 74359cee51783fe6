// dcm blender: a user's .blend rendered by Cycles only at the pixels DCM asks
// for. Blender starts once as a dcm-pipe child (plugins/blender/child_main.py)
// that renders the guides and a few-samples preview in one render call, then
// each round of exact pixels in masked render calls at full samples (two
// halves with two seeds, so that dcm knows the pixels' variance); dcm plans the
// rounds on the preview (RoundSchedule::kPreview) and writes a multilayer EXR
// with Blender's names. Nothing is written on failure, and no
// Blender is left running.
//
//   dcm blender SCENE.blend -o OUT.exr [--stats S.json] [--samples N] [--frames A-B]
//       [--blender PATH] + the engine and EXR flags of `dcm reconstruct`
//
// Compiles to nothing unless the dcm_pipe library is linked (DCM_HAVE_PIPE).
#ifdef DCM_HAVE_PIPE

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "blender_files.h"
#include "commands.h"
#include "common/elapsed.h"
#include "common/output_exr.h"
#include "common/output_guard.h"
#include "common/output_transaction.h"
#include "common/progress.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "common/summary.h"
#include "dcm/exact_noise_meter.h"
#include "dcm/noise_estimate.h"
#include "dcm/pipe/pipe_provider.h"
#include "dcm/pipe/run_command.h"
#include "dcm/pipe/scratch_folder.h"
#include "dcm/preview_target.h"
#include "dcm/quality_preview.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"
#include "engine_flags.h"
#include "flag_checks.h"
#include "output_flags.h"
#include "pipe_run.h"

namespace dcm::cli {
namespace {

using pipe::ShellQuote;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// The goal without --threshold, --target-psnr or --budget: 40 dB of
/// display-referred PSNR against the converged image (the bar of the speed-ups
/// in docs/BLENDER.md), where the preview can judge it (docs/QUALITY.md).
constexpr double kDefaultTargetPsnr = 40;

/// Where the render's own noise, from the ratio of samples, lies this far
/// beyond a target judged by the preview, the exact pixels' noise is not
/// measured: with every pixel exact it would be a quarter of the target's
/// squared error, and the ratio overstated it on every scene measured
/// (docs/BLENDER.md, *Exact pixels with their variance*), so the estimate
/// errs low, by less than 0.4 dB at 35 % exact pixels.
constexpr double kMeasureNoiseMarginDb = 6;

struct BlenderFlags {
  std::string scene, output, stats, sampleMap;
  std::string blender = "blender";
  std::string frames;      ///< A-B: one output per frame, '#' in -o replaced by the frame number
  std::string viewLayer;   ///< empty: the first that renders
  int samples = 0;         ///< 0: the file's
  int previewSamples = 0;  ///< 0: samples / 16, at least 16
  /// on: the exact pixels pooled with their preview (its own seeds: PreviewScheduleOptions::poolPreview)
  std::string poolPreview = "on";
  /// Every exact pixel at `samples`, also where a goal in dB needs fewer.
  bool fixedSamples = false;
  int renderThreads = 0;
  /// Exact pixels as two halves with two seeds; their variance to the engine:
  /// auto where the preview's halves say the noise matters (kNoisyPsnr), on, off
  /// (one render per pixel).
  std::string variance = "auto";
  /// The exact pixels' variance after the round that measured their noise:
  /// preview (its own times the measured share, one render call per round) or
  /// halves (their own, two calls).
  std::string varianceFrom = "preview";
  /// What judges --target-psnr: auto (the preview where it can tell), preview, validation.
  std::string estimateFrom = "auto";
  PipeFlags pipe;  ///< --provider-timeout, --provider-startup-timeout; engine; EXR format
};

/// "40": the default goal as a flag value.
std::string DefaultTarget() { return std::to_string(int(kDefaultTargetPsnr)); }

/// Undoes the child's percent-encoding of a handshake value.
std::string PercentDecoded(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(uint8_t(s[i + 1])) && std::isxdigit(uint8_t(s[i + 2]))) {
      out += char(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

/// Times every call of the exact provider: a round each with the preview schedule.
class TimedProvider final : public SampleProvider {
 public:
  explicit TimedProvider(SampleProvider& p) : p_(p) {}
  ProviderCapabilities Capabilities() const override { return p_.Capabilities(); }
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    step = "reading the guides";
    const auto t = Clock::now();
    Status st = p_.Guides(region, what, out);
    guidesS += toolkit::SecondsSince(t);
    return st;
  }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    step = "rendering exact pixels (call " + std::to_string(rounds.size() + 1) + ", " +
           std::to_string(pixels.size()) + " pixels)";
    const auto t = Clock::now();
    Status st = p_.Evaluate(pixels, what, out);
    rounds.push_back({int64_t(pixels.size()), toolkit::SecondsSince(t)});
    return st;
  }
  void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) override {
    p_.TakeExtraSamples(pixels, samples);
    extraPixels += int64_t(pixels->size());
  }
  struct Round {
    int64_t pixels;
    double seconds;
  };
  std::vector<Round> rounds;
  int64_t extraPixels = 0;  ///< exact pixels the rounds gave besides those asked for
  double guidesS = 0;
  std::string step = "planning";  ///< what the last call did, for messages

 private:
  SampleProvider& p_;
};

/// Pools the variance the child reports per exact pixel (from that pixel's two
/// halves alone: one degree of freedom per channel, often near 0 or several
/// times the truth) over the exact pixels known so far on the same surface
/// (equal object and shader IDs) within one noisy elementary block
/// as a share of the value (dcm::SurfaceWindowRelativeMean): a lattice corner
/// then pools the corners around it, and a pixel on an edge its neighbours
/// along the edge.
/// `use` false: the samples go to the engine without variance.
class PooledVarianceProvider final : public SampleProvider {
 public:
  PooledVarianceProvider(SampleProvider& p, int radius, bool use)
      : p_(p), caps_(p.Capabilities()), radius_(radius) {
    caps_.variance = caps_.variance && use;
  }
  ProviderCapabilities Capabilities() const override { return caps_; }
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    return p_.Guides(region, what, out);
  }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    DCM_RETURN_IF_ERROR(p_.Evaluate(pixels, what, out));
    p_.TakeExtraSamples(&extraPixels_, &extraSamples_);
    if (!what.variance || pixels.empty()) return Status::Ok();
    const size_t n = size_t(caps_.width) * size_t(caps_.height);
    if (raw_.empty()) {
      // The surfaces, once: the IDs the engine reads too.
      GuideImage g;
      DCM_RETURN_IF_ERROR(p_.Guides(Bounds2i{{0, 0}, {caps_.width, caps_.height}},
                                    {caps_.objectId, caps_.shaderId, false, false}, &g));
      objectId_ = std::move(g.objectId);
      shaderId_ = std::move(g.shaderId);
      raw_.assign(n, RGB::Gray(std::numeric_limits<float>::quiet_NaN()));
      value_ = raw_;
      rendered_.assign(n, 0);
    }
    auto keep = [&](std::span<const Point2i> at, std::span<const ExactSample> got) {
      for (size_t i = 0; i < at.size(); ++i) {
        const size_t k = size_t(at[i].y) * size_t(caps_.width) + size_t(at[i].x);
        raw_[k] = got[i].variance;
        value_[k] = got[i].L;
        rendered_[k] = 1;
      }
    };
    keep(pixels, out);
    keep(extraPixels_, extraSamples_);
    const std::vector<RGB> pooled =
        SurfaceWindowRelativeMean(raw_, value_, caps_.width, caps_.height, objectId_, shaderId_, radius_, pixels);
    for (size_t i = 0; i < pixels.size(); ++i) out[i].variance = pooled[i];
    const std::vector<RGB> pooledExtra = SurfaceWindowRelativeMean(raw_, value_, caps_.width, caps_.height, objectId_,
                                                                   shaderId_, radius_, extraPixels_);
    for (size_t i = 0; i < extraSamples_.size(); ++i) extraSamples_[i].variance = pooledExtra[i];
    return Status::Ok();
  }
  /// The exact provider's extra pixels of the last Evaluate(), their variance pooled as the others'.
  void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) override {
    *pixels = std::exchange(extraPixels_, {});
    *samples = std::exchange(extraSamples_, {});
  }

  /// The child's variance of each of `pixels` from that pixel alone where it
  /// rendered it (QualityGoal::ownVariance).
  void OwnVariance(std::span<const Point2i> pixels, std::span<RGB> variance) const {
    for (size_t i = 0; i < pixels.size(); ++i) {
      const size_t k = size_t(pixels[i].y) * size_t(caps_.width) + size_t(pixels[i].x);
      if (k < rendered_.size() && rendered_[k]) variance[i] = raw_[k];
    }
  }

 private:
  SampleProvider& p_;
  ProviderCapabilities caps_;
  int radius_;
  std::vector<RGB> raw_;           ///< the child's per-pixel variance; NaN: not rendered
  std::vector<RGB> value_;         ///< the rendered pixels' values; NaN: not rendered
  std::vector<uint8_t> rendered_;  ///< 1 where the child rendered the pixel (its value may be NaN)
  std::vector<uint32_t> objectId_, shaderId_;
  std::vector<Point2i> extraPixels_;
  std::vector<ExactSample> extraSamples_;
};

/// Renders one frame (`frame` < 0: the file's current frame) to `output`.
int RunFrame(const BlenderFlags& f, int frame, const std::string& output, const std::string& stats,
             const std::string& sampleMap) {
  const std::string cmd = "blender";
  auto Fail = [&](const std::string& message, int code = kExitFailure) {
    std::cerr << "dcm " << cmd << ": error: " << message << "\n";
    return code;
  };
  ReconstructionOptions options;
  if (Status st = ToOptions(f.pipe.engine, &options); !st.ok()) return Fail(st.message(), kExitUsage);
  if (Status st = toolkit::CheckExrFormat(f.pipe.exr); !st.ok()) return Fail(st.message(), kExitUsage);
  if (f.variance == "off" && f.pipe.engine.TargetsRender())
    return Fail("--target-psnr render needs the exact pixels' variance, which --variance off leaves out", kExitUsage);
  if (Status st = toolkit::CheckOutputs({{"scene", f.scene}}, {{"-o", output},
                                                               {"--stats", stats},
                                                               {"--sample-map", sampleMap},
                                                               toolkit::ProgressiveArg(f.pipe.engine.progressive)});
      !st.ok())
    return Fail(st.message(), kExitUsage);
  if (Status st = CheckBlendFile(f.scene); !st.ok()) return Fail(st.message());
  // Before Blender renders anything: the outputs' folders must take a file.
  for (const std::string& out : {output, stats, sampleMap}) {
    if (out.empty()) continue;
    const fs::path folder = fs::absolute(fs::path(out)).parent_path();
    std::error_code ec;
    if (!fs::is_directory(folder, ec) || ::access(folder.c_str(), W_OK | X_OK) != 0)
      return Fail("cannot write '" + out + "': its folder '" + folder.string() +
                  "' does not exist or is not writable (checking the outputs before rendering)");
  }
  std::string blender, child;
  if (Status st = FindBlender(f.blender, &blender); !st.ok()) return Fail(st.message());
  if (Status st = FindBlenderScript("child_main.py", "DCM_BLENDER_CHILD", &child); !st.ok()) return Fail(st.message());

  // Every output of the run appears at its Commit(), or none; a signal ends Blender too.
  toolkit::OutputTransaction outputs;
  toolkit::SetSignalHook(pipe::KillAllChildren);
  // The child's masks and renders and Blender's session folder: outlives the
  // provider, so that it is removed once Blender has ended.
  std::unique_ptr<pipe::ScratchFolder> scratch;
  if (Status st = pipe::ScratchFolder::Make("dcm-blender", &scratch); !st.ok()) return Fail(st.message());
  const auto t0 = Clock::now();
  // Blender's own session folder goes inside the scratch folder too (TMPDIR).
  std::string command = "TMPDIR=" + ShellQuote(scratch->path()) + " " + ShellQuote(blender) + " -b " +
                        ShellQuote(f.scene) + " --python " + ShellQuote(child) + " -- --protocol-fd 3 --workdir " +
                        ShellQuote(scratch->path());
  if (f.samples > 0) command += " --samples " + std::to_string(f.samples);
  if (f.previewSamples > 0) command += " --preview-samples " + std::to_string(f.previewSamples);
  if (frame >= 0) command += " --frame " + std::to_string(frame);
  if (!f.viewLayer.empty()) command += " --view-layer " + ShellQuote(f.viewLayer);
  if (f.renderThreads > 0) command += " --threads " + std::to_string(f.renderThreads);
  if (f.variance != "off" && !options.fullEvaluation) command += " --variance-halves";
  // Blender prints to stdout before any script runs: the protocol goes to fd 3,
  // Blender's own output to stderr with -v, else nowhere (the child's notes and
  // errors still reach stderr).
  if (f.pipe.engine.verbose) command += " --verbose";
  command += f.pipe.engine.verbose ? " 3>&1 1>&2" : " 3>&1 1>/dev/null";
  pipe::PipeOptions po;
  po.command = command;
  po.timeoutSeconds = f.pipe.timeout;
  po.startupTimeoutSeconds = f.pipe.startupTimeout;
  std::unique_ptr<pipe::PipeProvider> provider;
  if (Status st = pipe::PipeProvider::Start(po, &provider); !st.ok())
    return Fail("'" + f.scene + "': starting Blender: " + st.message());
  // The child renders its guides and preview before it answers the handshake.
  const double handshakeS = toolkit::SecondsSince(t0);
  const auto& keys = provider->handshakeKeys();
  const double guidesRenderS = keys.count("guides_seconds") ? std::atof(keys.at("guides_seconds").c_str()) : 0.0;
  const std::string layer = keys.count("view_layer") ? PercentDecoded(keys.at("view_layer")) : "ViewLayer";
  // The exact pixels' variance goes to the engine where their noise matters.
  const double noisePsnr =
      keys.count("noise_psnr") ? std::atof(keys.at("noise_psnr").c_str()) : std::numeric_limits<double>::quiet_NaN();
  // --target-psnr render is the full render's own error, which only the variance tells.
  const bool useVariance =
      provider->Capabilities().variance &&
      (f.variance == "on" || (f.variance == "auto" && (f.pipe.engine.TargetsRender() || noisePsnr < kNoisyPsnr)));
  // The variance is pooled over the elementary block of the noisy regime.
  const int poolRadius = VariancePoolRadius(options, provider->Capabilities());
  ExactNoiseMeter meter(*provider);
  PooledVarianceProvider pooled(meter, poolRadius, useVariance);
  const ProviderCapabilities caps = pooled.Capabilities();
  RoundSchedule schedule = RoundSchedule::kLevels;
  if (Status st = ScheduleFor(f.pipe.rounds, provider->roundCost(), provider->hasPreview(), &schedule); !st.ok())
    return Fail("'" + f.scene + "': " + st.message());
  const bool goalInDb = (f.pipe.engine.targetPsnr || f.pipe.engine.budget) && !f.pipe.engine.TargetsRender();
  if (f.estimateFrom == "preview" && (schedule != RoundSchedule::kPreview || !goalInDb))
    return Fail("--estimate-from preview: judges --target-psnr in dB or --budget with the preview schedule (here " +
                    std::string(schedule != RoundSchedule::kPreview ? "schedule " + std::string(ToString(schedule))
                                : f.pipe.engine.TargetsRender()     ? "--target-psnr render"
                                                                    : "no --target-psnr or --budget") +
                    ")",
                kExitUsage);
  if (options.fullEvaluation) {
    // The baseline: every pixel in one render call.
    schedule = RoundSchedule::kLevels;
    options.batchSize = caps.width * caps.height;
  }
  if (f.pipe.engine.verbose) {
    char noise[96] = "";
    if (!std::isnan(noisePsnr))
      std::snprintf(noise, sizeof noise, "; their noise costs about %.1f dB PSNR (from the preview's halves)", noisePsnr);
    std::cerr << "blender: " << caps.width << "x" << caps.height << ", view layer '" << layer << "', round latency "
              << provider->roundCost().latencyS << " s, " << provider->roundCost().perSampleS
              << " s per pixel: schedule " << ToString(schedule) << "\n"
              << "exact pixels: "
              << (provider->Capabilities().variance
                      ? std::string("two halves of the samples, seeds ") +
                            (keys.count("seeds") ? keys.at("seeds") : std::string("?")) + noise +
                            (useVariance ? ": the engine weighs their variance" : ": taken as noise-free")
                      : std::string("one render each, taken as noise-free"))
              << "\n"
              << "engine settings: " << SettingsSummary(options, caps) << "\n";
  }
  if (Status st = CheckDownsample(caps.width, caps.height, options.downsample, "the Blender image"); !st.ok())
    return Fail(st.message(), kExitUsage);

  toolkit::Progress progress(!f.pipe.engine.quiet);
  options.progress = [&](float v, std::string_view stage) { progress.Update(v, stage); };
  TimedProvider timed(pooled);
  Reconstruction rec;
  PreviewScheduleStats sched;
  // --target-psnr / --budget: the quality search, each run planned on the preview.
  QualityGoal goal;
  const bool haveGoal = QualityGoalOf(f.pipe.engine, &goal);
  if (useVariance)
    goal.ownVariance = [&pooled](std::span<const Point2i> pixels, std::span<RGB> variance) {
      pooled.OwnVariance(pixels, variance);
    };
  // Without a goal or a threshold, dcm's own method aims at kDefaultTargetPsnr
  // where the preview can judge it; the published methods keep their threshold.
  const bool defaultGoal = !haveGoal && !f.pipe.engine.threshold && !options.fullEvaluation &&
                           f.pipe.engine.method == "dcm" && f.estimateFrom != "validation";
  std::optional<QualityReport> quality;
  QualityRoundStats qrounds;
  PreviewTargetStats ptarget;
  bool targetFromPreview = false;
  double previewS = 0, goalS = 0;
  double assumedShare = std::numeric_limits<double>::quiet_NaN();  ///< the ratio of samples
  bool measureNoise = true;  ///< the first round in halves (ExactNoiseMeter)
  bool laterFromPreview = false;  ///< later rounds' variance the preview's times the share
  double ratioRenderPsnr = std::numeric_limits<double>::quiet_NaN();  ///< the render's own, from the ratio
  Status st;
  if (schedule == RoundSchedule::kPreview) {
    const auto tp = Clock::now();
    std::unique_ptr<SampleProvider> preview;
    timed.step = "reading the preview";
    // With the exact pixels' variance the engine plans in its noise regime: the
    // preview's own variance (its halves, pooled as the exact pixels') keeps
    // the preview's noise from passing for edges. The preview correction
    // needs that variance in any case.
    const bool previewVariance = useVariance || (f.pipe.rounds.previewCorrection > 0 && provider->Capabilities().variance);
    PreviewScheduleOptions so;
    st = provider->FetchPreview({options.textureSplit && caps.splitRadiance, previewVariance}, &preview, poolRadius,
                                &so.previewOwnVariance, &so.previewTextureCovariance);
    previewS = toolkit::SecondsSince(tp);
    // An exact pixel's noise, against the converged image: the preview's at its samples.
    const double samples = keys.count("samples") ? std::atof(keys.at("samples").c_str()) : 0.0;
    const double previewSamples = keys.count("preview_samples") ? std::atof(keys.at("preview_samples").c_str()) : 0.0;
    if (samples > 0 && previewSamples > 0) so.exactVarianceShare = std::min(1.0, previewSamples / samples);
    assumedShare = so.exactVarianceShare;
    so.measuredExactVarianceShare = [&meter] { return meter.share(); };
    ApplyRoundFlags(f.pipe.rounds, &so);
    // Fewer samples for the exact pixels where a goal does not need them all
    // (never noisier than the preview: the library's bound on the share), nor,
    // with their variance not weighed, past the noise the regime was chosen for.
    if (!f.fixedSamples && !options.fullEvaluation && provider->hasExactSamples() && samples > 0 &&
        previewSamples > 0) {
      int most = 0;
      auto fits = [&](int j) {
        return (int64_t(samples) >> j) >= 2 &&
               (useVariance || (std::isfinite(noisePsnr) && noisePsnr - 10 * std::log10(double(1 << j)) >= kNoisyPsnr));
      };
      while (most < 16 && fits(most + 1)) ++most;
      so.maxExactSampleHalvings = most;
      so.halveExactSamples = [&provider, samples](int j) {
        return provider->SetExactSamples(int64_t(samples) >> j);
      };
    }
    // A target in dB or a budget is judged by the preview's estimate where the preview can tell.
    const double target = f.pipe.engine.targetPsnr.value_or(defaultGoal ? kDefaultTargetPsnr : 0);
    if (st.ok() && (target > 0 || goalInDb) && f.estimateFrom != "validation") {
      std::string why;
      if (so.correctionRadius < 1) why = "--preview-correction 0: the correction makes the estimate";
      else if (options.downsample != 1) why = "--downsample: the preview estimates at final resolution only";
      targetFromPreview = why.empty() && CanTargetFromPreview(*preview, so, &why);
      if (targetFromPreview) ratioRenderPsnr = RenderPsnrFromPreview(*preview, so);
      // The render's own noise bounds raw exact samples; the engine's denoising
      // of noisy ones can pass it, which only validation pixels tell.
      const double renderPsnr = targetFromPreview && useVariance ? ratioRenderPsnr : HUGE_VAL;
      if (target > 0 && target > renderPsnr - kRenderNoiseMarginDb) {
        targetFromPreview = false;
        char line[160];
        std::snprintf(line, sizeof line, "the render's own noise (about %.2f dB against the converged image), which "
                      "the denoised exact samples may pass", renderPsnr);
        why = line;
      }
      if (!targetFromPreview && f.estimateFrom == "preview")
        return Fail("--estimate-from preview: " + why, kExitUsage);
      if (f.pipe.engine.verbose && defaultGoal)
        std::cerr << "blender: "
                  << (targetFromPreview ? "the default goal, --target-psnr " + DefaultTarget() +
                                              " judged by the preview's estimate"
                                        : "the default threshold: the preview cannot judge the default goal "
                                          "(--target-psnr " + DefaultTarget() + "): " + why)
                  << "\n";
      else if (f.pipe.engine.verbose)
        std::cerr << "blender: " << (target > 0 ? "--target-psnr" : "--budget") << " judged by "
                  << (targetFromPreview ? std::string("the preview's estimate") : "validation pixels: " + why) << "\n";
    }
    // The preview renders on seeds of its own (the child's `seeds`): its
    // samples are more samples of the exact pixels, where the result is judged
    // against the converged image; not where validation pixels judge it against
    // the full render, nor in the baseline.
    const bool againstRender = haveGoal && !targetFromPreview && !useVariance;
    so.poolPreview = f.poolPreview == "on" && !options.fullEvaluation && !againstRender;
    // The exact pixels' noise is measured (the first round in two halves: one
    // render call more, unless the engine weighs the variance) but for a
    // target judged by the preview that the render's own noise, from the
    // ratio of samples, lies kMeasureNoiseMarginDb or more beyond.
    measureNoise =
        !(st.ok() && targetFromPreview && !useVariance && target > 0 && ratioRenderPsnr >= target + kMeasureNoiseMarginDb);
    if (measureNoise) meter.SetPreviewVariance(&so.previewOwnVariance);
    // Validation pixels judge a goal by each one's own variance, which the
    // preview's times a share measured on other pixels (edges) would bias.
    laterFromPreview = f.varianceFrom == "preview" && !(haveGoal && !targetFromPreview);
    meter.SetVarianceFromPreview(laterFromPreview);
    if (targetFromPreview) {
      QualityReport report;
      const auto tq = Clock::now();
      QualityGoal previewGoal = goal;
      previewGoal.targetPsnr = std::max(0.0, target);
      previewGoal.searchBeyondRender = !defaultGoal;
      st = ReconstructToTargetFromPreview(timed, *preview, options, previewGoal, so, &rec, &report, &ptarget);
      goalS = toolkit::SecondsSince(tq);
      if (st.ok()) quality = std::move(report);
      sched = ptarget.last;
      // Halved samples: the exact pixels' variance is a larger share of the preview's.
      assumedShare = std::min(1.0, std::ldexp(assumedShare, ptarget.exactSampleHalvings));
      if (st.ok() && f.pipe.engine.verbose) {
        for (const PreviewTargetStats::Prediction& p : ptarget.predictions) {
          char line[200];
          const int n = std::snprintf(line, sizeof line, "blender: predicted on the preview at threshold %.3g: %lld "
                                      "pixels in the first round, ", p.threshold, static_cast<long long>(p.pixels));
          if (std::isnan(p.estimate.psnr))
            std::snprintf(line + n, sizeof line - size_t(n), "no fewer than an octave finer");
          else
            std::snprintf(line + n, sizeof line - size_t(n), "estimated PSNR %.2f dB (low %.2f)", p.estimate.psnr,
                          p.estimate.low);
          std::cerr << line << "\n";
        }
      }
      if (st.ok() && f.pipe.engine.verbose && ptarget.exactSampleHalvings > 0)
        std::cerr << "blender: exact pixels at " << (int64_t(samples) >> ptarget.exactSampleHalvings) << " of "
                  << int64_t(samples) << " samples: a full render at as few would lose at most a fifth of the "
                     "target's squared error (the render's own noise about "
                  << std::fixed << std::setprecision(2) << ptarget.renderPsnrAtStart << std::defaultfloat
                  << " dB against the converged image)\n";
      if (st.ok() && ptarget.beyondRender && defaultGoal && f.pipe.engine.verbose)
        std::cerr << "blender: the default threshold: the render itself is about " << std::fixed
                  << std::setprecision(2) << ptarget.renderPsnrAtStart << std::defaultfloat
                  << " dB from the converged image, too close to the default goal (--target-psnr " << DefaultTarget()
                  << ") to search for it\n";
      else if (st.ok() && ptarget.beyondRender && !defaultGoal && !quality->targetReached)
        std::cerr << "dcm " << cmd << ": warning: --target-psnr " << target << ": at or beyond the render's own noise: "
                  << "the render itself is about " << std::fixed << std::setprecision(2) << ptarget.renderPsnr
                  << std::defaultfloat << " dB from the converged image (the preview's estimate, which can err low by "
                  << "decibels), and no result from these samples is closer than the render: more --samples raise "
                  << "both\n";
    } else if (st.ok() && haveGoal) {
      LimitRoundsForValidation(&so);
      QualityReport report;
      const auto tq = Clock::now();
      st = ReconstructToQualityWithPreview(timed, *preview, options, goal, so, &rec, &report, &qrounds);
      goalS = toolkit::SecondsSince(tq);
      if (st.ok()) quality = std::move(report);
      sched.previewStandIns = qrounds.previewStandIns;
    } else if (st.ok()) {
      st = ReconstructWithPreview(timed, *preview, options, so, &rec, &sched);
    }
  } else {
    st = ReconstructFor(timed, options, f.pipe.engine, &rec, &quality);
  }
  progress.Done();
  if (!st.ok()) return Fail("'" + f.scene + "': " + timed.step + ": " + st.message());
  if (f.pipe.engine.verbose && meter.pixels() > 0) {
    char line[200];
    std::snprintf(line, sizeof line, "blender: the exact pixels' variance is %.3g of the preview's, measured on %lld "
                  "pixels of the first round (the ratio of samples says %.3g)\n", meter.share(),
                  static_cast<long long>(meter.pixels()), assumedShare);
    std::cerr << line;
  } else if (f.pipe.engine.verbose && !measureNoise && std::isfinite(ratioRenderPsnr)) {
    char line[240];
    std::snprintf(line, sizeof line, "blender: the exact pixels' noise is not measured: the render's own, about %.2f dB "
                  "from the ratio of samples (%.3g of the preview's variance), lies %g dB or more beyond the target\n",
                  ratioRenderPsnr, assumedShare, kMeasureNoiseMarginDb);
    std::cerr << line;
  }
  // Blender must end cleanly before anything is written.
  if (Status fin = provider->Finish(); !fin.ok()) return Fail("'" + f.scene + "': " + fin.message());
  const double wallS = toolkit::SecondsSince(t0);
  const ReconstructionStats& stats_ = rec.stats;
  double roundsS = 0;
  for (const auto& r : timed.rounds) roundsS += r.seconds;
  // With a goal: the search's time but its rounds (engine runs, validation, the cache).
  const double engineS = schedule != RoundSchedule::kPreview ? stats_.timeEngineS
                         : targetFromPreview                  ? ptarget.timeEngineS
                         : quality                            ? goalS - qrounds.timeExactS
                                                              : sched.timeEngineS;
  const std::string method = options.fullEvaluation ? "full" : f.pipe.engine.method;
  // The reports name the goal the run had, the default's too.
  EngineFlags engine = f.pipe.engine;
  if (defaultGoal && targetFromPreview) engine.targetPsnr = kDefaultTargetPsnr;

  // Blender's own layout: <view layer>.Combined.R/G/B/A.
  toolkit::OutputImage image;
  image.display = image.data = Bounds2i{{0, 0}, {rec.width, rec.height}};
  const size_t n = rec.image.size();
  for (int c = 0; c < 4; ++c) {
    toolkit::OutputChannel ch;
    ch.name = layer + ".Combined." + "RGBA"[c];
    ch.values.resize(n);
    for (size_t i = 0; i < n; ++i) ch.values[i] = c == 3 ? 1.f : (&rec.image[i].r)[c];
    image.channels.push_back(std::move(ch));
  }
  toolkit::Metadata meta;
  meta.strings.push_back({"Software", std::string("dcm ") + DCM_VERSION});
  meta.strings.push_back({"File", f.scene});
  meta.strings.push_back({"dcm:version", DCM_VERSION});
  meta.strings.push_back({"dcm:command_line", toolkit::CommandLine()});
  meta.strings.push_back({"dcm:provider", "blender"});
  meta.strings.push_back({"dcm:method", method});
  meta.strings.push_back({"dcm:schedule", std::string(ToString(schedule))});
  meta.strings.push_back({"dcm:options", toolkit::OptionsToJson(options).dump()});
  meta.floats.push_back({"dcm:exact_fraction", float(stats_.exactFraction())});
  if (quality) toolkit::AddQualityMetadata(*quality, &meta);
  // Without a goal, the preview correction's estimate of the whole image (against the converged image).
  const PsnrEstimate& fromPreview = sched.correction.estimate;
  const bool previewEstimate = !quality && std::isfinite(fromPreview.low);
  // Beside it the full render's own, where the exact pixels carry noise (else NaN).
  const double renderFromPreview = previewEstimate ? sched.correction.renderPsnr : NAN;
  if (previewEstimate) toolkit::AddEstimateMetadata(fromPreview, &meta);
  if (std::isfinite(renderFromPreview)) meta.floats.push_back({"dcm:estimated_render_psnr", float(renderFromPreview)});
  if (frame >= 0) meta.strings.push_back({"Frame", std::to_string(frame)});
  toolkit::AddMetadata(meta, &image.attributes);
  if (Status w = toolkit::WriteOutputExr(output, image, f.pipe.exr); !w.ok()) return Fail(w.message());
  if (!sampleMap.empty()) {
    if (Status w = toolkit::WriteSampleMap(sampleMap, rec); !w.ok()) return Fail(w.message());
  }
  if (!stats.empty()) {
    nlohmann::json j = toolkit::RunToJson(rec, method, options, wallS);
    j["provider"] = "blender";
    j["scene"] = f.scene;
    j["schedule"] = ToString(schedule);
    nlohmann::json b;
    b["startup_s"] = handshakeS - guidesRenderS;
    b["guides_s"] = guidesRenderS + timed.guidesS;
    b["preview_s"] = previewS;
    b["engine_s"] = engineS;
    b["rounds_s"] = roundsS;
    b["wall_s"] = wallS;
    nlohmann::json rounds = nlohmann::json::array();
    for (const auto& r : timed.rounds) rounds.push_back({{"pixels", r.pixels}, {"seconds", r.seconds}});
    b["rounds"] = rounds;
    b["preview_stand_ins"] = sched.previewStandIns;
    b["stopped_at_target"] = sched.stoppedAtTarget;  // the stand-ins' round not rendered: the goal was met without it
    b["extra_pixels"] = timed.extraPixels;
    if (schedule == RoundSchedule::kPreview && (!quality || targetFromPreview)) {  // the search's runs each make their own
      b["preview_corrected"] = sched.correction.pixels;
      b["preview_filtered"] = sched.correction.filtered;
      b["error_round_pixels"] = sched.errorRoundPixels;
      b["pooled_pixels"] = sched.pooledPixels;
      b["preview_correction_weight"] = sched.correction.meanWeight;
      if (std::isfinite(sched.correction.previewPsnr)) b["preview_psnr"] = sched.correction.previewPsnr;
    }
    b["round_latency_s"] = provider->roundCost().latencyS;
    b["sample_cost_s"] = provider->roundCost().perSampleS;
    // The seeds of the exact pixels' renders: two when they carry their variance.
    nlohmann::json seeds = nlohmann::json::array();
    if (keys.count("seeds")) {
      const std::string list = keys.at("seeds");
      for (size_t start = 0; start < list.size();) {
        const size_t end = std::min(list.find(',', start), list.size());
        seeds.push_back(std::atoll(list.substr(start, end - start).c_str()));
        start = end + 1;
      }
    }
    b["seeds"] = seeds;
    if (keys.count("samples")) {
      // The run's samples, and those of its exact pixels (fewer where a goal did not need them all).
      const int64_t all = std::atoll(keys.at("samples").c_str());
      b["samples"] = all;
      b["exact_samples"] = all >> ptarget.exactSampleHalvings;
    }
    b["variance"] = useVariance ? "halves" : provider->Capabilities().variance ? "halves, not used" : "none";
    // After the round that measured the share (ExactNoiseMeter::SetVarianceFromPreview).
    if (useVariance && meter.pixels() > 0) b["later_rounds_variance"] = laterFromPreview ? "preview" : "halves";
    if (!std::isnan(noisePsnr)) b["noise_psnr"] = noisePsnr;
    if (std::isfinite(assumedShare))
      b["exact_noise_share"] = {{"assumed", assumedShare},
                                {"measured", meter.pixels() > 0 ? nlohmann::json(meter.share()) : nlohmann::json()},
                                {"pixels", meter.pixels()}};
    if (std::isfinite(ratioRenderPsnr)) b["render_psnr_from_ratio"] = ratioRenderPsnr;
    j["blender"] = b;
    if (previewEstimate) {
      toolkit::AddEstimateJson(fromPreview, 0.90, &j);  // EstimatePsnr's interval
      j["estimated_psnr_against"] = "converged";
      j["estimated_psnr_from"] = "preview";
      if (const std::optional<bool> closer = toolkit::CloserThanRender(fromPreview, renderFromPreview)) {
        j["estimated_render_psnr"] = renderFromPreview;
        j["closer_than_render"] = *closer;
      }
    }
    if (quality) {
      toolkit::AddQualityJson(*quality, engine.targetPsnr.value_or(0), engine.budget.value_or(0), &j);
      j["quality"]["target_default"] = defaultGoal && targetFromPreview;
      if (targetFromPreview) {
        toolkit::AddLadderJson(ptarget, &j["quality"]);
      } else if (schedule == RoundSchedule::kPreview) {
        j["quality"]["searches"] = qrounds.passes;
      }
    }
    if (Status w = toolkit::WriteJson(stats, j); !w.ok()) return Fail(w.message());
  }
  if (Status w = outputs.Commit(); !w.ok()) return Fail(w.message());

  const toolkit::Summary say(!f.pipe.engine.quiet);
  say("%s: %dx%d, %s, schedule %s, %zu render calls for exact pixels\n", output.c_str(), rec.width,
      rec.height, method.c_str(), std::string(ToString(schedule)).c_str(), timed.rounds.size());
  say("  exact pixels   %.2f %% (%lld of %lld)%s%s\n", 100.0 * stats_.exactFraction(),
      static_cast<long long>(stats_.exactPixels), static_cast<long long>(stats_.totalPixels),
      sched.previewStandIns ? (", " + std::to_string(sched.previewStandIns) + " preview stand-ins" +
                               (sched.stoppedAtTarget ? " (their round not rendered: the target was met "
                                                        "without it)"
                                                      : ""))
                                  .c_str()
                            : "",
      timed.extraPixels ? (", " + std::to_string(timed.extraPixels) +
                           " rendered without being asked for (the pixel filter's reach inside the mask)")
                              .c_str()
                        : "");
  say("  time           Blender start %.2f s, guides %.2f s, preview %.2f s, rounds %.2f s, DCM %.2f s, "
      "total %.2f s\n",
      handshakeS - guidesRenderS, guidesRenderS + timed.guidesS, previewS, roundsS, engineS, wallS);
  if (sched.correction.pixels > 0)
    say("  correction     %lld interpolated pixels moved toward the preview (mean weight %.3f)%s\n",
        static_cast<long long>(sched.correction.pixels), sched.correction.meanWeight,
        sched.correction.filtered > 0
            ? (", " + std::to_string(sched.correction.filtered) + " halfway to its filtered value").c_str()
            : "");
  if (sched.errorRoundPixels > 0)
    say("  error round    %lld interpolated pixels rendered where the preview said the interpolation "
        "missed (--error-round)\n",
        static_cast<long long>(sched.errorRoundPixels));
  if (sched.pooledPixels > 0)
    say("  pooled         %lld exact pixels took their preview's samples in (--pool-preview)\n",
        static_cast<long long>(sched.pooledPixels));
  if (!quality && !previewEstimate && std::isfinite(sched.correction.previewPsnr) && f.pipe.engine.verbose)
    std::fprintf(stderr, "dcm %s: no estimate of the PSNR: the preview's own is %.2f dB, too noisy to tell\n",
                 cmd.c_str(), sched.correction.previewPsnr);
  if (previewEstimate) {
    char render[64] = "";
    if (std::isfinite(renderFromPreview))
      std::snprintf(render, sizeof render, "; the full render's own %.2f dB: ", renderFromPreview);
    say("  estimate       PSNR %.2f dB against the converged image, from the preview (90 %% interval %.2f to "
        "%.2f; the preview's own %.2f dB%s%s)\n",
        fromPreview.psnr, fromPreview.low, fromPreview.high, sched.correction.previewPsnr, render,
        *render ? WhichIsCloser(fromPreview, renderFromPreview).c_str() : "");
  }
  if (quality) {
    say("  quality        %s%s\n", QualityLine(*quality, engine).c_str(), defaultGoal ? " (the default goal)" : "");
    if (f.pipe.engine.verbose) std::cerr << QualityLine(*quality, engine) << "\n";
    // Where the render's own noise stops the default goal, -v has said so: no warning for what was not asked.
    if (const std::string w = QualityWarning(*quality, engine); !w.empty() && !(defaultGoal && ptarget.beyondRender))
      std::cerr << "dcm " << cmd << ": warning: " << w << (defaultGoal ? " (the default goal)" : "") << "\n";
  }
  for (const auto& w : toolkit::SampleWarnings(stats_)) std::cerr << "dcm " << cmd << ": warning: " << w << "\n";
  return kExitOk;
}

/// --frames A-B: the frame numbers; '#' in a path becomes the frame number.
int Run(const BlenderFlags& f) {
  if (f.frames.empty()) return RunFrame(f, -1, f.output, f.stats, f.sampleMap);
  int a = 0, b = 0;
  char dash = 0, extra = 0;
  if (std::sscanf(f.frames.c_str(), "%d%c%d%c", &a, &dash, &b, &extra) != 3 || dash != '-' || b < a) {
    if (std::sscanf(f.frames.c_str(), "%d%c", &a, &extra) != 1) {
      std::cerr << "dcm blender: error: --frames: expected A-B or A, got '" << f.frames << "'\n";
      return kExitUsage;
    }
    b = a;
  }
  auto named = [](const std::string& p, int frame) {
    if (p.empty()) return p;
    const size_t h = p.find('#');
    char num[16];
    std::snprintf(num, sizeof num, "%04d", frame);
    return h == std::string::npos ? p : p.substr(0, h) + num + p.substr(h + 1);
  };
  if (a != b && f.output.find('#') == std::string::npos) {
    std::cerr << "dcm blender: error: --frames " << f.frames << " writes one image per frame: put '#' in -o "
              << "(it becomes the frame number, e.g. out_#.exr)\n";
    return kExitUsage;
  }
  for (int frame = a; frame <= b; ++frame) {
    if (int code = RunFrame(f, frame, named(f.output, frame), named(f.stats, frame), named(f.sampleMap, frame)))
      return code;
  }
  return kExitOk;
}

Registration reg("blender", "Render a .blend with Cycles at the pixels DCM asks for, reconstruct the rest",
                 [](CLI::App* app) -> std::function<int()> {
                   auto f = std::make_shared<BlenderFlags>();
                   app->option_defaults()->group(kGroupIo);
                   app->add_option("scene", f->scene, "the scene (.blend); never modified")->required();
                   app->add_option("-o,--output", f->output, "output image (multilayer EXR, Blender's names)")
                       ->required();
                   app->add_option("--stats", f->stats, "write statistics (JSON): exact_fraction, times per phase");
                   app->add_option("--sample-map", f->sampleMap, "write the sample map (PNG)");
                   app->add_option("--blender", f->blender, "the Blender executable")->capture_default_str();
                   app->add_option("--frames", f->frames, "frames A-B (or A): one image each, '#' in -o the number");
                   app->add_option("--view-layer", f->viewLayer, "view layer to render (default: the first that renders)");
                   app->option_defaults()->group(kGroupQuality);
                   app->add_option("--samples", f->samples, "Cycles samples of the exact pixels (0: the file's)")
                       ->transform(Integer(0, 1 << 24));
                   app->add_flag("--fixed-samples", f->fixedSamples,
                                 "every exact pixel at --samples; without it a goal in dB (the default goal too) "
                                 "renders them at half, a quarter, ... where a full render at as few samples would "
                                 "lose at most a fifth of the target's squared error (docs/BLENDER.md)");
                   app->add_option("--preview-samples", f->previewSamples,
                                   "samples of the guides and preview render (0: a sixteenth of --samples, at least 16)")
                       ->transform(Integer(0, 1 << 24));
                   app->add_option("--pool-preview", f->poolPreview,
                                   "on: each exact pixel ends as the inverse-variance mean of its samples and its "
                                   "preview's (rendered on seeds of their own), the preview's weight its samples' "
                                   "share; off: the exact samples alone")
                       ->check(CLI::IsMember({"on", "off"}))
                       ->capture_default_str();
                   app->add_option("--variance", f->variance,
                                   "exact pixels as two renders of half the samples with two seeds, whose difference "
                                   "gives the engine their variance: auto (where the preview's halves say their "
                                   "noise costs less than 42 dB PSNR, and always with --target-psnr render), on, "
                                   "or off (one render each, no variance)")
                       ->check(CLI::IsMember({"auto", "on", "off"}))
                       ->capture_default_str();
                   app->add_option("--variance-from", f->varianceFrom,
                                   "the exact pixels' variance after the first round, which measures it against the "
                                   "preview's: preview (the preview's own times that share: one render call per "
                                   "round; halves where validation pixels judge a goal) or halves (each round in "
                                   "two renders, as the first)")
                       ->check(CLI::IsMember({"preview", "halves"}))
                       ->capture_default_str();
                   app->add_option("--estimate-from", f->estimateFrom,
                                   "what judges --target-psnr and --budget: the preview's estimate at every pixel "
                                   "(against the converged image; needs the preview's variance), validation pixels "
                                   "rendered exactly, or auto (the preview where it can tell: its own noise under "
                                   "25 dB). Without --target-psnr, --threshold or --budget the goal is "
                                   "--target-psnr 40 where the preview can judge it, else the default threshold")
                       ->check(CLI::IsMember({"auto", "preview", "validation"}))
                       ->capture_default_str();
                   app->add_option("--render-threads", f->renderThreads, "Cycles threads (0: Blender's choice)")
                       ->transform(Integer(0, kMaxThreads));
                   app->option_defaults()->group(kGroupGeneral);
                   AddProviderTimeoutFlags(app, &f->pipe);
                   AddExrFormatFlags(app, &f->pipe.exr);
                   AddEngineFlags(app, &f->pipe.engine);
                   AddRoundFlags(app, &f->pipe.rounds);
                   return [f] { return Run(*f); };
                 });

}  // namespace
}  // namespace dcm::cli

#endif  // DCM_HAVE_PIPE

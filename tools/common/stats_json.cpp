// Statistics and settings as JSON.
#include "stats_json.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <utility>

#include "image_io.h"

namespace dcm::toolkit {

namespace {
/// A float option as the shortest decimal that reads back as the same float
/// (0.06, not 0.0599999986...).
double Decimal(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));
  for (int digits = 1; digits <= 9; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, double(v));
    if (std::strtof(buf, nullptr) == v) break;
  }
  return std::strtod(buf, nullptr);
}
/// An option with a regime-aware default: null where unset (the settings
/// report the value used).
template <typename T, typename F>
nlohmann::json Regime(const std::optional<T>& v, F&& toJson) {
  return v ? nlohmann::json(toJson(*v)) : nlohmann::json(nullptr);
}
}  // namespace

nlohmann::json OptionsToJson(const ReconstructionOptions& o) {
  nlohmann::json j;
  const auto same = [](auto v) { return v; };
  const auto name = [](auto v) { return std::string(ToString(v)); };
  j["elementary_block"] = Regime(o.elementaryBlock, same);
  j["min_block"] = o.minBlock;
  j["contrast_threshold"] = Regime(o.contrastThreshold, Decimal);
  j["contrast_metric"] = Regime(o.contrastMetric, name);
  j["directions"] = Regime(o.directions, same);
  j["object_test"] = std::string(ToString(o.objectTest));
  j["thin_objects"] = Regime(o.thinObjects, name);
  j["crossing_fill_reach"] = o.crossingFillReach;
  j["surface_aware"] = o.surfaceAware;
  j["texture_split"] = o.textureSplit;
  j["smooth_refinement"] = std::string(ToString(o.smoothRefinement));
  j["adaptive_borders"] = o.adaptiveBorders;
  j["zero_order_test"] = o.zeroOrderTest;
  j["gradient_blocks_simple"] = o.gradientBlocksSimple;
  j["first_order_test"] = o.firstOrderTest;
  j["first_order_from_guides"] = o.firstOrderFromGuides;
  j["checkerboard"] = o.checkerboard;
  j["lazy_evaluation"] = o.lazyEvaluation;
  j["fallback"] = o.fallback;
  j["fallback_max_changes"] = o.fallbackMaxChanges;
  j["fallback_shading_changes"] = o.fallbackShadingChanges;
  j["simple_surface_changes"] = o.simpleSurfaceChanges;
  j["neighbour_directions"] = o.neighbourDirections;
  j["fallback_filled_borders"] = o.fallbackFilledBorders;
  j["finest_centre_probe"] = o.finestCentreProbe;
  j["noise_significance"] = o.noiseSignificance;
  j["probe_lc_share"] = o.probeLcShare;
  j["crease_angle"] = o.creaseAngle;
  j["denoise_samples"] = o.denoiseSamples;
  j["downsample"] = o.downsample;
  j["full_evaluation"] = o.fullEvaluation;
  j["threads"] = o.threads;
  j["tile_size"] = o.tileSize;
  j["batch_size"] = o.batchSize;
  return j;
}

nlohmann::json StatsToJson(const ReconstructionStats& s) {
  nlohmann::json j;
  j["exact_pixels"] = s.exactPixels;
  j["total_pixels"] = s.totalPixels;
  j["exact_fraction"] = s.exactFraction();
  j["time_s"] = s.timeEngineS;
  j["time_illum_s"] = s.timeProviderS;
  j["time_guides_s"] = s.timeGuidesS;
  nlohmann::json reasons = nlohmann::json::object();
  for (int i = 0; i < kSampleReasonCount; ++i)
    reasons[std::string(ToString(SampleReason(i)))] = s.byReason[size_t(i)];
  j["by_reason"] = reasons;
  j["blocks"] = {{"smooth", s.smoothBlocks},
                 {"simple_edge", s.simpleEdgeBlocks},
                 {"complex_edge", s.complexEdgeBlocks},
                 {"lazy_accepted", s.lazyAccepted},
                 {"lazy_rejected", s.lazyRejected},
                 {"fallback", s.fallbackBlocks}};
  j["non_finite_samples"] = s.nonFiniteSamples;
  j["clamped_samples"] = s.clampedSamples;
  j["denoised_samples"] = s.denoisedSamples;
  j["checkerboard_filled"] = s.checkerboardFilled;
  j["crossings_filled"] = s.crossingsFilled;
  j["provider_calls"] = s.providerCalls;
  j["used"] = {{"split", s.usedSplit}, {"object_id", s.usedObjectId}, {"shader_id", s.usedShaderId},
               {"supersampled_rules", s.usedSupersampledRules},
               {"normals", s.usedNormals}};
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, seconds] : s.stageTimes.Named()) stages[std::string(name)] = seconds;
  j["stage_times_s"] = stages;
  // What "used" says already (split, guides, supersampled rules) is not repeated.
  const ResolvedSettings& r = s.settings;
  j["settings"] = {{"noisy", r.noisy},
                   {"elementary_block", r.elementaryBlock},
                   {"contrast_metric", std::string(ToString(r.contrastMetric))},
                   {"contrast_threshold", Decimal(r.contrastThreshold)},
                   {"contrast_significance", Decimal(r.contrastSignificance)},
                   {"directions", r.directions},
                   {"thin_objects", std::string(ToString(r.thinObjects))},
                   {"crossing_fill_reach", r.crossingFillReach},
                   {"smooth_refinement", std::string(ToString(r.smoothRefinement))},
                   {"object_test", std::string(ToString(r.objectTest))},
                   {"crease_angle", Decimal(r.creaseAngle)},
                   {"denoise", r.denoise},
                   {"denoise_radius", r.denoiseRadius},
                   {"denoise_gate", Decimal(r.denoiseGate)},
                   {"lazy_correction_gate", Decimal(r.lazyCorrectionGate)}};
  return j;
}

std::string StageTimesLine(const ReconstructionStats& s) {
  std::string line = "time per stage:";
  char buf[64];
  for (const auto& [name, seconds] : s.stageTimes.Named()) {
    std::snprintf(buf, sizeof buf, " %s %.3f s,", std::string(name).c_str(), seconds);
    line += buf;
  }
  std::snprintf(buf, sizeof buf, " engine %.3f s", s.timeEngineS);
  return line + buf;
}

nlohmann::json RunToJson(const Reconstruction& r, const std::string& method, const ReconstructionOptions& o,
                         double wallS) {
  nlohmann::json j = StatsToJson(r.stats);
  j["method"] = method;
  j["options"] = OptionsToJson(o);
  j["resolution"] = {r.width, r.height};
  j["working_resolution"] = {r.workWidth, r.workHeight};
  j["time_wall_s"] = wallS;
  return j;
}

void AddEstimateJson(const PsnrEstimate& e, double confidence, nlohmann::json* j) {
  (*j)["estimated_psnr"] = e.psnr;
  (*j)["estimated_psnr_low"] = e.low;
  (*j)["estimated_psnr_high"] = e.high;
  (*j)["estimated_psnr_confidence"] = confidence;
  (*j)["estimated_psnr_effective_pixels"] = std::isfinite(e.effective) ? nlohmann::json(e.effective) : nlohmann::json(nullptr);
}

nlohmann::json EstimateJson(const PsnrEstimate& e) { return {{"psnr", e.psnr}, {"low", e.low}, {"high", e.high}}; }

void AddLadderJson(const PreviewTargetStats& s, nlohmann::json* quality) {
  nlohmann::json ladder = nlohmann::json::array();
  for (size_t k = 0; k < s.thresholds.size() && k < s.estimates.size(); ++k) {
    nlohmann::json run = EstimateJson(s.estimates[k]);
    run["threshold"] = s.thresholds[k];
    ladder.push_back(std::move(run));
  }
  (*quality)["ladder"] = std::move(ladder);
  nlohmann::json predictions = nlohmann::json::array();
  for (const PreviewTargetStats::Prediction& p : s.predictions) {
    nlohmann::json prediction = EstimateJson(p.estimate);
    prediction["threshold"] = p.threshold;
    prediction["pixels"] = p.pixels;
    predictions.push_back(std::move(prediction));
  }
  (*quality)["start_predictions"] = std::move(predictions);
}

void AddEstimateMetadata(const PsnrEstimate& e, Metadata* m) {
  for (const auto& [name, v] : {std::pair<const char*, double>{"dcm:estimated_psnr", e.psnr},
                                {"dcm:estimated_psnr_low", e.low},
                                {"dcm:estimated_psnr_high", e.high}})
    if (std::isfinite(v)) m->floats.push_back({name, float(v)});
}

void AddQualityJson(const QualityReport& r, double targetPsnr, double budget, nlohmann::json* j) {
  auto orNull = [](double v) { return v > 0 ? nlohmann::json(v) : nlohmann::json(nullptr); };
  AddEstimateJson(r.estimate, r.confidence, j);
  (*j)["estimated_psnr_from"] = r.estimateSource == EstimateSource::kPreview ? "preview" : "validation";
  if (r.againstConverged) {
    // Noisy samples of known variance: the estimate is against the converged image.
    (*j)["estimated_psnr_against"] = "converged";
    (*j)["estimated_render_psnr"] = r.renderEstimate.psnr;
    (*j)["estimated_render_psnr_low"] = r.renderEstimate.low;
    (*j)["estimated_render_psnr_high"] = r.renderEstimate.high;
    if (const std::optional<bool> closer = CloserThanRender(r)) (*j)["closer_than_render"] = *closer;
  }
  nlohmann::json levels = nlohmann::json::array();
  for (const LevelEstimate& l : r.levels) {
    nlohmann::json level = EstimateJson(l.estimate);
    level["level"] = l.level;
    levels.push_back(std::move(level));
  }
  (*j)["quality"] = {{"target_psnr", orNull(targetPsnr < 0 ? r.targetPsnr : targetPsnr)},
                     {"budget", orNull(budget)},
                     {"target_reached", r.targetReached},
                     {"confirmed", r.confirmed},
                     {"budget_bound", r.budgetBound},
                     {"exact_pixels", r.exactPixels},
                     {"exact_fraction", r.exactFraction()},
                     {"validation_pixels", r.validationPixels},
                     {"validation_exact_pixels", r.validationExactPixels},
                     {"runs", r.runs},
                     {"threshold", r.threshold < 0 ? nlohmann::json(nullptr) : nlohmann::json(r.threshold)},
                     {"levels", levels}};
  if (targetPsnr < 0) (*j)["quality"]["target_render"] = true;
  if (std::isfinite(r.secondEstimate.psnr)) {
    // Both judges, where there are two; estimated_psnr is the lower.
    (*j)["quality"]["second_estimate"] = EstimateJson(r.secondEstimate);
    (*j)["quality"]["validation_estimate"] = EstimateJson(r.validationEstimate);
  }
}

std::optional<bool> CloserThanRender(const QualityReport& r) {
  if (!r.againstConverged) return {};
  return CloserThanRender(r.estimate, r.renderEstimate.psnr);
}

std::optional<bool> CloserThanRender(const PsnrEstimate& result, double renderPsnr) {
  if (!std::isfinite(renderPsnr) || std::isnan(result.low)) return {};
  return result.low >= renderPsnr;
}

void AddQualityMetadata(const QualityReport& r, Metadata* m) {
  AddEstimateMetadata(r.estimate, m);
  if (std::isfinite(r.renderEstimate.psnr)) m->floats.push_back({"dcm:estimated_render_psnr", float(r.renderEstimate.psnr)});
}

std::vector<std::string> SampleWarnings(const ReconstructionStats& s) {
  std::vector<std::string> w;
  if (s.nonFiniteSamples)
    w.push_back(std::to_string(s.nonFiniteSamples) + " exact samples are NaN/Inf (kept to their pixels)");
  if (s.clampedSamples) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", double(kMaxSampleMagnitude));
    w.push_back(std::to_string(s.clampedSamples) + " exact samples have finite values beyond +-" + limit +
                " (clamped to it)");
  }
  return w;
}

Status WriteJson(const std::string& path, const nlohmann::json& j) {
  std::string text;
  try {
    // Replace invalid UTF-8 (e.g. from a file name) instead of throwing.
    text = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  } catch (const std::exception& e) {
    return Status::Error("cannot write '" + path + "': " + e.what());
  }
  return WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Status::Error("cannot write '" + path + "': cannot create a file in its folder");
    out << text;
    out.close();
    if (!out) return Status::Error("cannot write '" + path + "': write failed");
    return Status::Ok();
  });
}

}  // namespace dcm::toolkit

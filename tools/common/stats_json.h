// Statistics and settings as JSON, for --stats files and EXR metadata.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "dcm/options.h"
#include "dcm/preview_target.h"
#include "dcm/quality_target.h"
#include "dcm/reconstructor.h"
#include "dcm/status.h"

namespace dcm::toolkit {

struct Metadata;

/// The switches of a reconstruction (every field except the progress callback),
/// with snake_case names and enums by their ToString() names.
nlohmann::json OptionsToJson(const ReconstructionOptions& o);

/// exact_pixels, total_pixels, exact_fraction, time_s (engine), time_illum_s
/// (provider), time_guides_s, by_reason {reason name: count, for every reason
/// including "interpolated"}, blocks {...}, non_finite_samples, clamped_samples, provider_calls,
/// used {split, object_id, shader_id, supersampled_rules, normals},
/// stage_times_s {stage: seconds, for every StageTimes::Named() stage} and
/// settings {the ResolvedSettings that "used" does not report}.
nlohmann::json StatsToJson(const ReconstructionStats& s);

/// "time per stage: surfaces 0.012 s, ..., engine 0.345 s" (-v).
std::string StageTimesLine(const ReconstructionStats& s);

/// What every command's --stats file says of one reconstruction: StatsToJson()
/// of its stats, plus method, options, resolution, working_resolution and
/// time_wall_s.
nlohmann::json RunToJson(const Reconstruction& r, const std::string& method, const ReconstructionOptions& o,
                         double wallS);

/// Adds an estimate of the result's PSNR to a --stats object:
/// estimated_psnr, estimated_psnr_low, estimated_psnr_high (the interval at
/// estimated_psnr_confidence, `confidence`) and
/// estimated_psnr_effective_pixels (PsnrEstimate::effective; null: no error seen).
void AddEstimateJson(const PsnrEstimate& estimate, double confidence, nlohmann::json* j);

/// {psnr, low, high} of one estimate: a run's, a level's, a judge's.
nlohmann::json EstimateJson(const PsnrEstimate& estimate);

/// Adds a ladder judged by the preview (ReconstructToTargetFromPreview) to a
/// --stats object's quality: ladder [{threshold, psnr, low, high}] per run and
/// start_predictions [{threshold, pixels, psnr, low, high}].
void AddLadderJson(const PreviewTargetStats& ladder, nlohmann::json* quality);

/// Adds dcm:estimated_psnr, dcm:estimated_psnr_low, dcm:estimated_psnr_high
/// (finite values only) to EXR metadata.
void AddEstimateMetadata(const PsnrEstimate& estimate, Metadata* metadata);

/// Adds what --target-psnr / --budget delivered to a --stats object:
/// estimated_psnr, estimated_psnr_low, estimated_psnr_high (the interval at
/// estimated_psnr_confidence), estimated_psnr_effective_pixels and quality {target_psnr, budget, target_reached,
/// confirmed, budget_bound, exact_pixels, exact_fraction, validation_pixels,
/// validation_exact_pixels, runs, threshold, levels [{level, psnr, low, high}],
/// second_estimate and validation_estimate {psnr, low, high} where
/// QualityReport::secondEstimate is (estimated_psnr is then the lower of the
/// two, estimated_psnr_from names it)};
/// a target or budget of 0 is null (not asked). A negative targetPsnr is
/// --target-psnr render: target_psnr is then the render's estimate aimed at,
/// and quality.target_render true. With samples of known variance
/// (QualityReport::againstConverged) also estimated_psnr_against "converged"
/// and estimated_render_psnr, _low, _high (the full render's own PSNR
/// against the converged image), and closer_than_render (CloserThanRender)
/// where both are known.
void AddQualityJson(const QualityReport& report, double targetPsnr, double budget, nlohmann::json* j);

/// Whether the result is shown to be at least as close to the converged
/// image as the full render: the lower end of its estimate's interval at
/// least the render's estimate (a point estimate above the render's whose
/// interval reaches below it is no claim); empty where either is not known.
std::optional<bool> CloserThanRender(const QualityReport& report);

/// The same from the result's estimate against the converged image and the
/// render's PSNR: empty where the render's is not finite or the result's
/// lower end is NaN.
std::optional<bool> CloserThanRender(const PsnrEstimate& result, double renderPsnr);

/// Adds AddEstimateMetadata() of the report's estimate and, with samples of
/// known variance, dcm:estimated_render_psnr (finite values only) to EXR
/// metadata.
void AddQualityMetadata(const QualityReport& report, Metadata* metadata);

/// The warnings a run's samples deserve, one sentence each: NaN/Inf samples
/// (kept to their pixels) and huge finite ones (clamped to kMaxSampleMagnitude).
std::vector<std::string> SampleWarnings(const ReconstructionStats& s);

/// Writes JSON (pretty, 2 spaces) atomically. Non-finite numbers become null
/// (JSON has no infinity).
Status WriteJson(const std::string& path, const nlohmann::json& j);

}  // namespace dcm::toolkit

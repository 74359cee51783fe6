#include "reconstruct_exr.h"

#include <chrono>
#include <cmath>

#include "common/image_io.h"
#include "common/stats_json.h"
#include "common/tiles.h"
#include "dcm/downsample.h"

namespace dcm::cli {

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

nlohmann::json ExrStatsJson(const std::string& cmd, const aov_common::AovFlags& aov, const EngineFlags& engine,
                            const aov::AovProvider& provider, const Reconstruction& r,
                            const ReconstructionOptions& options, double wallS) {
  nlohmann::json stats = toolkit::StatsToJson(r.stats);
  stats["command"] = cmd;
  stats["inputs"] = aov.inputs;
  if (!aov.samples.empty()) stats["samples"] = aov.samples;
  stats["mode"] = provider.dense() ? "dense" : "sparse";
  stats["method"] = engine.method;
  stats["width"] = r.width;
  stats["height"] = r.height;
  stats["work_width"] = r.workWidth;
  stats["work_height"] = r.workHeight;
  stats["time_reconstruct_s"] = wallS;
  stats["options"] = toolkit::OptionsToJson(options);
  stats["warnings"] = provider.Warnings();
  return stats;
}

std::string MissingSamplesMessage(const aov::AovProvider& provider, const std::vector<Point2i>& pending,
                                  const std::string& forWhat) {
  int64_t missing = 0;
  for (const auto& p : pending) missing += provider.HasSample(p) ? 0 : 1;
  return "the samples lack " + std::to_string(missing) + " pixels the engine needs" + forWhat +
         "; run `dcm plan` with the same inputs, flags and samples, render what it asks for, and repeat";
}

Status OutputWindows(const aov::AovProvider& provider, int n, Bounds2i* display, Bounds2i* data) {
  *display = provider.DisplayWindow();
  *data = provider.DataWindow();
  if (n <= 1) return Status::Ok();
  const bool whole = *display == *data;
  // A region must sit on the N-pixel lattice of its frame; a whole frame
  // only needs its origin there (CheckDownsample checked its size).
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

Status ReconstructWholeExr(const std::string& cmd, aov::AovProvider& provider, const aov_common::AovFlags& aov,
                           const EngineFlags& engine, const ReconstructionOptions& options,
                           const std::string& referencePath, ExrReconstruction* out, bool* usage) {
  *usage = true;
  DCM_RETURN_IF_ERROR(OutputWindows(provider, options.downsample, &out->display, &out->data));
  *usage = false;

  // An explicit reference is read (and checked) before the work starts.
  int refW = 0, refH = 0;
  if (!referencePath.empty()) DCM_RETURN_IF_ERROR(toolkit::ReadRgb(referencePath, &refW, &refH, &out->reference));

  Reconstruction& r = out->result;
  std::vector<Point2i> pending;
  const auto t0 = std::chrono::steady_clock::now();
  const Status st = aov_common::Run(provider, options, engine, &r, &pending);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (st.pending()) return Status::Error(MissingSamplesMessage(provider, pending, ""));
  DCM_RETURN_IF_ERROR(st);

  // The error against the full input (dense mode) or an explicit reference,
  // at the output resolution.
  if (!referencePath.empty()) {
    if (refW != r.width || refH != r.height)
      return Status::Error("reference '" + referencePath + "' is " + std::to_string(refW) + "x" +
                           std::to_string(refH) + ", the output is " + std::to_string(r.width) + "x" +
                           std::to_string(r.height));
    out->haveReference = true;
  } else if (provider.dense()) {
    int w = 0, h = 0;
    out->reference =
        dcm::BoxDownsample(provider.Beauty(), provider.width(), provider.height(), options.downsample, &w, &h);
    out->haveReference = (w == r.width && h == r.height);
  }
  if (out->haveReference) out->error = toolkit::Compare(r.image, out->reference, r.width, r.height);

  out->stats = ExrStatsJson(cmd, aov, engine, provider, r, options, wall);
  const auto caps = provider.Capabilities();
  out->stats["capabilities"] = {{"object_id", caps.objectId}, {"shader_id", caps.shaderId},
                                {"texture", caps.texture},    {"split_radiance", caps.splitRadiance},
                                {"variance", caps.variance},  {"hard_shadows_guided", caps.hardShadowsGuided}};
  if (out->haveReference) out->stats["reference"] = ErrorJson(out->error);
  return Status::Ok();
}

}  // namespace dcm::cli

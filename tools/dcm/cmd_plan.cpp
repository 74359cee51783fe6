// dcm plan: one round of the file-based round trip.
//
//   dcm plan GUIDES.exr [--samples S1.exr ...] --mask NEXT.exr --list NEXT.txt
//
// Runs the engine on the guides and the samples rendered so far (the engine is
// deterministic, so every round starts from the beginning) and writes the
// pixels it needs next: an EXR mask (channel "mask", 1 where requested) and a
// text list ("x y" per line in the frame's coordinates, '#' comments); both
// keep the guides' data window (a render region). The renderer renders those pixels
// into a samples EXR (the channels plan names, plus "mask"); repeat with all
// samples files until plan prints "done"; then `dcm reconstruct GUIDES.exr
// --samples ...` gives the same image as dense mode.
//
// With --tile I/N or --region, the round covers one part of the frame (the
// window ReconstructRegion reconstructs for it, halo included): each node of a
// farm plans and renders its own part, and `dcm reconstruct --tile I/N` then
// `dcm merge` assemble the frame. With --frames, '#' in the file names is the
// frame number.
//
// stdout is one word for scripts: "pending N" or "done" (per frame).
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>

#include "aov_common.h"
#include "common/image_io.h"
#include "common/stats_json.h"
#include "common/tiles.h"
#include "dcm/window_provider.h"
#include "flag_checks.h"
#include "tile_flags.h"

namespace dcm::cli {
namespace {

struct PlanFlags {
  aov_common::AovFlags aov;
  EngineFlags engine;
  TileFlags tiles;
  std::string mask, list, stats;
};

/// The mask covers the guides' data window of their display window, so that
/// a renderer reads it in its own frame's pixel coordinates.
Status WriteMask(const std::string& path, const Bounds2i& display, const Bounds2i& data,
                 const std::vector<Point2i>& pixels, const std::vector<std::string>& channels) {
  const int width = data.width();
  std::vector<float> mask(size_t(data.area()), 0.f);
  for (const auto& p : pixels) mask[size_t(p.y) * size_t(width) + size_t(p.x)] = 1.f;
  OIIO::ImageSpec spec = toolkit::WindowedSpec(display, data, 1);
  spec.channelnames = {"mask"};
  spec.attribute("compression", "zip");
  spec.attribute("dcm:channels", OIIO::Strutil::join(channels, ","));
  spec.attribute("dcm:pending", int(pixels.size()));
  return toolkit::WriteImage(path, spec, mask.data(), OIIO::TypeDesc::FLOAT);
}

/// "x y" lines in the frame's pixel coordinates (EXR coordinates: the data
/// window's origin added).
Status WriteList(const std::string& path, const Bounds2i& display, const Bounds2i& data,
                 const std::vector<Point2i>& pixels, const std::vector<std::string>& channels) {
  return toolkit::WriteAtomically(path, [&](const std::string& tmp) -> Status {
    std::ofstream out(tmp, std::ios::trunc);
    if (!out) return Status::Error("cannot write '" + path + "': cannot create a file in its folder");
    out << "# dcm plan: " << pixels.size() << " pixels of " << data.width() << "x" << data.height();
    if (!(data == display))
      out << " at " << data.min.x << "," << data.min.y << " (data window) of the " << display.width() << "x"
          << display.height() << " frame";
    out << " to render; samples EXR channels: " << OIIO::Strutil::join(channels, ",") << "\n";
    for (const auto& p : pixels) out << p.x + data.min.x << ' ' << p.y + data.min.y << '\n';
    out.close();
    if (!out) return Status::Error("cannot write '" + path + "': write failed");
    return Status::Ok();
  });
}

int RunPlan(const PlanFlags& f) {
  const std::string cmd = "plan";
  ReconstructionOptions options;
  Status st = ToOptions(f.engine, &options);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);
  if (f.mask.empty() && f.list.empty())
    return aov_common::Fail(cmd, "give --list and/or --mask for the pixels to render", kExitUsage);
  if (int rc = aov_common::CheckFiles(cmd, aov_common::InputArgs(f.aov),
                                      {{"--mask", f.mask},
                                       {"--list", f.list},
                                       {"--stats", f.stats},
                                       toolkit::ProgressiveArg(f.engine.progressive)}))
    return rc;
  aov_common::Outputs outputs(cmd);  // before the run: --progressive writes during it
  aov::AovOptions aovOptions;
  st = aov_common::ToAovOptions(f.aov, /*sparse=*/true, options.textureSplit, &aovOptions);
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);

  std::unique_ptr<aov::AovProvider> provider;
  st = aov_common::OpenProvider(cmd, f.aov, aovOptions, f.engine, options, &provider);
  if (!st.ok()) return aov_common::Fail(cmd, st.message());
  st = CheckDownsample(provider->width(), provider->height(), options.downsample, "the guides' data window");
  if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);

  Reconstruction r;
  std::vector<Point2i> pending;
  std::string tile;
  Bounds2i region;
  RegionInfo info;
  if (IsPartial(f.tiles) && (f.engine.targetPsnr || f.engine.budget))
    return aov_common::Fail(cmd, "--target-psnr and --budget estimate the whole frame; not with --tile or --region",
                            kExitUsage);
  std::optional<QualityReport> quality;
  if (IsPartial(f.tiles)) {
    st = aov_common::ResolvePart(*provider, f.tiles, options, "guides", &region, &tile);
    if (!st.ok()) return aov_common::Fail(cmd, st.message(), kExitUsage);
  }
  st = aov_common::Run(*provider, options, f.engine, &r, &pending, IsPartial(f.tiles) ? &region : nullptr, &info,
                       &quality);
  if (!st.ok() && !st.pending()) return aov_common::Fail(cmd, st.message());
  const bool done = st.ok();
  std::vector<Point2i> next;
  if (!done) {
    // The engine reports every pixel of the phase it could not finish; the
    // ones already rendered need not be rendered again.
    for (const auto& p : pending)
      if (!provider->HasSample(p)) next.push_back(p);
    std::sort(next.begin(), next.end(),
              [](const Point2i& a, const Point2i& b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
    next.erase(std::unique(next.begin(), next.end()), next.end());
    if (next.empty())
      return aov_common::Fail(cmd, "the engine is pending on pixels that all have samples: " + st.message());
  }
  const Bounds2i display = provider->DisplayWindow(), data = provider->DataWindow();
  const auto channels = provider->SampleChannels();

  int rc = kExitOk;
  if (!f.mask.empty() && (rc = outputs.Write(WriteMask(f.mask, display, data, next, channels)))) return rc;
  if (!f.list.empty() && (rc = outputs.Write(WriteList(f.list, display, data, next, channels)))) return rc;
  if (!f.stats.empty()) {
    nlohmann::json j;
    j["command"] = cmd;
    j["done"] = done;
    j["pending"] = next.size();
    j["samples_present"] = provider->SampleCount();
    j["total_pixels"] = data.area();
    j["channels"] = channels;
    j["options"] = toolkit::OptionsToJson(options);
    if (IsPartial(f.tiles)) {
      j["part"] = PartJson(tile, info);
      if (!done) j["part"].erase("window_stats");  // the engine did not finish the window
    }
    else if (done) j["result"] = toolkit::StatsToJson(r.stats);
    if (done && quality)
      toolkit::AddQualityJson(*quality, f.engine.targetPsnr.value_or(0), f.engine.budget.value_or(0), &j["result"]);
    if ((rc = outputs.Write(toolkit::WriteJson(f.stats, j)))) return rc;
  }
  if ((rc = outputs.Commit())) return rc;
  if (!f.engine.quiet) {
    if (IsPartial(f.tiles))
      std::cerr << "dcm plan: " << (tile.empty() ? "region " : "tile " + tile + ", ")
                << toolkit::RegionText(info.output) << " of the frame, window " << toolkit::RegionText(info.window)
                << "\n";
    std::string names;
    for (const auto& c : channels) names += (names.empty() ? "" : ",") + c;
    if (done)
      std::cerr << "dcm plan: done: the " << provider->SampleCount()
                << " samples rendered suffice; run `dcm reconstruct` with them\n";
    else
      std::cerr << "dcm plan: " << next.size() << " pixels to render (samples EXR channels: " << names
                << "); " << provider->SampleCount() << " rendered so far\n";
  }
  if (done)
    std::cout << "done\n";
  else
    std::cout << "pending " << next.size() << "\n";
  return kExitOk;
}

/// --frames: one round per frame, '#' in the file names replaced by the
/// frame number.
int RunPlanFrames(const PlanFlags& f) {
  return RunPerFrame<PlanFlags>(
      "plan", f, f.tiles,
      [](PlanFlags* g, const std::function<void(std::string*)>& each) {
        for (auto* list : {&g->aov.inputs, &g->aov.samples})
          for (auto& name : *list) each(&name);
        for (auto* name : {&g->mask, &g->list, &g->stats}) each(name);
      },
      RunPlan);
}

Registration reg("plan", "Plan the next round of a file-based round trip (pixels to render)",
                 [](CLI::App* app) -> std::function<int()> {
                   auto f = std::make_shared<PlanFlags>();
                   aov_common::AddAovFlags(app, &f->aov, true);
                   app->option_defaults()->group(kGroupIo);
                   app->add_option("--mask", f->mask, "output EXR mask of the pixels to render");
                   app->add_option("--list", f->list, "output text list of the pixels to render ('x y' lines)");
                   app->add_option("--stats", f->stats, "round summary as JSON");
                   app->option_defaults()->group(kGroupGeneral);
                   AddEngineFlags(app, &f->engine);
                   app->get_option("--quiet")->description(
                       "no progress, warnings or notes on stderr (stdout still says \"pending N\" or \"done\")");
                   AddTileFlags(app, &f->tiles, /*plans=*/true);
                   return [f] { return RunPlanFrames(*f); };
                 });

}  // namespace
}  // namespace dcm::cli

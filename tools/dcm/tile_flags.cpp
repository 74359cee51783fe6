#include "tile_flags.h"

#include <cstdio>

#include "common/stats_json.h"
#include "common/tiles.h"

namespace dcm::cli {

void AddTileFlags(CLI::App* app, TileFlags* f, bool plans) {
  auto* tile = app->add_option(
      "--tile", f->tile,
      plans ? "I/N: plan the pixels tile I (0-based, as Slurm's --array=0-N-1) of N still needs (its window, halo "
              "included); then dcm reconstruct --tile I/N and dcm merge"
            : "I/N: compute tile I (0-based, as Slurm's --array=0-N-1) of N and write it as a part (the frame's "
              "display window, the tile's data window); assemble with dcm merge");
  app->add_option("--region", f->region,
                  plans ? "x,y,w,h: plan the pixels this region of the output frame still needs"
                        : "x,y,w,h: compute this region of the output frame and write it as a part")
      ->excludes(tile);
  app->add_option("--frames", f->frames,
                  "N or A-B: substitute the frame number for each run of '#' in file names (zero-padded to "
                  "the run's length: room.####.exr), one frame after another");
}

Status ResolveRegion(const TileFlags& f, int width, int height, int align, Bounds2i* region, std::string* tile) {
  tile->clear();
  if (!f.tile.empty()) {
    int index = 0, count = 0;
    char extra = 0;
    if (std::sscanf(f.tile.c_str(), "%d/%d%c", &index, &count, &extra) != 2 || count < 1)
      return Status::Error("--tile: expected I/N with N >= 1 (e.g. 0/8), got '" + f.tile + "'");
    if (index < 0 || index >= count)
      return Status::Error("--tile " + f.tile + ": I must be in 0.." + std::to_string(count - 1) +
                           " (tiles are numbered from 0, as Slurm's --array=0-" + std::to_string(count - 1) + ")");
    Status st = TileRegion(width, height, index, count, align, region);
    if (!st.ok()) return Status::Error("--tile " + f.tile + ": " + st.message());
    *tile = std::to_string(index) + "/" + std::to_string(count);
    return Status::Ok();
  }
  int x = 0, y = 0, w = 0, h = 0;
  char extra = 0;
  if (std::sscanf(f.region.c_str(), "%d,%d,%d,%d%c", &x, &y, &w, &h, &extra) != 4 || x < 0 || y < 0 || w < 1 ||
      h < 1)
    return Status::Error("--region: expected x,y,w,h with x, y >= 0 and w, h >= 1, got '" + f.region + "'");
  if (int64_t(x) + w > width || int64_t(y) + h > height)
    return Status::Error("--region " + f.region + " reaches beyond the " + std::to_string(width) + "x" +
                         std::to_string(height) + " output frame");
  *region = {{x, y}, {x + w, y + h}};
  return Status::Ok();
}

Status FrameList(const TileFlags& f, std::vector<int>* frames) {
  frames->clear();
  if (f.frames.empty()) return Status::Ok();
  int a = 0, b = 0;
  char dash = 0, extra = 0;
  const int n = std::sscanf(f.frames.c_str(), "%d%c%d%c", &a, &dash, &b, &extra);
  if (n == 1) {
    b = a;
  } else if (n != 3 || dash != '-') {
    return Status::Error("--frames: expected N or A-B (e.g. 1-24), got '" + f.frames + "'");
  }
  if (a < 0 || b < a || b - a >= 1000000)
    return Status::Error("--frames " + f.frames + ": expected 0 <= A <= B (and fewer than a million frames)");
  for (int i = a; i <= b; ++i) frames->push_back(i);
  return Status::Ok();
}

int RunFrames(const std::string& cmd, const std::vector<int>& frames, const std::function<int(int)>& run) {
  for (int frame : frames) {
    if (const int rc = run(frame); rc != 0) {
      std::fprintf(stderr, "dcm %s: frame %d failed\n", cmd.c_str(), frame);
      return rc;
    }
  }
  return 0;
}

bool HasFramePattern(const std::string& name) { return name.find('#') != std::string::npos; }

std::string ExpandFrame(const std::string& pattern, int frame) {
  std::string out;
  for (size_t i = 0; i < pattern.size();) {
    if (pattern[i] != '#') {
      out.push_back(pattern[i++]);
      continue;
    }
    size_t run = 0;
    while (i < pattern.size() && pattern[i] == '#') ++i, ++run;
    std::string number = std::to_string(frame);
    if (number.size() < run) number.insert(0, run - number.size(), '0');
    out += number;
  }
  return out;
}

void AddPartMetadata(const std::string& tile, const Bounds2i& region, const nlohmann::json& settings,
                     const Reconstruction& part, const RegionInfo& info, toolkit::Metadata* meta) {
  if (!tile.empty()) meta->strings.push_back({toolkit::kAttrTile, tile});
  meta->strings.push_back({toolkit::kAttrRegion, toolkit::RegionText(region)});
  meta->strings.push_back({toolkit::kAttrFingerprint, toolkit::Fingerprint(settings)});
  meta->strings.push_back({toolkit::kAttrSettings, settings.dump()});
  nlohmann::json counts;
  counts["total_pixels"] = part.stats.totalPixels;
  counts["exact_pixels"] = part.stats.exactPixels;
  nlohmann::json reasons = nlohmann::json::object();
  for (int i = 0; i < kSampleReasonCount; ++i)
    reasons[std::string(ToString(SampleReason(i)))] = part.stats.byReason[size_t(i)];
  counts["by_reason"] = reasons;
  counts["window_pixels"] = info.windowStats.totalPixels;
  counts["window_exact_pixels"] = info.windowStats.exactPixels;
  counts["time_illum_s"] = info.windowStats.timeProviderS;
  counts["time_s"] = info.windowStats.timeEngineS;
  counts["time_guides_s"] = info.windowStats.timeGuidesS;
  meta->strings.push_back({toolkit::kAttrPartStats, counts.dump()});
}

nlohmann::json PartJson(const std::string& tile, const RegionInfo& info) {
  nlohmann::json j;
  if (!tile.empty()) j["tile"] = tile;
  j["region"] = {info.output.min.x, info.output.min.y, info.output.width(), info.output.height()};
  j["work_region"] = {info.work.min.x, info.work.min.y, info.work.width(), info.work.height()};
  j["window"] = {info.window.min.x, info.window.min.y, info.window.width(), info.window.height()};
  j["halo_blocks"] = info.haloBlocks;
  j["frame"] = {info.frameWidth, info.frameHeight};
  j["frame_working"] = {info.frameWorkWidth, info.frameWorkHeight};
  j["window_stats"] = toolkit::StatsToJson(info.windowStats);
  return j;
}

}  // namespace dcm::cli

#include "tile_flags.h"

#include <charconv>
#include <cstdint>
#include <cstdio>

#include "common/stats_json.h"
#include "common/tiles.h"
#include "flag_checks.h"

namespace dcm::cli {

namespace {

/// `s` as integers separated by `sep` (each a whole decimal int, a leading
/// '-' allowed); false on anything else, overflow included.
bool SplitInts(const std::string& s, char sep, std::vector<int>* out) {
  out->clear();
  size_t begin = 0;
  while (true) {
    const size_t end = s.find(sep, begin);
    const std::string part = s.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    int v = 0;
    const auto [ptr, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (part.empty() || ec != std::errc() || ptr != part.data() + part.size()) return false;
    out->push_back(v);
    if (end == std::string::npos) return true;
    begin = end + 1;
  }
}

/// --tile I/N: the index and count.
Status ParseTile(const std::string& text, int* index, int* count) {
  std::vector<int> v;
  if (!SplitInts(text, '/', &v) || v.size() != 2 || v[1] < 1)
    return Status::Error("expected I/N with N >= 1 (e.g. 0/8), got '" + text + "'");
  if (v[0] < 0 || v[0] >= v[1])
    return Status::Error("I must be in 0.." + std::to_string(v[1] - 1) + " (tiles are numbered from 0, as Slurm's "
                         "--array=0-" + std::to_string(v[1] - 1) + "), got '" + text + "'");
  *index = v[0];
  *count = v[1];
  return Status::Ok();
}

/// --region x,y,w,h: the region (not yet checked against the frame).
Status ParseRegion(const std::string& text, Bounds2i* region) {
  std::vector<int> v;
  if (!SplitInts(text, ',', &v) || v.size() != 4 || v[0] < 0 || v[1] < 0 || v[2] < 1 || v[3] < 1 ||
      int64_t(v[0]) + v[2] > INT32_MAX || int64_t(v[1]) + v[3] > INT32_MAX)
    return Status::Error("expected x,y,w,h with x, y >= 0 and w, h >= 1, got '" + text + "'");
  *region = {{v[0], v[1]}, {v[0] + v[2], v[1] + v[3]}};
  return Status::Ok();
}

/// --frames N or A-B: the first and last frame.
Status ParseFrames(const std::string& text, int* first, int* last) {
  std::vector<int> v;
  if (!SplitInts(text, '-', &v) || v.empty() || v.size() > 2)
    return Status::Error("expected N or A-B (e.g. 1-24), got '" + text + "'");
  *first = v.front();
  *last = v.back();
  if (*first < 0 || *last < *first || int64_t(*last) - *first >= 1000000)
    return Status::Error("expected 0 <= A <= B (and fewer than a million frames), got '" + text + "'");
  return Status::Ok();
}

}  // namespace

void AddFramesFlag(CLI::App* app, std::string* frames, const std::string& help) {
  app->add_option("--frames", *frames, help)
      ->check(Parsed("", [](const std::string& s) {
        int a = 0, b = 0;
        return ParseFrames(s, &a, &b);
      }))
      ->group(kGroupTiles);
}

void AddTileFlags(CLI::App* app, TileFlags* f, bool plans) {
  auto* tile = app->add_option(
      "--tile", f->tile,
      plans ? "I/N: plan the pixels tile I (0-based, as Slurm's --array=0-N-1) of N still needs (its window, halo "
              "included); then dcm reconstruct --tile I/N and dcm merge"
            : "I/N: compute tile I (0-based, as Slurm's --array=0-N-1) of N and write it as a part (the frame's "
              "display window, the tile's data window); assemble with dcm merge");
  tile->check(Parsed("", [](const std::string& s) {
        int i = 0, n = 0;
        return ParseTile(s, &i, &n);
      }))
      ->group(kGroupTiles);
  app->add_option("--region", f->region,
                  plans ? "x,y,w,h: plan the pixels this region of the output frame still needs"
                        : "x,y,w,h: compute this region of the output frame and write it as a part")
      ->check(Parsed("", [](const std::string& s) {
        Bounds2i r;
        return ParseRegion(s, &r);
      }))
      ->excludes(tile)
      ->group(kGroupTiles);
  AddFramesFlag(app, &f->frames,
                "N or A-B: substitute the frame number for each run of '#' in file names (zero-padded to "
                "the run's length: room.####.exr), one frame after another");
}

Status ResolveRegion(const TileFlags& f, int width, int height, int align, Bounds2i* region, std::string* tile) {
  tile->clear();
  if (!f.tile.empty()) {
    int index = 0, count = 0;
    if (Status st = ParseTile(f.tile, &index, &count); !st.ok()) return Status::Error("--tile: " + st.message());
    Status st = TileRegion(width, height, index, count, align, region);
    if (!st.ok()) return Status::Error("--tile " + f.tile + ": " + st.message());
    *tile = std::to_string(index) + "/" + std::to_string(count);
    return Status::Ok();
  }
  if (Status st = ParseRegion(f.region, region); !st.ok()) return Status::Error("--region: " + st.message());
  if (region->max.x > width || region->max.y > height)
    return Status::Error("--region " + f.region + " reaches beyond the " + std::to_string(width) + "x" +
                         std::to_string(height) + " output frame");
  return Status::Ok();
}

Status FrameList(const TileFlags& f, std::vector<int>* frames) {
  frames->clear();
  if (f.frames.empty()) return Status::Ok();
  int a = 0, b = 0;
  if (Status st = ParseFrames(f.frames, &a, &b); !st.ok()) return Status::Error("--frames: " + st.message());
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

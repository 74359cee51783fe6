// Tiles, regions and frame sequences, shared by `dcm render` and
// `dcm reconstruct`: --tile I/N, --region x,y,w,h, --frames A-B with '#'
// patterns in file names.
#pragma once

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "common/image_io.h"
#include "dcm/geometry.h"
#include "dcm/reconstructor.h"
#include "dcm/status.h"
#include "dcm/window_provider.h"

namespace dcm::cli {

/// The flags as parsed.
struct TileFlags {
  std::string tile;    ///< "I/N", I 0-based
  std::string region;  ///< "x,y,w,h" in output pixels
  std::string frames;  ///< "N" or "A-B"
};

/// Adds --frames (N or A-B, checked at parse time) in the tiles group.
void AddFramesFlag(CLI::App* app, std::string* frames, const std::string& help);

/// Adds --tile, --region (exclusive) and --frames, their syntax checked at
/// parse time (the frame's size only once the input is read). `plans`: the command
/// plans the part's pixels (dcm plan) instead of writing it as a part.
void AddTileFlags(CLI::App* app, TileFlags* flags, bool plans = false);

/// True when the flags ask for a part of the frame.
inline bool IsPartial(const TileFlags& f) { return !f.tile.empty() || !f.region.empty(); }

/// The output region the flags select in a width x height frame (tiles on
/// multiples of `align` output pixels where possible, see dcm::TileRegion);
/// `tile` receives "I/N" for --tile, "" for --region. The message names the flag.
Status ResolveRegion(const TileFlags& f, int width, int height, int align, Bounds2i* region, std::string* tile);

/// The frames of --frames ("7" or "1-10"); empty when the flag is absent.
Status FrameList(const TileFlags& f, std::vector<int>* frames);

/// Runs `run(frame)` for each of `frames` in order; at the first that fails,
/// prints "dcm CMD: frame N failed" and returns its exit code.
int RunFrames(const std::string& cmd, const std::vector<int>& frames, const std::function<int(int)>& run);

/// True when `name` contains a '#' frame pattern.
bool HasFramePattern(const std::string& name);

/// Replaces each run of '#' in `pattern` by `frame`, zero-padded to the run's
/// length (room.####.exr, 7 -> room.0007.exr; longer numbers are not cut).
std::string ExpandFrame(const std::string& pattern, int frame);

/// --frames for a command whose flags name files: `names(flags, each)` hands
/// every file name of the flags to `each`. Without --frames, `run(flags)`
/// once; with it, once per frame, each run of '#' in those names replaced by
/// the frame number (RunFrames). A bad frame list, or names without any '#',
/// is a usage error (exit 2) that "dcm CMD: error:" explains.
template <typename Flags>
int RunPerFrame(const std::string& cmd, const Flags& flags, const TileFlags& tiles,
                const std::function<void(Flags*, const std::function<void(std::string*)>&)>& names,
                const std::function<int(const Flags&)>& run) {
  std::vector<int> frames;
  const Status st = FrameList(tiles, &frames);
  std::string problem = st.ok() ? "" : st.message();
  if (st.ok() && frames.empty()) return run(flags);
  if (problem.empty()) {
    bool any = false;
    Flags probe = flags;
    names(&probe, [&](std::string* name) { any = any || HasFramePattern(*name); });
    if (!any) problem = "--frames " + tiles.frames + ": no '#' frame pattern in the input or output names";
  }
  if (!problem.empty()) {
    std::fprintf(stderr, "dcm %s: error: %s\n", cmd.c_str(), problem.c_str());
    return kExitUsage;
  }
  return RunFrames(cmd, frames, [&](int frame) {
    Flags g = flags;
    names(&g, [frame](std::string* name) { *name = ExpandFrame(*name, frame); });
    return run(g);
  });
}

/// The elementary block in output pixels: the tile alignment (the larger of
/// the noisy and the noiseless block: whether the samples are noisy is known
/// only once the provider is).
inline int TileAlignment(const ReconstructionOptions& o) {
  return std::max(1, LargestElementaryBlock(o) / std::max(1, o.downsample));
}

/// The attributes of a part (tile, region, fingerprint, settings, the counts
/// over its pixels) added to `meta`.
void AddPartMetadata(const std::string& tile, const Bounds2i& region, const nlohmann::json& settings,
                     const Reconstruction& part, const RegionInfo& info, toolkit::Metadata* meta);

/// The part's entry of a --stats file: tile, region, window, frame size and
/// the engine's statistics of the whole window.
nlohmann::json PartJson(const std::string& tile, const RegionInfo& info);

}  // namespace dcm::cli

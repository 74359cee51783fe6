// dcm merge: assemble the parts written by `dcm render|reconstruct --tile I/N`
// (or --region) into the frame, after checking that they come from the same
// settings and cover the frame exactly once.
//
//   dcm merge PART.exr... -o OUT.exr [--stats OUT.json] [--frames A-B]
//
// A PART argument with '*', '?' or '[' is expanded by dcm merge itself (sorted),
// after '#' runs are replaced by the frame number with --frames, so that
// `dcm merge --frames 1-24 'parts/room.####.tile*.exr' -o 'out/room.####.exr'`
// works without the shell.
#include <glob.h>

#include <algorithm>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "common/output_guard.h"
#include "common/output_transaction.h"
#include "common/stats_json.h"
#include "common/tiles.h"
#include "flag_checks.h"
#include "output_flags.h"
#include "tile_flags.h"

namespace dcm::cli {
namespace {

struct MergeFlags {
  std::vector<std::string> parts;
  std::string output;
  std::string stats;
  TileFlags frames;  ///< only --frames is used
  bool quiet = false;
  toolkit::ExrFormat exr;  ///< -d, --compression, --ch
};

int Fail(const std::string& message, int code = kExitFailure) {
  std::cerr << "dcm merge: error: " << message << "\n";
  return code;
}

/// The part files of one argument: itself, or its glob matches (sorted).
Status Expand(const std::string& pattern, std::vector<std::string>* out) {
  if (pattern.find_first_of("*?[") == std::string::npos) {
    out->push_back(pattern);
    return Status::Ok();
  }
  glob_t g{};
  const int rc = ::glob(pattern.c_str(), 0, nullptr, &g);
  if (rc == GLOB_NOMATCH) {
    globfree(&g);
    return Status::Error("no part matches '" + pattern + "'");
  }
  if (rc != 0) {
    globfree(&g);
    return Status::Error("cannot expand '" + pattern + "'");
  }
  std::vector<std::string> matches(g.gl_pathv, g.gl_pathv + g.gl_pathc);
  globfree(&g);
  std::sort(matches.begin(), matches.end());
  out->insert(out->end(), matches.begin(), matches.end());
  return Status::Ok();
}

int MergeOne(const std::vector<std::string>& patterns, const std::string& output, const std::string& statsPath,
             bool quiet, const toolkit::ExrFormat& format) {
  std::vector<std::string> parts;
  for (const auto& p : patterns)
    if (Status st = Expand(p, &parts); !st.ok()) return Fail(st.message());
  std::vector<toolkit::FileArg> inputs;
  for (const auto& p : parts) inputs.push_back({"part", p});
  if (Status st = toolkit::CheckOutputs(inputs, {{"-o", output}, {"--stats", statsPath}}); !st.ok())
    return Fail(st.message(), kExitUsage);
  toolkit::OutputTransaction outputs;  // the frame and its stats together, or neither
  toolkit::MergedFrame frame;
  if (Status st = toolkit::MergeParts(parts, &frame); !st.ok()) return Fail(st.message());
  toolkit::Metadata extra;
  extra.strings.push_back({"dcm:merged_parts", std::to_string(parts.size())});
  if (frame.stats.is_object() && frame.stats.contains("exact_fraction")) {
    // The part's own exact fraction is replaced by the frame's.
    auto& floats = frame.metadata.floats;
    floats.erase(std::remove_if(floats.begin(), floats.end(),
                                [](const auto& a) { return a.first == "dcm:exact_fraction"; }),
                 floats.end());
    extra.floats.push_back({"dcm:exact_fraction", frame.stats["exact_fraction"].get<float>()});
  }
  if (!statsPath.empty() && !frame.stats.is_object())
    return Fail("--stats: a part carries no " + std::string(toolkit::kAttrPartStats) + " attribute");
  if (Status st = toolkit::WriteMergedExr(output, frame, extra, format); !st.ok()) return Fail(st.message());
  if (!statsPath.empty()) {
    nlohmann::json j = frame.stats;
    j["parts_files"] = parts;
    j["resolution"] = {frame.width, frame.height};
    if (Status st = toolkit::WriteJson(statsPath, j); !st.ok()) return Fail(st.message());
  }
  if (Status st = outputs.Commit(); !st.ok()) return Fail(st.message());
  if (!quiet)
    std::cout << "dcm merge: " << parts.size() << " parts -> " << output << " (" << frame.width << "x"
              << frame.height << ")\n";
  return kExitOk;
}

int RunMerge(const MergeFlags& f) {
  std::vector<int> frames;
  if (Status st = FrameList(f.frames, &frames); !st.ok()) return Fail(st.message(), kExitUsage);
  if (Status st = toolkit::CheckExrFormat(f.exr); !st.ok()) return Fail(st.message(), kExitUsage);
  if (frames.empty()) return MergeOne(f.parts, f.output, f.stats, f.quiet, f.exr);
  if (!HasFramePattern(f.output))
    return Fail("--frames " + f.frames.frames + ": the output name has no '#' frame pattern", kExitUsage);
  return RunFrames("merge", frames, [&](int frame) {
    std::vector<std::string> parts;
    for (const auto& p : f.parts) parts.push_back(ExpandFrame(p, frame));
    return MergeOne(parts, ExpandFrame(f.output, frame), ExpandFrame(f.stats, frame), f.quiet, f.exr);
  });
}

Registration reg("merge", "Assemble the parts of --tile/--region runs into the frame (checks coverage and settings)",
                 [](CLI::App* app) -> std::function<int()> {
                   auto f = std::make_shared<MergeFlags>();
                   app->option_defaults()->group(kGroupIo);
                   app->add_option("parts", f->parts,
                                   "part EXRs (a pattern with * ? [ is expanded here, sorted)")
                       ->required();
                   app->add_option("-o,--output", f->output, "the frame (EXR)")->required();
                   app->add_option("--stats", f->stats, "write the counts summed over the parts (JSON)");
                   AddExrFormatFlags(app, &f->exr);
                   app->option_defaults()->group(kGroupGeneral);
                   AddFramesFlag(app, &f->frames.frames,
                                 "N or A-B: replace '#' runs in the part and output names by the frame number");
                   app->add_flag("-q,--quiet", f->quiet, "no summary on stdout");
                   return [f] { return RunMerge(*f); };
                 });

}  // namespace
}  // namespace dcm::cli

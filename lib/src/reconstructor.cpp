// The DCM driver: level by level, stage by stage (collect requests, evaluate
// the batch, classify, next requests). Every decision about a block depends
// only on samples at its own pixels, and requests are deduplicated per phase,
// so the result is the same for any thread count and tile size. The stages
// live in the files named after them (engine.h lists them).
#include "dcm/reconstructor.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "dcm/downsample.h"
#include "elapsed.h"
#include "engine.h"

namespace dcm {

std::string_view ToString(SampleReason r) {
  switch (r) {
    case SampleReason::kInterpolated: return "interpolated";
    case SampleReason::kCorner: return "corner";
    case SampleReason::kBorder: return "border";
    case SampleReason::kFirstOrderProbe: return "first_order_probe";
    case SampleReason::kLazyCentre: return "lazy_centre";
    case SampleReason::kCentreProbe: return "centre_probe";
    case SampleReason::kThinObject: return "thin_object";
    case SampleReason::kFallback: return "fallback";
    case SampleReason::kFull: return "full";
    case SampleReason::kPreviewStandIn: return "preview_stand_in";
    case SampleReason::kRendered: return "rendered";
    case SampleReason::kValidation: return "validation";
    case SampleReason::kCount: break;
  }
  return "?";
}

std::string_view ToString(BlockType t) {
  switch (t) {
    case BlockType::kSmooth: return "smooth";
    case BlockType::kSimpleEdge: return "simple_edge";
    case BlockType::kComplexEdge: return "complex_edge";
    case BlockType::kLazy: return "lazy";
    case BlockType::kFallback: return "fallback";
  }
  return "?";
}

namespace detail {

using Clock = std::chrono::steady_clock;

Engine::Engine(SampleProvider& provider, const ReconstructionOptions& opt, const ProviderCapabilities& caps,
               const Settings& settings)
    : provider_(provider),
      opt_(opt),
      caps_(caps),
      settings_(settings),
      block_(settings.elementaryBlock),
      store_(caps.width, caps.height, settings.split, settings.noisy),
      contrast_(settings.contrastMetric, settings.contrastThreshold, settings.split, settings.contrastSignificance) {
  const int blocksPerTile = std::max(1, opt.tileSize / std::max(1, block_));
  grain_ = size_t(blocksPerTile) * size_t(blocksPerTile);
  request_.split = settings.split;
  request_.variance = settings.noisy;
  stats_.settings = settings;
  if (opt.recordInterpolation) record_ = std::make_unique<InterpolationRecorder>(store_);
}

Status Engine::Run(Reconstruction* out, std::vector<Point2i>* pending) {
  pending_ = pending;
  const auto tStart = Clock::now();
  const int W = caps_.width, H = caps_.height;
  StageTimes& t = stats_.stageTimes;
  // The baseline needs no guides: it evaluates every pixel.
  if (!opt_.fullEvaluation) DCM_RETURN_IF_ERROR(Timed(&t.surfaces, [&] { return LoadGuides(); }));
  if (opt_.checkerboard && !opt_.fullEvaluation) deferred_.assign(size_t(W) * size_t(H), SampleReason::kInterpolated);

  if (opt_.fullEvaluation) {
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) store_.Request(x, y, SampleReason::kFull);
    Progress(0.f, "full evaluation");
    DCM_RETURN_IF_ERROR(Flush());
  } else {
    std::vector<Block> classify = LatticeBlocks(W, H, block_);
    std::vector<Block> edges;
    int levels = 1;
    while ((block_ >> (levels - 1)) > opt_.minBlock) ++levels;

    for (int level = 0; level < levels && !(classify.empty() && edges.empty()); ++level) {
      const int size = block_ >> level;
      const bool finest = level == levels - 1;
      const float f0 = float(level) / float(levels), df = 1.f / float(levels);
      std::vector<Block> nextClassify, nextEdges, splitSmooth;  // splitSmooth: for progressive previews

      Progress(f0, "corners");
      DCM_RETURN_IF_ERROR(Timed(&t.refinement, [&] {
        return ClassifySmoothOrEdge(classify, size, finest, &edges, &nextClassify, &splitSmooth);
      }));
      Progress(f0 + 0.4f * df, "edge borders");
      std::vector<EdgeBlock> eb;
      DCM_RETURN_IF_ERROR(Timed(&t.borders, [&] { return EvaluateBorders(edges, size < block_, &eb); }));
      Timed(&t.directions, [&] { OrientEdgeBlocks(eb); });
      if (!finest) {
        DCM_RETURN_IF_ERROR(Timed(&t.simpleComplex, [&] { return ClassifySimpleOrComplex(eb); }));
        DCM_RETURN_IF_ERROR(Timed(&t.lazy, [&] { return EvaluateLazily(eb, size, &nextEdges); }));
      } else {
        DCM_RETURN_IF_ERROR(Timed(&t.finest, [&] { return SettleFinest(eb); }));
      }
      if (opt_.onLevel && !finest) WritePreview(level, splitSmooth, eb);
      classify = std::move(nextClassify);
      edges = std::move(nextEdges);
    }

    DCM_RETURN_IF_ERROR(Timed(&t.interpolation, [&] {
      RequestFallbackInteriors();
      // Flushed before the thin-object pass: a fallback block's border is
      // also its neighbours' border, and what the pass decides depends on it.
      const Status flushed = Flush();
      return flushed.ok() ? InterpolateLeaves() : flushed;
    }));
    if (opt_.onLevel) opt_.onLevel(levels - 1, W, H, store_.radiance());
    stats_.smoothBlocks = int64_t(smoothLeaves_.size());
    stats_.fallbackBlocks = int64_t(fallbackLeaves_.size());
  }

  // Outputs.
  Timed(&t.output, [&] {
    out->workWidth = W;
    out->workHeight = H;
    out->workImage = store_.TakeRadiance();
    out->sampleMap = store_.TakeReasons();
    out->interpolation = record_ ? record_->Finish(W, H, out->sampleMap) : nullptr;
    out->image = BoxDownsample(out->workImage, W, H, opt_.downsample, &out->width, &out->height);
    RecordLeaves(out);
  });
  stats_.totalPixels = int64_t(W) * H;
  // Flush() counted the exact pixels by reason as it made them exact.
  stats_.exactPixels = 0;
  for (size_t r = 0; r < stats_.byReason.size(); ++r)
    if (r != size_t(SampleReason::kInterpolated)) stats_.exactPixels += stats_.byReason[r];
  stats_.byReason[size_t(SampleReason::kInterpolated)] = stats_.totalPixels - stats_.exactPixels;
  const double total = SecondsSince(tStart);
  stats_.timeEngineS = std::max(0.0, total - stats_.timeProviderS - stats_.timeGuidesS);
  out->stats = stats_;
  Progress(1.f, "done");
  return Status::Ok();
}

void Engine::RecordLeaves(Reconstruction* out) {
  out->blocks.clear();
  out->blocks.reserve(smoothLeaves_.size() + orientedLeaves_.size() + fallbackLeaves_.size());
  auto record = [&](const Leaf& l) {
    const Block& b = l.block;
    out->blocks.push_back({b.x0, b.y0, b.x1, b.y1, b.level, l.type, l.direction});
  };
  for (const Leaf& l : smoothLeaves_) record(l);
  for (const Leaf& l : orientedLeaves_) record(l);
  for (const Leaf& l : fallbackLeaves_) record(l);
}

}  // namespace detail

Status Reconstruct(SampleProvider& provider, const ReconstructionOptions& options, Reconstruction* out,
                   std::vector<Point2i>* pending) {
  DCM_RETURN_IF_ERROR(options.Validate());
  const ProviderCapabilities caps = provider.Capabilities();
  constexpr int64_t kMaxPixels = int64_t(1) << 30;
  if (caps.width <= 0 || caps.height <= 0 || int64_t(caps.width) * caps.height > kMaxPixels)
    return Status::Error("provider '" + caps.name + "' reports an unusable size " + std::to_string(caps.width) +
                         "x" + std::to_string(caps.height));
  const detail::Settings settings = detail::Resolve(options, caps);
  Status status;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    detail::Engine engine(provider, options, caps, settings);
    status = engine.Run(out, pending);
  });
  return status;
}

}  // namespace dcm

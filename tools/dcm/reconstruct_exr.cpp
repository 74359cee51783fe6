#include "reconstruct_exr.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <map>
#include <tuple>

#include "common/elapsed.h"
#include "common/image_io.h"
#include "common/stats_json.h"
#include "common/tiles.h"
#include "dcm/downsample.h"
#include "pass_downsample.h"

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
  const aov::AovProvider::NoiseInfo& noise = provider.Noise();
  stats["noise"] = {{"variance", noise.variance}};
  // Absent where the detector did not run; null where it saw no noise at all
  // (an infinite PSNR, as ErrorJson's).
  if (!std::isnan(noise.detectedPsnr))
    stats["noise"]["detected_psnr"] =
        std::isfinite(noise.detectedPsnr) ? nlohmann::json(noise.detectedPsnr) : nlohmann::json(nullptr);
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
  // Both windows must sit on the N-pixel lattice of the frame: no output
  // pixel is a partial box (the Python module has no CheckDownsample before).
  const std::vector<int> onLattice = {display->min.x, display->min.y, data->min.x, data->min.y,
                                      display->max.x, display->max.y, data->max.x, data->max.y};
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

bool ApplyNoisyDefaultGoal(const aov::AovProvider& provider, bool sparse, EngineFlags* e) {
  if (sparse || !provider.Capabilities().variance) return false;
  if (e->threshold || e->targetPsnr || e->budget || e->full || e->method != "dcm") return false;
  e->targetPsnr = kTargetRender;
  e->budget = kNoisyDefaultBudget;
  e->budgetFromThreshold = true;
  return true;
}

Status ReconstructWholeExr(const std::string& cmd, aov::AovProvider& provider, const aov_common::AovFlags& aov,
                           const EngineFlags& givenEngine, const ReconstructionOptions& options,
                           const std::string& referencePath, ExrReconstruction* out, bool* usage) {
  EngineFlags engine = givenEngine;
  *usage = true;
  DCM_RETURN_IF_ERROR(OutputWindows(provider, options.downsample, &out->display, &out->data));
  *usage = false;

  // An explicit reference is read (and checked) before the work starts.
  int refW = 0, refH = 0;
  if (!referencePath.empty()) DCM_RETURN_IF_ERROR(toolkit::ReadRgb(referencePath, &refW, &refH, &out->reference));

  Reconstruction& r = out->result;
  std::vector<Point2i> pending;
  const auto t0 = std::chrono::steady_clock::now();
  Status st = aov_common::Run(provider, options, engine, &r, &pending, nullptr, nullptr, &out->quality);
  if (st.overBudget() && engine.budgetFromThreshold) {
    // The default's bound is too small for this image's coarsest lattice and
    // validation: without it, as --target-psnr render.
    if (engine.verbose)
      std::cerr << "dcm " << cmd << ": the default's bound of " << 100 * kNoisyDefaultBudget
                << " % does not fit this image (" << st.message() << "): without it\n";
    engine.budget.reset();
    engine.budgetFromThreshold = false;
    out->quality.reset();
    st = aov_common::Run(provider, options, engine, &r, &pending, nullptr, nullptr, &out->quality);
  }
  const double wall = toolkit::SecondsSince(t0);
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
  if (out->quality)
    toolkit::AddQualityJson(*out->quality, engine.targetPsnr.value_or(0), engine.budget.value_or(0), &out->stats);
  return Status::Ok();
}

namespace {

/// The channel name of the alpha beside the beauty's red `r`: "A" for "R",
/// "<layer>.Combined.A" for "<layer>.Combined.R"; empty when `r` is named
/// otherwise.
std::string AlphaBeside(const std::string& r) {
  if (r == "R") return "A";
  if (r.size() > 2 && r.compare(r.size() - 2, 2, ".R") == 0) return r.substr(0, r.size() - 1) + "A";
  return "";
}

/// The stored type an input channel keeps in the output.
OIIO::TypeDesc KeptType(OIIO::TypeDesc t) {
  if (t == OIIO::TypeDesc::UINT) return OIIO::TypeDesc::UINT;
  return t == OIIO::TypeDesc::HALF ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT;
}

}  // namespace

std::vector<std::string> OutputLayout::Names() const {
  std::vector<std::string> names;
  for (const auto& c : channels) names.push_back(c.name);
  return names;
}

bool OutputLayout::Reconstructs() const {
  return std::any_of(channels.begin(), channels.end(), [&](const Channel& c) {
    return (c.kind == Kind::kPass && passes[size_t(c.index)].reconstructed) ||
           (c.kind == Kind::kAlpha && alpha && alpha->reconstructed);
  });
}

Status PlanOutputLayout(const aov::AovProvider& provider, const std::vector<std::string>& inputs,
                        const std::vector<std::string>& samples, bool alpha, int downsample, OutputLayout* out) {
  *out = OutputLayout{};
  std::vector<std::string> beauty = provider.BeautyChannels();
  if (beauty.size() != 3) {
    beauty = {"R", "G", "B"};
    out->notes.push_back("output: the beauty is no single channel of the inputs; written as R, G, B");
  }
  const std::string alphaName = AlphaBeside(beauty[0]);
  if (downsample > 1)
    out->notes.push_back("output: --downsample " + std::to_string(downsample) +
                         ": passes box-filtered, IDs by majority, Cryptomatte by rank");

  // Every input channel, first file first (as the provider reads them).
  std::vector<OutputLayout::Source> all;
  std::vector<std::string> cryptoLayers;
  const Bounds2i window = provider.DataWindow();
  out->inputSize = {window.width(), window.height()};
  // Each file's channels of this image, first file first (as the provider
  // reads them), its metadata into the output's.
  auto channelsOf = [&](const std::string& path, std::vector<OutputLayout::Source>* list) -> Status {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return Status::Error("cannot read '" + path + "': " + OIIO::geterror());
    for (int sub = 0; in->seek_subimage(sub, 0); ++sub) {
      const OIIO::ImageSpec& spec = in->spec();
      const Bounds2i data{{spec.x, spec.y}, {spec.x + spec.width, spec.y + spec.height}};
      if (!(data == window)) continue;  // a part of another window is not this image's
      for (const auto& attr : spec.extra_attribs) {
        const std::string name = attr.name().string();
        if (toolkit::IsStructuralAttribute(name) || out->attributes.contains(name)) continue;
        out->attributes.push_back(attr);
        if (name.rfind("cryptomatte/", 0) == 0 && name.size() > 5 && name.compare(name.size() - 5, 5, "/name") == 0)
          cryptoLayers.push_back(attr.get_string());
      }
      for (int c = 0; c < spec.nchannels; ++c) {
        const std::string& name = spec.channelnames[size_t(c)];
        if (std::any_of(list->begin(), list->end(), [&](const auto& s) { return s.name == name; })) continue;
        list->push_back({0, sub, c, name, KeptType(spec.channelformat(c)), false, false, {}});
      }
    }
    return Status::Ok();
  };
  for (size_t f = 0; f < inputs.size(); ++f) {
    const size_t first = all.size();
    DCM_RETURN_IF_ERROR(channelsOf(inputs[f], &all));
    for (size_t k = first; k < all.size(); ++k) all[k].file = int(f);
  }
  // Sparse mode: the channels every samples file holds, read where each
  // rendered (the beauty's and the mask's are the provider's).
  int reconstructed = 0;
  if (!provider.dense() && !samples.empty()) {
    out->samples = samples;
    std::vector<std::vector<OutputLayout::Source>> files(samples.size());
    for (size_t f = 0; f < samples.size(); ++f) DCM_RETURN_IF_ERROR(channelsOf(samples[f], &files[f]));
    const auto& masks = provider.MaskChannels();
    std::vector<std::string> partial;
    for (const auto& s : files[0]) {
      if (std::find(beauty.begin(), beauty.end(), s.name) != beauty.end() ||
          std::find(masks.begin(), masks.end(), s.name) != masks.end())
        continue;
      OutputLayout::Source r = s;
      r.reconstructed = true;
      for (const auto& file : files) {
        const auto it = std::find_if(file.begin(), file.end(), [&](const auto& c) { return c.name == s.name; });
        if (it == file.end()) break;
        r.where.push_back({it->subimage, it->index});
      }
      const auto in = std::find_if(all.begin(), all.end(), [&](const auto& c) { return c.name == s.name; });
      if (r.where.size() != samples.size()) {
        if (in == all.end()) partial.push_back(s.name);
        continue;
      }
      // The inputs' guides render gives the alpha, coverage, at every pixel.
      if (in != all.end() && s.name == alphaName) continue;
      ++reconstructed;
      if (in != all.end()) *in = r;
      else all.push_back(r);
    }
    if (!partial.empty()) {
      std::string names;
      for (const auto& p : partial) names += (names.empty() ? "" : ", ") + p;
      out->notes.push_back("output: not in every samples file, not written: " + names);
    }
  }
  out->cryptoLayers = cryptoLayers;
  const auto& ids = provider.IdChannels();
  for (auto& s : all) {
    s.raw = s.type == OIIO::TypeDesc::UINT || std::find(ids.begin(), ids.end(), s.name) != ids.end();
    for (const auto& layer : cryptoLayers)
      if (s.name.size() > layer.size() && s.name.compare(0, layer.size(), layer) == 0 &&
          std::isdigit(static_cast<unsigned char>(s.name[layer.size()])))
        s.raw = true;
  }

  // The input's order where it holds the beauty, else the beauty first.
  auto isBeauty = [&](const std::string& name) { return std::find(beauty.begin(), beauty.end(), name) != beauty.end(); };
  const bool inPlace = std::all_of(beauty.begin(), beauty.end(), [&](const std::string& b) {
    return std::any_of(all.begin(), all.end(), [&](const auto& s) { return s.name == b; });
  });
  using Kind = OutputLayout::Kind;
  if (!inPlace)
    for (int c = 0; c < 3; ++c) out->channels.push_back({Kind::kBeauty, c, beauty[size_t(c)]});
  for (const auto& s : all) {
    if (isBeauty(s.name)) {
      if (inPlace)
        out->channels.push_back(
            {Kind::kBeauty, int(std::find(beauty.begin(), beauty.end(), s.name) - beauty.begin()), s.name});
    } else if (!alphaName.empty() && s.name == alphaName) {
      out->alpha = s;
      if (inPlace) out->channels.push_back({Kind::kAlpha, 0, alphaName});  // else after the beauty, below
    } else {
      out->channels.push_back({Kind::kPass, int(out->passes.size()), s.name});
      out->passes.push_back(s);
    }
  }
  const bool haveAlpha = out->alpha.has_value() || (alpha && !alphaName.empty());
  if (haveAlpha && (!inPlace || !out->alpha)) {
    // After the beauty's last component.
    size_t at = 0;
    for (size_t i = 0; i < out->channels.size(); ++i)
      if (out->channels[i].kind == Kind::kBeauty) at = i + 1;
    out->channels.insert(out->channels.begin() + std::ptrdiff_t(at), {Kind::kAlpha, 0, alphaName});
  }
  if (alpha && alphaName.empty())
    out->notes.push_back("output: --alpha: the beauty's channels (" + beauty[0] + ", ...) have no alpha beside them");
  const int copied = int(out->passes.size()) - reconstructed + (out->alpha && out->alpha->reconstructed ? 1 : 0);
  out->notes.push_back(
      "output: channels " + std::to_string(out->channels.size()) + " (" +
      (out->alpha ? "alpha " + alphaName + (out->alpha->reconstructed ? " reconstructed" : " from the inputs")
                  : haveAlpha ? "alpha " + alphaName + " = 1" : "no alpha") +
      ", " + std::to_string(copied) + " passes " + (downsample > 1 ? "downsampled" : "copied") +
      (reconstructed ? ", " + std::to_string(out->passes.size() - size_t(copied)) +
                           " reconstructed from the samples with the beauty's interpolation"
                     : std::string()) +
      "), " + std::to_string(out->attributes.size()) + " metadata attributes of the inputs");
  return Status::Ok();
}

Status BuildOutputImage(const aov::AovProvider& provider, const OutputLayout& layout, const std::vector<std::string>& inputs,
                        const ExrReconstruction& run, int downsample, const toolkit::Metadata& provenance,
                        toolkit::OutputImage* out, const Bounds2i* region) {
  const Reconstruction& r = run.result;
  // The inputs' data window: the alpha's resolution.
  const int inWidth = layout.inputSize.x, inHeight = layout.inputSize.y;
  out->display = run.display;
  out->data = run.data;
  if (region)
    out->data = {{run.data.min.x + region->min.x, run.data.min.y + region->min.y},
                 {run.data.min.x + region->max.x, run.data.min.y + region->max.y}};
  out->attributes = layout.attributes;
  toolkit::AddMetadata(provenance, &out->attributes);
  const size_t n = r.image.size();
  if (n != size_t(out->data.area()))
    return Status::Error("the output has " + std::to_string(n) + " pixels, its data window " +
                         std::to_string(out->data.area()));

  // The input channels the layout reads. EXR compresses all channels of a
  // block of scanlines together: each part is decoded once, as float, and
  // only UINT channels (IDs above 2^24 would not survive float) apart. A
  // part of the frame reads only the input rows its region covers.
  const int rowBegin = region ? region->min.y * downsample : 0;
  const int rowEnd = region ? region->max.y * downsample : inHeight;
  const int rows = rowEnd - rowBegin;
  struct Part {
    int nchannels = 0;
    size_t pixels = 0;
    std::vector<float> values;  // interleaved
  };
  // (file, subimage, first row, end row); the samples files after the inputs
  std::map<std::tuple<int, int, int, int>, Part> parts;
  auto path = [&](int file) -> const std::string& {
    return size_t(file) < inputs.size() ? inputs[size_t(file)] : layout.samples[size_t(file) - inputs.size()];
  };
  // Rows [y0, y1) of channel `index` of (file, subimage): as float, or UINT
  // into `ids`.
  auto readRows = [&](int file, int subimage, int index, OIIO::TypeDesc type, const std::string& name, int y0, int y1,
                      toolkit::OutputChannel* ch) -> Status {
    auto fail = [&](const std::string& why) {
      return Status::Error("cannot read channel '" + name + "' of '" + path(file) + "': " + why);
    };
    if (type == OIIO::TypeDesc::UINT) {
      auto in = OIIO::ImageInput::open(path(file));
      if (!in) return fail(OIIO::geterror());
      const OIIO::ImageSpec spec = in->spec(subimage, 0);
      ch->ids.resize(size_t(spec.width) * size_t(y1 - y0));
      if (!in->read_scanlines(subimage, 0, spec.y + y0, spec.y + y1, 0, index, index + 1,
                              OIIO::TypeDesc::UINT, ch->ids.data()))
        return fail(in->geterror());
      return Status::Ok();
    }
    auto [it, fresh] = parts.try_emplace({file, subimage, y0, y1});
    Part& part = it->second;
    if (fresh) {
      auto in = OIIO::ImageInput::open(path(file));
      if (!in) return fail(OIIO::geterror());
      const OIIO::ImageSpec spec = in->spec(subimage, 0);
      part.nchannels = spec.nchannels;
      part.pixels = size_t(spec.width) * size_t(y1 - y0);
      part.values.resize(part.pixels * size_t(part.nchannels));
      if (!in->read_scanlines(subimage, 0, spec.y + y0, spec.y + y1, 0, 0, spec.nchannels,
                              OIIO::TypeDesc::FLOAT, part.values.data()))
        return fail(in->geterror());
    }
    ch->values.resize(part.pixels);
    for (size_t i = 0; i < part.pixels; ++i) ch->values[i] = part.values[i * size_t(part.nchannels) + size_t(index)];
    return Status::Ok();
  };
  // The reconstructed channels (sparse mode) at the exact pixels of the
  // record's window, each pixel from the samples file whose beauty it has;
  // gathered one samples file at a time (a farm's round trip has many).
  const InterpolationRecord* record = r.interpolation.get();
  std::vector<const OutputLayout::Source*> wanted;
  for (const auto& c : layout.channels) {
    const OutputLayout::Source* s = c.kind == OutputLayout::Kind::kPass  ? &layout.passes[size_t(c.index)]
                                    : c.kind == OutputLayout::Kind::kAlpha ? (layout.alpha ? &*layout.alpha : nullptr)
                                                                           : nullptr;
    if (s && s->reconstructed) wanted.push_back(s);
  }
  std::vector<std::vector<float>> exactOf(wanted.size());
  Bounds2i w;
  if (!wanted.empty()) {
    if (!record) return Status::Error("channel '" + wanted[0]->name + "': the reconstruction kept no interpolation record");
    // The record covers the region's pixels and the window around them.
    w = record->window();
    const int x0 = region ? region->min.x * downsample : 0;
    const int x1 = region ? std::min(region->max.x * downsample, inWidth) : inWidth;
    if (w.min.y > rowBegin || w.max.y < std::min(rowEnd, inHeight) || w.min.x > x0 || w.max.x < x1 ||
        w.max.x > inWidth || w.max.y > inHeight)
      return Status::Error("the interpolation record's window " + toolkit::RegionText(w) +
                           " does not cover the output's pixels");
    const size_t ww = size_t(w.width());
    std::vector<int> fileOf(ww * size_t(w.height()), -1);
    for (int y = w.min.y; y < w.max.y; ++y)
      for (int x = w.min.x; x < w.max.x; ++x) {
        const size_t i = size_t(y - w.min.y) * ww + size_t(x - w.min.x);
        if (!record->IsExact(int64_t(i))) continue;
        fileOf[i] = provider.SamplesFileOf({x, y});
        if (fileOf[i] < 0 || size_t(fileOf[i]) >= layout.samples.size())
          return Status::Error("exact pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                               ") is in no samples file");
      }
    for (auto& plane : exactOf) plane.assign(fileOf.size(), 0.f);
    for (size_t f = 0; f < layout.samples.size(); ++f) {
      if (std::find(fileOf.begin(), fileOf.end(), int(f)) == fileOf.end()) continue;
      const int file = int(inputs.size() + f);
      for (size_t k = 0; k < wanted.size(); ++k) {
        const auto& s = *wanted[k];
        toolkit::OutputChannel decoded;
        DCM_RETURN_IF_ERROR(readRows(file, s.where[f].first, s.where[f].second, s.type, s.name, w.min.y, w.max.y, &decoded));
        for (size_t i = 0; i < fileOf.size(); ++i) {
          if (fileOf[i] != int(f)) continue;
          const size_t at = (i / ww) * size_t(inWidth) + size_t(w.min.x) + i % ww;
          // A uint ID's bits travel in the float (ChannelKind::kId only copies).
          if (s.type == OIIO::TypeDesc::UINT) std::memcpy(&exactOf[k][i], &decoded.ids[at], sizeof(float));
          else exactOf[k][i] = decoded.values[at];
        }
      }
      // This file's decoded rows are no longer needed.
      for (auto it = parts.begin(); it != parts.end();) it = std::get<0>(it->first) == file ? parts.erase(it) : std::next(it);
    }
  }
  // A reconstructed channel: the record applied to its exact values, in the
  // rows of the output's region like a copied channel's.
  auto reconstruct = [&](const OutputLayout::Source& s, toolkit::OutputChannel* ch) -> Status {
    const size_t k = size_t(std::find(wanted.begin(), wanted.end(), &s) - wanted.begin());
    const bool ids = s.type == OIIO::TypeDesc::UINT;
    std::vector<float> plane;
    DCM_RETURN_IF_ERROR(record->Apply(exactOf[k], s.raw || ids ? ChannelKind::kId : ChannelKind::kContinuous, &plane));
    std::vector<float>().swap(exactOf[k]);
    const size_t ww = size_t(w.width()), size = size_t(inWidth) * size_t(rows);
    if (ids) ch->ids.assign(size, 0u);
    else ch->values.assign(size, 0.f);
    for (int y = std::max(w.min.y, rowBegin); y < std::min(w.max.y, rowEnd); ++y)
      for (int x = w.min.x; x < w.max.x; ++x) {
        const float v = plane[size_t(y - w.min.y) * ww + size_t(x - w.min.x)];
        const size_t at = size_t(y - rowBegin) * size_t(inWidth) + size_t(x);
        if (ids) std::memcpy(&ch->ids[at], &v, sizeof(float));
        else ch->values[at] = v;
      }
    return Status::Ok();
  };
  auto read = [&](const OutputLayout::Source& s, toolkit::OutputChannel* ch) -> Status {
    if (s.reconstructed) return reconstruct(s, ch);
    return readRows(s.file, s.subimage, s.index, s.type, s.name, rowBegin, rowEnd, ch);
  };
  std::vector<size_t> passes;  // output channels that are passes
  std::vector<size_t> fromInputs;  // output channels read from the inputs: whole rows of the output
  for (const auto& c : layout.channels) {
    toolkit::OutputChannel ch;
    ch.name = c.name;
    switch (c.kind) {
      case OutputLayout::Kind::kBeauty:
        ch.values.resize(n);
        for (size_t i = 0; i < n; ++i) ch.values[i] = r.image[i][c.index];
        break;
      case OutputLayout::Kind::kAlpha:
        if (!layout.alpha) {
          ch.values.assign(n, 1.f);
          break;
        }
        DCM_RETURN_IF_ERROR(read(*layout.alpha, &ch));
        // The coverage of the output pixel: the mean of its input pixels'.
        if (downsample > 1) ch.values = BoxMeanPlane(ch.values, inWidth, rows, downsample);
        fromInputs.push_back(out->channels.size());
        break;
      case OutputLayout::Kind::kPass: {
        const auto& s = layout.passes[size_t(c.index)];
        ch.type = s.type;
        ch.raw = s.raw;
        DCM_RETURN_IF_ERROR(read(s, &ch));
        passes.push_back(out->channels.size());
        fromInputs.push_back(out->channels.size());
        break;
      }
    }
    out->channels.push_back(std::move(ch));
  }
  if (downsample > 1 && !passes.empty())
    DCM_RETURN_IF_ERROR(DownsamplePasses(&out->channels, passes, layout.cryptoLayers, inWidth, rows, downsample));
  if (region) {
    // What was read holds the region's rows across the whole width: cut to its columns.
    const size_t W = size_t(run.data.width());
    auto cut = [&](auto& plane) {
      if (plane.empty()) return;
      std::remove_reference_t<decltype(plane)> mine;
      mine.reserve(size_t(region->area()));
      for (int y = 0; y < region->height(); ++y)
        for (int x = region->min.x; x < region->max.x; ++x) mine.push_back(plane[size_t(y) * W + size_t(x)]);
      plane = std::move(mine);
    };
    for (size_t c : fromInputs) {
      cut(out->channels[c].values);
      cut(out->channels[c].ids);
    }
  }
  return Status::Ok();
}

}  // namespace dcm::cli

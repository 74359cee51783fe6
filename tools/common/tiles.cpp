// Parts of a frame (tiles, regions) as EXRs with a data window, and merging them.
#include "tiles.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "common/stats_json.h"

namespace dcm::toolkit {

namespace {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

std::string Quote(const std::string& path) { return "'" + path + "'"; }

/// "'a.exr' (tile 3/8, region 0,0,64,64)".
std::string Describe(const Part& p) {
  std::string s = Quote(p.path) + " (";
  if (!p.tile.empty()) s += "tile " + p.tile + ", ";
  return s + "region " + RegionText(p.region) + ")";
}

bool ParseRegion(const std::string& text, Bounds2i* r) {
  int x = 0, y = 0, w = 0, h = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d,%d,%d,%d%c", &x, &y, &w, &h, &extra) != 4 || w <= 0 || h <= 0) return false;
  *r = {{x, y}, {x + w, y + h}};
  return true;
}

bool ParseTile(const std::string& text, int* index, int* count) {
  char extra = 0;
  return std::sscanf(text.c_str(), "%d/%d%c", index, count, &extra) == 2 && *count >= 1 && *index >= 0 &&
         *index < *count;
}

/// Names the fields where two settings differ ("options.contrast_threshold:
/// 0.15 vs 0.1"), at most a few.
void DiffJson(const nlohmann::json& a, const nlohmann::json& b, const std::string& prefix,
              std::vector<std::string>* out) {
  if (a.is_object() && b.is_object()) {
    std::set<std::string> keys;
    for (auto it = a.begin(); it != a.end(); ++it) keys.insert(it.key());
    for (auto it = b.begin(); it != b.end(); ++it) keys.insert(it.key());
    for (const auto& k : keys) {
      const std::string name = prefix.empty() ? k : prefix + "." + k;
      if (!a.contains(k)) out->push_back(name + ": absent vs " + b[k].dump());
      else if (!b.contains(k)) out->push_back(name + ": " + a[k].dump() + " vs absent");
      else DiffJson(a[k], b[k], name, out);
    }
    return;
  }
  if (a != b) out->push_back((prefix.empty() ? std::string("settings") : prefix) + ": " + a.dump() + " vs " + b.dump());
}

/// Adds the numbers of `add` into `sum` (objects recursively).
void SumJson(nlohmann::json& sum, const nlohmann::json& add) {
  for (auto it = add.begin(); it != add.end(); ++it) {
    if (it->is_object()) {
      if (!sum.contains(it.key())) sum[it.key()] = nlohmann::json::object();
      SumJson(sum[it.key()], *it);
    } else if (it->is_number_integer()) {
      sum[it.key()] = (sum.contains(it.key()) ? sum[it.key()].get<int64_t>() : int64_t(0)) + it->get<int64_t>();
    } else if (it->is_number()) {
      sum[it.key()] = (sum.contains(it.key()) ? sum[it.key()].get<double>() : 0.0) + it->get<double>();
    }
  }
}

bool IsPartAttribute(const std::string& name) {
  return name == kAttrTile || name == kAttrRegion || name == kAttrFingerprint || name == kAttrSettings ||
         name == kAttrPartStats || name == kAttrRawChannels;
}

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    if (end > start) out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

}  // namespace

uint64_t HashBytes(std::span<const char> bytes, uint64_t seed) {
  uint64_t h = seed;
  for (char c : bytes) {
    h ^= uint64_t(uint8_t(c));
    h *= 1099511628211ull;
  }
  return h;
}

Status HashFile(const std::string& path, uint64_t* hash) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error("cannot read '" + path + "' (for the settings fingerprint)");
  uint64_t h = 14695981039346656037ull;
  std::vector<char> buffer(size_t(1) << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    const std::streamsize n = in.gcount();
    if (n > 0) h = HashBytes(std::span<const char>(buffer.data(), size_t(n)), h);
  }
  if (in.bad()) return Status::Error("cannot read '" + path + "' (for the settings fingerprint)");
  *hash = h;
  return Status::Ok();
}

std::string HexHash(uint64_t hash) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, hash);
  return buf;
}

nlohmann::json PartSettings(const std::string& command, const std::string& version,
                            const ReconstructionOptions& options, const nlohmann::json& identity) {
  nlohmann::json o = OptionsToJson(options);
  for (const char* k : {"threads", "tile_size", "batch_size"}) o.erase(k);
  return {{"command", command}, {"version", version}, {"options", o}, {"input", identity}};
}

std::string Fingerprint(const nlohmann::json& settings) {
  const std::string text = settings.dump();
  return HexHash(HashBytes(std::span<const char>(text.data(), text.size())));
}

std::string RegionText(const Bounds2i& r) {
  return std::to_string(r.min.x) + "," + std::to_string(r.min.y) + "," + std::to_string(r.width()) + "," +
         std::to_string(r.height());
}

Status WritePartExr(const std::string& path, int frameWidth, int frameHeight, const Bounds2i& region,
                    std::span<const RGB> pixels, const Metadata& metadata, bool alpha) {
  const Bounds2i frame{{0, 0}, {frameWidth, frameHeight}};
  if (region.empty() || Intersect(region, frame) != region)
    return Status::Error("cannot write '" + path + "': region " + RegionText(region) + " is not inside the " +
                         std::to_string(frameWidth) + "x" + std::to_string(frameHeight) + " frame");
  if (pixels.size() != size_t(region.area()))
    return Status::Error("cannot write '" + path + "': " + std::to_string(pixels.size()) + " pixels given for region " +
                         RegionText(region));
  return WriteRgbExr(path, frame, region, pixels, metadata, alpha);
}

Status WritePartImage(const std::string& path, OutputImage image, const Metadata& metadata) {
  if (image.data.empty() || Intersect(image.data, image.display) != image.data)
    return Status::Error("cannot write '" + path + "': region " + RegionText(image.data) + " is not inside the " +
                         std::to_string(image.display.width()) + "x" + std::to_string(image.display.height()) +
                         " frame");
  std::string raw;
  for (const auto& c : image.channels)
    if (c.raw || c.type == TypeDesc::UINT) raw += (raw.empty() ? "" : ",") + c.name;
  AddMetadata(metadata, &image.attributes);
  if (!raw.empty()) image.attributes.attribute(kAttrRawChannels, raw);
  return WriteOutputExr(path, image, ExrFormat{});
}

Status ReadPart(const std::string& path, Part* part, bool withPixels) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(Quote(path) + ": no such file");
  auto in = ImageInput::open(path);
  if (!in) return Status::Error("cannot read " + Quote(path) + ": " + OIIO::geterror());
  const ImageSpec& spec = in->spec();
  if (spec.deep || spec.depth > 1) return Status::Error(Quote(path) + ": not a flat 2D image");
  part->path = path;
  part->tile = spec.get_string_attribute(kAttrTile);
  part->fingerprint = spec.get_string_attribute(kAttrFingerprint);
  part->settings = spec.get_string_attribute(kAttrSettings);
  part->partStats = spec.get_string_attribute(kAttrPartStats);
  const std::string region = spec.get_string_attribute(kAttrRegion);
  if (region.empty() || part->fingerprint.empty())
    return Status::Error(Quote(path) + ": not a part of a dcm frame (no " + std::string(kAttrRegion) + " or " +
                         kAttrFingerprint + " attribute; write parts with --tile or --region)");
  if (!ParseRegion(region, &part->region))
    return Status::Error(Quote(path) + ": attribute " + kAttrRegion + " is '" + region + "', expected x,y,w,h");
  int index = 0, count = 0;
  if (!part->tile.empty() && !ParseTile(part->tile, &index, &count))
    return Status::Error(Quote(path) + ": attribute " + kAttrTile + " is '" + part->tile + "', expected I/N");
  part->frameWidth = spec.full_width;
  part->frameHeight = spec.full_height;
  const Bounds2i data{{spec.x, spec.y}, {spec.x + spec.width, spec.y + spec.height}};
  if (data != part->region || spec.full_x != 0 || spec.full_y != 0)
    return Status::Error(Quote(path) + ": data window " + RegionText(data) + " does not match its " + kAttrRegion +
                         " " + RegionText(part->region) + " (or the display window does not start at 0,0)");
  DCM_RETURN_IF_ERROR(CheckImageDimensions(path, spec.full_width, spec.full_height, spec.nchannels));
  const Bounds2i frame{{0, 0}, {spec.full_width, spec.full_height}};
  if (Intersect(data, frame) != data)
    return Status::Error(Quote(path) + ": region " + RegionText(data) + " lies outside its " +
                         std::to_string(spec.full_width) + "x" + std::to_string(spec.full_height) + " frame");
  part->channels = spec.channelnames;
  part->types.clear();
  for (int c = 0; c < spec.nchannels; ++c) {
    const TypeDesc t = spec.channelformat(c);
    part->types.push_back(t == TypeDesc::UINT ? TypeDesc::UINT : t == TypeDesc::HALF ? TypeDesc::HALF : TypeDesc::FLOAT);
  }
  part->rawChannels = SplitCommas(spec.get_string_attribute(kAttrRawChannels));
  part->pixels.clear();
  part->ids.assign(size_t(spec.nchannels), {});
  if (withPixels) {
    const size_t n = size_t(spec.width) * size_t(spec.height);
    part->pixels.assign(n * size_t(spec.nchannels), 0.f);
    if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, part->pixels.data()))
      return Status::Error("cannot read the pixels of " + Quote(path) + ": " + in->geterror());
    // IDs above 2^24 do not survive float: UINT channels are read as they are.
    for (int c = 0; c < spec.nchannels; ++c) {
      if (part->types[size_t(c)] != TypeDesc::UINT) continue;
      part->ids[size_t(c)].resize(n);
      if (!in->read_image(0, 0, c, c + 1, TypeDesc::UINT, part->ids[size_t(c)].data()))
        return Status::Error("cannot read channel '" + spec.channelnames[size_t(c)] + "' of " + Quote(path) + ": " +
                             in->geterror());
    }
  }
  part->metadata = {};
  part->attributes.clear();
  for (const auto& p : spec.extra_attribs) {
    const std::string name = p.name().string();
    if (IsPartAttribute(name)) continue;
    if (name.rfind("dcm:", 0) == 0 || name == "Software") {
      if (p.type() == TypeDesc::STRING) part->metadata.strings.push_back({name, p.get_string()});
      else if (p.type() == TypeDesc::FLOAT) part->metadata.floats.push_back({name, p.get_float()});
    } else if (!IsStructuralAttribute(name)) {
      part->attributes.push_back(p);
    }
  }
  return Status::Ok();
}

Status MergeParts(const std::vector<std::string>& paths, MergedFrame* frame) {
  if (paths.empty()) return Status::Error("no parts to merge");
  std::vector<Part> parts(paths.size());
  // Headers first: every check before any pixel is read; then one part's
  // pixels at a time, so that merging holds the frame and one part.
  for (size_t i = 0; i < paths.size(); ++i) DCM_RETURN_IF_ERROR(ReadPart(paths[i], &parts[i], false));
  const Part& first = parts[0];
  int tileCount = 0;
  {
    int index = 0;
    if (!first.tile.empty()) ParseTile(first.tile, &index, &tileCount);
  }
  for (const Part& p : parts) {
    if (p.frameWidth != first.frameWidth || p.frameHeight != first.frameHeight)
      return Status::Error(Describe(p) + " belongs to a " + std::to_string(p.frameWidth) + "x" +
                           std::to_string(p.frameHeight) + " frame, " + Describe(first) + " to a " +
                           std::to_string(first.frameWidth) + "x" + std::to_string(first.frameHeight) + " frame");
    if (p.fingerprint != first.fingerprint) {
      std::string detail;
      try {
        std::vector<std::string> diffs;
        DiffJson(nlohmann::json::parse(first.settings), nlohmann::json::parse(p.settings), "", &diffs);
        for (size_t k = 0; k < diffs.size() && k < 4; ++k) detail += (k ? "; " : ": ") + diffs[k];
        if (diffs.size() > 4) detail += "; and " + std::to_string(diffs.size() - 4) + " more";
      } catch (const std::exception&) {
        detail = " (settings not readable)";
      }
      return Status::Error(Describe(p) + " was made with other settings than " + Describe(first) +
                           " (fingerprint " + p.fingerprint + " vs " + first.fingerprint + ")" + detail);
    }
    if (p.channels != first.channels || p.types != first.types) {
      auto join = [](const std::vector<std::string>& v) {
        std::string s;
        for (const auto& c : v) s += (s.empty() ? "" : ",") + c;
        return s;
      };
      return Status::Error(Describe(p) + " has channels " + join(p.channels) + ", " + Describe(first) + " " +
                           join(first.channels));
    }
    int index = 0, count = 0;
    if (!p.tile.empty()) ParseTile(p.tile, &index, &count);
    if (count != tileCount)
      return Status::Error(Describe(p) + " is from a split into " +
                           (count ? std::to_string(count) + " tiles" : std::string("an explicit region")) + ", " +
                           Describe(first) + " from " +
                           (tileCount ? std::to_string(tileCount) + " tiles" : std::string("an explicit region")));
  }
  // Overlaps: regions are rectangles, so pairs of parts suffice.
  for (size_t i = 0; i < parts.size(); ++i)
    for (size_t j = i + 1; j < parts.size(); ++j) {
      const Bounds2i o = Intersect(parts[i].region, parts[j].region);
      if (!o.empty())
        return Status::Error("parts " + Describe(parts[i]) + " and " + Describe(parts[j]) + " overlap in " +
                             std::to_string(o.width()) + "x" + std::to_string(o.height()) + " pixels from (" +
                             std::to_string(o.min.x) + "," + std::to_string(o.min.y) + ")");
    }
  // Coverage.
  const int W = first.frameWidth, H = first.frameHeight;
  const size_t nch = first.channels.size();
  std::vector<uint8_t> covered(size_t(W) * size_t(H), 0);
  frame->pixels.assign(size_t(W) * size_t(H) * nch, 0.f);
  frame->ids.assign(nch, {});
  for (size_t c = 0; c < nch; ++c)
    if (first.types[c] == TypeDesc::UINT) frame->ids[c].assign(size_t(W) * size_t(H), 0u);
  for (const Part& header : parts) {
    Part p;
    DCM_RETURN_IF_ERROR(ReadPart(header.path, &p));
    if (p.region != header.region || p.channels != header.channels || p.types != header.types)
      return Status::Error(Quote(p.path) + " changed while it was being merged");
    const int w = p.region.width();
    for (int y = 0; y < p.region.height(); ++y) {
      const size_t dst = (size_t(y + p.region.min.y) * size_t(W) + size_t(p.region.min.x));
      std::copy_n(p.pixels.begin() + ptrdiff_t(size_t(y) * size_t(w) * nch), size_t(w) * nch,
                  frame->pixels.begin() + ptrdiff_t(dst * nch));
      for (size_t c = 0; c < nch; ++c)
        if (!p.ids[c].empty())
          std::copy_n(p.ids[c].begin() + ptrdiff_t(size_t(y) * size_t(w)), size_t(w),
                      frame->ids[c].begin() + ptrdiff_t(dst));
      std::fill_n(covered.begin() + ptrdiff_t(dst), w, uint8_t(1));
    }
  }
  int64_t missing = 0;
  Bounds2i hole{{W, H}, {0, 0}};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (!covered[size_t(y) * size_t(W) + size_t(x)]) {
        ++missing;
        hole.min.x = std::min(hole.min.x, x), hole.min.y = std::min(hole.min.y, y);
        hole.max.x = std::max(hole.max.x, x + 1), hole.max.y = std::max(hole.max.y, y + 1);
      }
  if (missing) {
    std::string tiles;
    if (tileCount) {
      std::set<int> present;
      for (const Part& p : parts) {
        int index = 0, count = 0;
        ParseTile(p.tile, &index, &count);
        present.insert(index);
      }
      int listed = 0, absent = 0;
      for (int i = 0; i < tileCount; ++i)
        if (!present.count(i)) {
          ++absent;
          if (listed < 8) tiles += (listed++ ? ", " : "") + std::to_string(i) + "/" + std::to_string(tileCount);
        }
      if (absent > listed) tiles += ", ...";
      tiles = "; missing tile" + std::string(absent > 1 ? "s " : " ") + tiles;
    }
    return Status::Error("the " + std::to_string(parts.size()) + " parts leave " + std::to_string(missing) + " of " +
                         std::to_string(int64_t(W) * H) + " pixels of the " + std::to_string(W) + "x" +
                         std::to_string(H) + " frame uncovered (within " + RegionText(hole) + ")" + tiles);
  }

  frame->width = W;
  frame->height = H;
  frame->channels = first.channels;
  frame->types = first.types;
  frame->rawChannels = first.rawChannels;
  frame->metadata = first.metadata;
  frame->attributes = first.attributes;
  frame->stats = nullptr;
  bool allStats = true;
  nlohmann::json sum = nlohmann::json::object();
  for (const Part& p : parts) {
    if (p.partStats.empty()) {
      allStats = false;
      break;
    }
    try {
      SumJson(sum, nlohmann::json::parse(p.partStats));
    } catch (const std::exception& e) {
      return Status::Error(Quote(p.path) + ": attribute " + kAttrPartStats + " is not JSON: " + e.what());
    }
  }
  if (allStats) {
    if (sum.contains("total_pixels") && sum["total_pixels"].get<int64_t>() > 0)
      sum["exact_fraction"] = double(sum.value("exact_pixels", int64_t(0))) / double(sum["total_pixels"].get<int64_t>());
    sum["parts"] = parts.size();
    frame->stats = sum;
  }
  return Status::Ok();
}

Status WriteMergedExr(const std::string& path, const MergedFrame& frame, const Metadata& extra,
                      const ExrFormat& format) {
  const size_t nch = frame.channels.size();
  const size_t n = size_t(std::max(frame.width, 0)) * size_t(std::max(frame.height, 0));
  if (n == 0 || nch == 0 || frame.pixels.size() != n * nch)
    return Status::Error("cannot write '" + path + "': inconsistent merged frame");
  OutputImage image;
  image.display = image.data = {{0, 0}, {frame.width, frame.height}};
  for (size_t c = 0; c < nch; ++c) {
    OutputChannel ch;
    ch.name = frame.channels[c];
    ch.type = c < frame.types.size() ? frame.types[c] : TypeDesc::FLOAT;
    ch.raw = std::find(frame.rawChannels.begin(), frame.rawChannels.end(), ch.name) != frame.rawChannels.end();
    if (ch.type == TypeDesc::UINT) {
      ch.ids = frame.ids.at(c);
    } else {
      ch.values.resize(n);
      for (size_t i = 0; i < n; ++i) ch.values[i] = frame.pixels[i * nch + c];
    }
    image.channels.push_back(std::move(ch));
  }
  image.attributes = frame.attributes;
  AddMetadata(frame.metadata, &image.attributes);
  AddMetadata(extra, &image.attributes);
  return WriteOutputExr(path, image, format);
}

}  // namespace dcm::toolkit

#include "exr_channels.h"

#include <OpenImageIO/strutil.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "dcm/memory_budget.h"

namespace dcm::aov::detail {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

ChannelSet::ChannelSet() = default;
ChannelSet::~ChannelSet() = default;
ChannelSet::ChannelSet(ChannelSet&&) noexcept = default;
ChannelSet& ChannelSet::operator=(ChannelSet&&) noexcept = default;

namespace {

Status CheckDimensions(const std::string& path, int width, int height) {
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide)
    return Status::Error(Quote(path) + ": absurd image dimensions " + std::to_string(width) + "x" +
                         std::to_string(height) + " (at most " + std::to_string(kMaxSide) +
                         " pixels per side)");
  return CheckMemoryBudget(Quote(path) + ": " + std::to_string(width) + "x" + std::to_string(height) + " pixels",
                           double(width) * double(height) * kPlanesPerPixel * 4.0);
}

/// Scanlines per chunk of an OpenEXR compression method (OIIO's name).
int LinesPerChunk(std::string compression) {
  compression = compression.substr(0, compression.find(':'));  // "dwaa:45"
  if (compression.empty() || compression == "none" || compression == "rle" || compression == "zips") return 1;
  if (compression == "zip" || compression == "pxr24") return 16;
  if (compression == "piz" || compression == "b44" || compression == "b44a" || compression == "dwaa") return 32;
  return 256;  // dwab, and the most any method takes
}

/// The least a part of `spec` takes in an OpenEXR file of `parts` parts: per
/// chunk (a block of scanlines, or a tile of level 0) an offset-table entry
/// and the chunk's header (coordinates and data size), and its pixel data
/// compressed at most kMaxCompressionRatio:1 (stored raw without compression).
double LeastPartBytes(const ImageSpec& spec, int parts) {
  const double w = std::max(spec.width, 1), h = std::max(spec.height, 1);
  const std::string compression = spec.get_string_attribute("compression", "none");
  const double partNumber = parts > 1 ? 4.0 : 0.0;
  double chunks = 0.0, perChunk = 0.0;
  if (spec.tile_width > 0 && spec.tile_height > 0) {
    chunks = std::ceil(w / spec.tile_width) * std::ceil(h / spec.tile_height);
    perChunk = 8.0 + partNumber + 20.0;  // tile x, y, level x, y, data size
  } else {
    chunks = std::ceil(h / LinesPerChunk(compression));
    perChunk = 8.0 + partNumber + 8.0;  // y, data size
  }
  double raw = 0.0;
  for (int c = 0; c < spec.nchannels; ++c) raw += double(spec.channelformat(c).size());
  raw *= w * h;
  const bool compressed = !(compression.empty() || compression == "none");
  return chunks * perChunk + (compressed ? raw / kMaxCompressionRatio : raw);
}

}  // namespace

Status ChannelSet::Add(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(Quote(path) + ": no such file");
  if (fs::is_directory(path, ec)) return Status::Error(Quote(path) + ": is a directory");
  // Identify the format by its magic number, whatever the extension.
  {
    auto exr = ImageInput::create("openexr");
    if (!exr) return Status::Error("OpenImageIO was built without OpenEXR support");
    if (!exr->valid_file(path)) return Status::Error(Quote(path) + ": not an OpenEXR file");
  }
  File f;
  f.path = path;
  f.in = ImageInput::create("openexr");
  ImageSpec spec;
  if (!f.in || !f.in->open(path, spec)) {
    std::string err = f.in ? f.in->geterror() : OIIO::geterror();
    return Status::Error(Quote(path) + ": corrupt or unreadable OpenEXR file: " + err);
  }
  for (int s = 0; f.in->seek_subimage(s, 0); ++s) {
    const ImageSpec& sp = f.in->spec();
    if (sp.deep) return Status::Error(Quote(path) + ": deep EXR images are not supported");
    DCM_RETURN_IF_ERROR(CheckDimensions(path, sp.full_width, sp.full_height));
    DCM_RETURN_IF_ERROR(CheckDimensions(path, sp.width, sp.height));
    if (s > 0 && (sp.x != f.specs[0].x || sp.y != f.specs[0].y || sp.width != f.specs[0].width ||
                  sp.height != f.specs[0].height))
      return Status::Error(Quote(path) + ": its parts have different data windows");
    f.specs.push_back(sp);
  }
  (void)f.in->geterror();
  if (f.specs.empty()) return Status::Error(Quote(path) + ": no image in the file");
  // A header may declare any size; the file must hold the chunks of it.
  {
    double least = 0.0;
    for (const ImageSpec& sp : f.specs) least += LeastPartBytes(sp, int(f.specs.size()));
    const auto fileBytes = fs::file_size(path, ec);
    if (!ec && least > double(fileBytes))
      return Status::Error(Quote(path) + ": declares " + std::to_string(f.specs[0].width) + "x" +
                           std::to_string(f.specs[0].height) + " pixels, whose chunks need at least " +
                           ByteText(least) + ", but the file holds " + ByteText(double(fileBytes)) +
                           " (truncated or corrupt)");
  }
  const ImageSpec& sp = f.specs[0];
  const ImageWindows w{{{sp.x, sp.y}, {sp.x + sp.width, sp.y + sp.height}},
                       {{sp.full_x, sp.full_y}, {sp.full_x + sp.full_width, sp.full_y + sp.full_height}}};
  if (!files_.empty() && !(w == windows_))
    return Status::Error("inputs of different resolutions or data windows: " + Quote(path) + " is " + w.Text() +
                         ", " + Quote(files_[0].path) + " is " + windows_.Text());
  windows_ = w;
  const int fileIndex = int(files_.size());
  for (int s = 0; s < int(f.specs.size()); ++s) {
    const ImageSpec& part = f.specs[size_t(s)];
    for (int c = 0; c < part.nchannels; ++c)
      channels_.emplace(part.channel_name(c), ChannelRef{fileIndex, s, c, part.channelformat(c)});
  }
  files_.push_back(std::move(f));
  ScanCrypto(fileIndex);
  return Status::Ok();
}

std::string ImageWindows::Text() const {
  auto text = [](const Bounds2i& b) {
    return std::to_string(b.width()) + "x" + std::to_string(b.height()) + " at " + std::to_string(b.min.x) + "," +
           std::to_string(b.min.y);
  };
  return cropped() ? "data window " + text(data) + " of display window " + text(display)
                   : std::to_string(data.width()) + "x" + std::to_string(data.height());
}

std::string ImageWindows::PixelText(size_t i) const {
  const size_t w = size_t(std::max(1, data.width()));
  return "(" + std::to_string(int(i % w) + data.min.x) + ", " + std::to_string(int(i / w) + data.min.y) + ")";
}

void ChannelSet::ScanCrypto(int file) {
  const File& f = files_[size_t(file)];
  for (const ImageSpec& sp : f.specs) {
    for (const auto& attr : sp.extra_attribs) {
      const std::string key = attr.name().string();
      if (!OIIO::Strutil::starts_with(key, "cryptomatte/") || !OIIO::Strutil::ends_with(key, "/name"))
        continue;
      const std::string prefix = key.substr(0, key.size() - 4);  // "cryptomatte/<id>/"
      CryptoLayer layer;
      layer.name = sp.get_string_attribute(key);
      if (layer.name.empty()) continue;
      bool dup = false;
      for (const auto& l : crypto_) dup |= (l.name == layer.name);
      if (dup) continue;
      for (const char* suffix : {"00.R", "00.r", "00.red"}) {
        auto ref = Find(layer.name + suffix);
        if (ref) {
          layer.channel = layer.name + suffix;
          layer.ref = *ref;
          break;
        }
      }
      if (layer.channel.empty()) continue;  // metadata without channels: not usable
      for (int rank = 0; rank < 100; ++rank) {
        const std::string rankPrefix = layer.name + (rank < 10 ? "0" : "") + std::to_string(rank) + ".";
        bool found = false;
        for (const auto& [even, odd] : {std::pair("G", "A"), std::pair("g", "a"), std::pair("green", "alpha")})
          if (Has(rankPrefix + even) && Has(rankPrefix + odd)) {
            layer.coverage.push_back(rankPrefix + even);
            layer.coverage.push_back(rankPrefix + odd);
            found = true;
            break;
          }
        if (!found) break;
      }
      const std::string manifest = sp.get_string_attribute(prefix + "manifest");
      if (!manifest.empty()) {
        auto j = nlohmann::json::parse(manifest, nullptr, /*allow_exceptions=*/false);
        if (j.is_object()) {
          for (const auto& [name, hex] : j.items()) {
            if (!hex.is_string()) continue;
            try {
              layer.manifest[name] = uint32_t(std::stoul(hex.get<std::string>(), nullptr, 16));
            } catch (const std::exception&) {
            }
          }
        }
      }
      crypto_.push_back(std::move(layer));
    }
  }
}

std::optional<ChannelRef> ChannelSet::Find(const std::string& name) const {
  auto it = channels_.find(name);
  if (it == channels_.end()) return std::nullopt;
  return it->second;
}

std::vector<std::string> ChannelSet::Names() const {
  std::vector<std::string> names;
  for (const auto& [name, ref] : channels_) names.push_back(name);
  return names;
}

std::string ChannelSet::Describe() const {
  std::string s;
  size_t shown = 0;
  for (size_t fi = 0; fi < files_.size(); ++fi) {
    s += (fi ? "; " : "") + Quote(files_[fi].path) + ":";
    bool first = true;
    for (const auto& [name, ref] : channels_) {
      if (ref.file != int(fi)) continue;
      if (++shown > 100) {
        s += " ...";
        return s;
      }
      s += (first ? " " : ", ") + name;
      first = false;
    }
    if (first) s += " (no channels)";
  }
  return s;
}

const std::string& ChannelSet::Path(int file) const { return files_[size_t(file)].path; }

std::string ChannelSet::Paths() const {
  std::string s;
  for (const auto& f : files_) s += (s.empty() ? "" : ", ") + Quote(f.path);
  return s;
}

void ChannelSet::Want(const std::vector<std::string>& names) {
  for (const auto& name : names) {
    const auto ref = Find(name);
    if (!ref) continue;
    auto& wanted = wanted_[{ref->file, ref->subimage}];
    wanted.resize(size_t(files_[size_t(ref->file)].specs[size_t(ref->subimage)].nchannels), 0);
    wanted[size_t(ref->index)] = 1;
  }
}

std::vector<std::vector<float>>& ChannelSet::OnePass(int file, int subimage) const {
  Pass& p = passes_[{file, subimage}];
  if (p.tried) return p.planes;
  p.tried = true;
  const File& f = files_[size_t(file)];
  const ImageSpec& sp = f.specs[size_t(subimage)];
  const size_t n = pixels();
  // The channels to keep: the wanted ones, or all of them when none were
  // named and they fit the budget.
  std::vector<uint8_t> keep(size_t(sp.nchannels), 1);
  if (!wanted_.empty()) {
    const auto it = wanted_.find({file, subimage});
    if (it == wanted_.end()) return p.planes;
    keep = it->second;
  } else if (int64_t(sp.nchannels) * int64_t(n) * 4 > kOnePassBytes) {
    return p.planes;
  }
  int lo = sp.nchannels, hi = -1, kept = 0;
  for (int c = 0; c < sp.nchannels; ++c)
    if (keep[size_t(c)]) lo = std::min(lo, c), hi = c, ++kept;
  if (sp.tile_width != 0 || kept < 2) return p.planes;  // tiled, or nothing to share
  const int range = hi - lo + 1;
  std::vector<std::vector<float>> planes(size_t(sp.nchannels));
  for (int c = lo; c <= hi; ++c)
    if (keep[size_t(c)]) planes[size_t(c)].assign(n, 0.f);
  // Rows per read: about 8 MiB of float, a multiple of 32 scanlines (the
  // largest EXR scanline block).
  const size_t rowBytes = size_t(sp.width) * size_t(range) * 4;
  const int rows = std::max(32, int((size_t(8) << 20) / std::max<size_t>(1, rowBytes)) / 32 * 32);
  std::vector<float> buffer(size_t(std::min(rows, sp.height)) * size_t(sp.width) * size_t(range));
  for (int y = 0; y < sp.height; y += rows) {
    const int end = std::min(sp.height, y + rows);
    if (!f.in->read_scanlines(subimage, 0, sp.y + y, sp.y + end, 0, lo, hi + 1, TypeDesc::FLOAT, buffer.data())) {
      (void)f.in->geterror();
      return p.planes;  // empty: the per-channel reads say what is wrong
    }
    const size_t first = size_t(y) * size_t(sp.width), count = size_t(end - y) * size_t(sp.width);
    for (int c = lo; c <= hi; ++c) {
      if (!keep[size_t(c)]) continue;
      float* out = planes[size_t(c)].data() + first;
      for (size_t i = 0; i < count; ++i) out[i] = buffer[i * size_t(range) + size_t(c - lo)];
    }
  }
  p.planes = std::move(planes);
  return p.planes;
}

Status ChannelSet::ReadRef(const ChannelRef& ref, const std::string& name, TypeDesc type,
                           void* data) const {
  if (type == TypeDesc::FLOAT) {
    const auto& planes = OnePass(ref.file, ref.subimage);
    if (!planes.empty() && !planes[size_t(ref.index)].empty()) {
      std::memcpy(data, planes[size_t(ref.index)].data(), pixels() * sizeof(float));
      return Status::Ok();
    }
  }
  const File& f = files_[size_t(ref.file)];
  if (!f.in->read_image(ref.subimage, 0, ref.index, ref.index + 1, type, data))
    return Status::Error(Quote(f.path) + ": cannot read channel " + Quote(name) +
                         " (truncated or corrupt file?): " + f.in->geterror());
  return Status::Ok();
}

Status ChannelSet::ReadRaw(const std::string& name, TypeDesc type, void* data) const {
  auto ref = Find(name);
  if (!ref) return Status::Error("no channel " + Quote(name) + " in " + Describe());
  return ReadRef(*ref, name, type, data);
}

Status ChannelSet::ReadFloat(const std::string& name, std::vector<float>* plane) const {
  // A plane of the one-pass read is handed over, not copied (a second read
  // of the channel reads it from the file again).
  if (auto ref = Find(name)) {
    auto& planes = OnePass(ref->file, ref->subimage);
    if (size_t(ref->index) < planes.size() && !planes[size_t(ref->index)].empty()) {
      plane->swap(planes[size_t(ref->index)]);
      std::vector<float>().swap(planes[size_t(ref->index)]);
      return Status::Ok();
    }
  }
  plane->assign(pixels(), 0.f);
  return ReadRaw(name, TypeDesc::FLOAT, plane->data());
}

Status ChannelSet::ReadId(const std::string& name, std::vector<uint32_t>* plane) const {
  auto ref = Find(name);
  if (!ref) return Status::Error("no channel " + Quote(name) + " in " + Describe());
  plane->assign(pixels(), 0u);
  const TypeDesc::BASETYPE base = TypeDesc::BASETYPE(ref->format.basetype);
  if (base == TypeDesc::UINT32 || base == TypeDesc::INT32 || base == TypeDesc::UINT16 ||
      base == TypeDesc::INT16 || base == TypeDesc::UINT8 || base == TypeDesc::INT8) {
    // Integer storage: read as integers (a float buffer would normalise them).
    return ReadRef(*ref, name, TypeDesc::UINT32, plane->data());
  }
  std::vector<float> f(pixels());
  DCM_RETURN_IF_ERROR(ReadRef(*ref, name, TypeDesc::FLOAT, f.data()));
  for (size_t i = 0; i < f.size(); ++i) {
    const float v = f[i];
    // Integers exactly representable in float32 span +-2^24; larger integral
    // values are accepted as stored (they are still integers).
    if (!std::isfinite(v) || v != std::floor(v) || v < -2147483648.f || v >= 4294967296.f) {
      return Status::Error(Quote(Path(ref->file)) + ": channel " + Quote(name) + " holds a non-integer ID " +
                           std::to_string(v) + " at pixel " + windows_.PixelText(i) + "; IDs must be integers");
    }
    (*plane)[i] = v < 0 ? uint32_t(int32_t(v)) : uint32_t(v);
  }
  return Status::Ok();
}

Status ChannelSet::ReadCrypto(const CryptoLayer& layer, std::vector<uint32_t>* plane) const {
  if (layer.ref.format.basetype != TypeDesc::FLOAT)
    return Status::Error(Quote(Path(layer.ref.file)) + ": Cryptomatte channel " +
                         Quote(layer.channel) + " is stored as " + layer.ref.format.c_str() +
                         "; its IDs need 32-bit float");
  std::vector<float> f(pixels());
  DCM_RETURN_IF_ERROR(ReadRef(layer.ref, layer.channel, TypeDesc::FLOAT, f.data()));
  plane->resize(pixels());
  static_assert(sizeof(float) == sizeof(uint32_t));
  std::memcpy(plane->data(), f.data(), f.size() * sizeof(float));
  if (layer.coverage.empty()) return Status::Ok();
  // Rank 0 holds the largest coverage; the rest of the footprint, 1 - sum,
  // saw nothing. Where that is more than rank 0's share, the pixel is
  // background.
  std::vector<float> rank0, sum(pixels(), 0.f), c;
  for (size_t k = 0; k < layer.coverage.size(); ++k) {
    DCM_RETURN_IF_ERROR(ReadFloat(layer.coverage[k], &c));
    for (size_t i = 0; i < c.size(); ++i) sum[i] += std::isfinite(c[i]) ? c[i] : 0.f;
    if (k == 0) rank0 = c;
  }
  for (size_t i = 0; i < sum.size(); ++i)
    if (1.f - sum[i] > rank0[i]) (*plane)[i] = 0u;
  return Status::Ok();
}

Status ChannelSet::FindCrypto(const std::string& name, const CryptoLayer** layer) const {
  const CryptoLayer* found = nullptr;
  for (const auto& l : crypto_) {
    if (l.name == name) {
      *layer = &l;
      return Status::Ok();
    }
  }
  for (const auto& l : crypto_) {
    if (OIIO::Strutil::ends_with(l.name, name)) {
      if (found)
        return Status::Error("Cryptomatte layer " + Quote(name) + " is ambiguous in " + Paths() +
                             ": " + Quote(found->name) + " and " + Quote(l.name));
      found = &l;
    }
  }
  if (!found) {
    std::string names;
    for (const auto& l : crypto_) names += (names.empty() ? "" : ", ") + Quote(l.name);
    return Status::Error("no Cryptomatte layer " + Quote(name) + " in " + Paths() +
                         (names.empty() ? " (none found)" : " (layers: " + names + ")"));
  }
  *layer = found;
  return Status::Ok();
}

}  // namespace dcm::aov::detail

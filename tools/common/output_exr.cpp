// Output EXRs of named channels of mixed stored types, as oiiotool stores them.
#include "output_exr.h"

#include <OpenImageIO/half.h>

#include <algorithm>
#include <cstring>

namespace dcm::toolkit {
namespace {

using OIIO::TypeDesc;

std::string Join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

/// The stored type of `c` under -d.
TypeDesc StoredType(const OutputChannel& c, const std::string& dataType) {
  if (c.raw || c.type == TypeDesc::UINT || dataType.empty()) return c.type;
  return dataType == "half" ? TypeDesc::HALF : TypeDesc::FLOAT;
}

}  // namespace

Status CheckExrFormat(const ExrFormat& format) {
  if (!format.dataType.empty() && format.dataType != "half" && format.dataType != "float")
    return Status::Error("-d " + format.dataType + ": the output type is half or float");
  const auto& c = kExrCompressions;
  if (std::find(std::begin(c), std::end(c), format.compression) == std::end(c)) {
    std::string names;
    for (const char* n : c) names += (names.empty() ? "" : ", ") + std::string(n);
    return Status::Error("--compression " + format.compression + ": not an OpenEXR compression (" + names + ")");
  }
  return Status::Ok();
}

bool IsStructuralAttribute(const std::string& name) {
  static const char* const kNames[] = {"compression", "planarconfig", "chunkCount", "lineOrder", "tiles",
                                       "channels",    "dataWindow",   "displayWindow", "version", "type"};
  for (const char* n : kNames)
    if (name == n) return true;
  return StartsWith(name, "oiio:") || StartsWith(name, "openexr:") || StartsWith(name, "dcm:");
}

Status SelectChannels(const std::vector<std::string>& available, const std::vector<std::string>& wanted,
                      std::vector<size_t>* order) {
  order->clear();
  if (wanted.empty()) {
    for (size_t i = 0; i < available.size(); ++i) order->push_back(i);
    return Status::Ok();
  }
  for (const auto& name : wanted) {
    const auto it = std::find(available.begin(), available.end(), name);
    if (it == available.end())
      return Status::Error("--ch " + name + ": the output has no such channel (channels: " + Join(available) + ")");
    const size_t i = size_t(it - available.begin());
    if (std::find(order->begin(), order->end(), i) != order->end())
      return Status::Error("--ch " + name + ": named twice");
    order->push_back(i);
  }
  return Status::Ok();
}

Status WriteOutputExr(const std::string& path, const OutputImage& image, const ExrFormat& format) {
  DCM_RETURN_IF_ERROR(CheckExrFormat(format));
  if (image.display.empty() || image.data.empty())
    return Status::Error("cannot write '" + path + "': empty display or data window");
  std::vector<std::string> names;
  for (const auto& c : image.channels) names.push_back(c.name);
  std::vector<size_t> order;
  DCM_RETURN_IF_ERROR(SelectChannels(names, format.channels, &order));
  if (order.empty()) return Status::Error("cannot write '" + path + "': no channels");
  const size_t n = size_t(image.data.area());

  OIIO::ImageSpec spec = WindowedSpec(image.display, image.data, int(order.size()));
  spec.channelnames.clear();
  spec.channelformats.clear();
  std::vector<size_t> offset;  // of each channel in a pixel (native layout)
  size_t pixelBytes = 0;
  for (size_t k = 0; k < order.size(); ++k) {
    const OutputChannel& c = image.channels[order[k]];
    const size_t have = c.type == TypeDesc::UINT ? c.ids.size() : c.values.size();
    if (have != n)
      return Status::Error("cannot write '" + path + "': channel '" + c.name + "' has " + std::to_string(have) +
                           " pixels, the data window " + std::to_string(n));
    const TypeDesc t = StoredType(c, format.dataType);
    spec.channelnames.push_back(c.name);
    spec.channelformats.push_back(t);
    offset.push_back(pixelBytes);
    pixelBytes += t.size();
    if (c.name == "A" || (c.name.size() > 2 && c.name.compare(c.name.size() - 2, 2, ".A") == 0))
      if (spec.alpha_channel < 0) spec.alpha_channel = int(k);
  }
  // One type for all: the spec's format; mixed: per channel.
  const bool mixed = std::any_of(spec.channelformats.begin(), spec.channelformats.end(),
                                 [&](TypeDesc t) { return t != spec.channelformats[0]; });
  const std::vector<TypeDesc> formats = spec.channelformats;
  spec.set_format(formats[0]);  // clears channelformats
  if (mixed) spec.channelformats = formats;

  for (const auto& attr : image.attributes) spec.extra_attribs.add_or_replace(attr);
  spec.attribute("compression", format.compression);

  std::vector<std::byte> buffer(n * pixelBytes);
  for (size_t k = 0; k < order.size(); ++k) {
    const OutputChannel& c = image.channels[order[k]];
    const TypeDesc t = mixed ? spec.channelformats[k] : spec.format;
    std::byte* dst = buffer.data() + offset[k];
    for (size_t i = 0; i < n; ++i, dst += pixelBytes) {
      if (t == TypeDesc::UINT) {
        std::memcpy(dst, &c.ids[i], 4);
      } else if (t == TypeDesc::HALF) {
        const half h(c.values[i]);
        std::memcpy(dst, &h, 2);
      } else {
        std::memcpy(dst, &c.values[i], 4);
      }
    }
  }
  // TypeUnknown: the buffer holds each channel in its stored type.
  return WriteImage(path, spec, buffer.data(), TypeDesc::UNKNOWN);
}

void AddMetadata(const Metadata& metadata, OIIO::ParamValueList* attributes) {
  for (const auto& [name, value] : metadata.strings) attributes->attribute(name, value);
  for (const auto& [name, value] : metadata.floats) attributes->attribute(name, value);
}

Status WriteRgbExr(const std::string& path, const Bounds2i& display, const Bounds2i& data,
                   std::span<const RGB> pixels, const Metadata& metadata, bool alpha, const ExrFormat& format) {
  if (pixels.size() != size_t(std::max<int64_t>(data.area(), 0)))
    return Status::Error("cannot write '" + path + "': " + std::to_string(pixels.size()) + " pixels given for a " +
                         std::to_string(data.width()) + "x" + std::to_string(data.height()) + " image");
  OutputImage image;
  image.display = display;
  image.data = data;
  for (int c = 0; c < (alpha ? 4 : 3); ++c) {
    OutputChannel ch;
    ch.name = std::string(1, "RGBA"[c]);
    ch.values.resize(pixels.size(), 1.f);
    if (c < 3)
      for (size_t i = 0; i < pixels.size(); ++i) ch.values[i] = pixels[i][c];
    image.channels.push_back(std::move(ch));
  }
  AddMetadata(metadata, &image.attributes);
  return WriteOutputExr(path, image, format);
}

namespace {
std::string& CommandLineText() {
  static std::string text;
  return text;
}
}  // namespace

void SetCommandLine(int argc, const char* const* argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    const bool plain = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                          "0123456789-_=./,:+@%#") == std::string::npos;
    std::string quoted = "'";
    for (char ch : a) quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    quoted += "'";
    s += (i ? " " : "") + (plain ? a : quoted);
  }
  CommandLineText() = s;
}

const std::string& CommandLine() { return CommandLineText(); }

}  // namespace dcm::toolkit

// Image files in and out through OpenImageIO, every output written atomically.
#include "image_io.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <system_error>

#include "dcm/memory_budget.h"
#include "output_exr.h"

namespace dcm::toolkit {
namespace {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

Status CheckSize(const std::string& path, int width, int height, size_t count) {
  if (width <= 0 || height <= 0)
    return Status::Error("cannot write '" + path + "': empty image (" + std::to_string(width) + "x" +
                         std::to_string(height) + ")");
  if (count != size_t(width) * size_t(height))
    return Status::Error("cannot write '" + path + "': " + std::to_string(count) +
                         " pixels given for a " + std::to_string(width) + "x" +
                         std::to_string(height) + " image");
  return Status::Ok();
}

}  // namespace

ImageSpec WindowedSpec(const Bounds2i& display, const Bounds2i& data, int channels) {
  ImageSpec spec(data.width(), data.height(), channels, TypeDesc::FLOAT);
  spec.x = data.min.x;
  spec.y = data.min.y;
  spec.full_x = display.min.x;
  spec.full_y = display.min.y;
  spec.full_width = display.width();
  spec.full_height = display.height();
  return spec;
}

Status WriteImage(const std::string& path, const ImageSpec& spec, const void* pixels, TypeDesc format) {
  return WriteAtomically(path, [&](const std::string& tmp) -> Status {
    auto out = ImageOutput::create(tmp);
    if (!out) return Status::Error("cannot write '" + path + "': " + OIIO::geterror());
    if (!out->open(tmp, spec)) return Status::Error("cannot write '" + path + "': " + out->geterror());
    bool ok = out->write_image(format, pixels);
    std::string err = ok ? "" : out->geterror();
    if (!out->close() && ok) {
      ok = false;
      err = out->geterror();
    }
    if (!ok) return Status::Error("cannot write '" + path + "': " + err);
    return Status::Ok();
  });
}

Status WriteRgbExr(const std::string& path, int width, int height, std::span<const RGB> pixels,
                   const Metadata& metadata) {
  return WriteRgbExr(path, width, height, pixels, metadata, /*alpha=*/false);
}

Status WriteRgbExr(const std::string& path, int width, int height, std::span<const RGB> pixels,
                   const Metadata& metadata, bool alpha) {
  const Bounds2i frame{{0, 0}, {width, height}};
  return WriteRgbExr(path, frame, frame, pixels, metadata, alpha);
}

Status WriteRgbExr(const std::string& path, const Bounds2i& display, const Bounds2i& data,
                   std::span<const RGB> pixels, const Metadata& metadata, bool alpha) {
  DCM_RETURN_IF_ERROR(CheckSize(path, data.width(), data.height(), pixels.size()));
  return WriteRgbExr(path, display, data, pixels, metadata, alpha, ExrFormat{});
}

Status WriteRgb8(const std::string& path, int width, int height, std::span<const uint8_t> rgb) {
  if (rgb.size() % 3 != 0)
    return Status::Error("cannot write '" + path + "': RGB data size is not a multiple of 3");
  DCM_RETURN_IF_ERROR(CheckSize(path, width, height, rgb.size() / 3));
  ImageSpec spec(width, height, 3, TypeDesc::UINT8);
  return WriteImage(path, spec, rgb.data(), TypeDesc::UINT8);
}

Status CheckImageDimensions(const std::string& path, int width, int height, int channels) {
  const int64_t kMaxSide = int64_t(1) << 17;  // 131072 pixels per side
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide)
    return Status::Error("'" + path + "': absurd image dimensions " + std::to_string(width) + "x" +
                         std::to_string(height) + " (at most " + std::to_string(kMaxSide) +
                         " pixels per side)");
  const double bytes = double(width) * double(height) * double(std::max(channels, 1)) * 4.0;
  const int64_t budget = MemoryBudget();
  if (bytes > double(budget))
    return Status::Error("'" + path + "': " + std::to_string(width) + "x" + std::to_string(height) +
                         " with " + std::to_string(channels) + " channels needs " +
                         std::to_string(int64_t(bytes / double(1 << 20))) +
                         " MiB, more than the limit of " +
                         std::to_string(budget >> 20) + " MiB (DCM_MEMORY_LIMIT)");
  return Status::Ok();
}

Status ReadRgb(const std::string& path, int* width, int* height, std::vector<RGB>* pixels) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error("'" + path + "': no such file");
  auto in = ImageInput::open(path);
  if (!in) return Status::Error("cannot read '" + path + "': " + OIIO::geterror());
  const ImageSpec spec = in->spec();
  if (spec.deep) return Status::Error("'" + path + "': deep images are not supported");
  if (spec.depth > 1) return Status::Error("'" + path + "': volume images are not supported");
  DCM_RETURN_IF_ERROR(CheckImageDimensions(path, spec.width, spec.height, 3));
  int idx[3] = {spec.channelindex("R"), spec.channelindex("G"), spec.channelindex("B")};
  if (idx[0] < 0 || idx[1] < 0 || idx[2] < 0) {
    // Blender's multilayer EXR: the one layer <view layer>.Combined.
    std::vector<std::string> combined;
    for (const auto& n : spec.channelnames) {
      const std::string suffix = ".Combined.R";
      if (n.size() > suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0) {
        const std::string layer = n.substr(0, n.size() - 1);
        if (spec.channelindex(layer + "G") >= 0 && spec.channelindex(layer + "B") >= 0) combined.push_back(layer);
      }
    }
    if (combined.size() == 1)
      for (int c = 0; c < 3; ++c) idx[c] = spec.channelindex(combined[0] + "RGB"[c]);
  }
  if (idx[0] < 0 || idx[1] < 0 || idx[2] < 0) {
    if (spec.nchannels == 1) {
      idx[0] = idx[1] = idx[2] = 0;
    } else {
      std::string names;
      for (const auto& n : spec.channelnames) names += (names.empty() ? "" : ", ") + n;
      return Status::Error("'" + path + "': no R, G, B channels (channels: " + names + ")");
    }
  }
  const size_t n = size_t(spec.width) * size_t(spec.height);
  std::vector<float> plane(n);
  pixels->assign(n, RGB{});
  for (int c = 0; c < 3; ++c) {
    if (c > 0 && idx[c] == idx[c - 1]) {
      for (size_t i = 0; i < n; ++i) (*pixels)[i][c] = (*pixels)[i][c - 1];
      continue;
    }
    if (!in->read_image(0, 0, idx[c], idx[c] + 1, TypeDesc::FLOAT, plane.data()))
      return Status::Error("cannot read channel '" + spec.channelnames[size_t(idx[c])] + "' of '" +
                           path + "': " + in->geterror());
    for (size_t i = 0; i < n; ++i) (*pixels)[i][c] = plane[i];
  }
  *width = spec.width;
  *height = spec.height;
  return Status::Ok();
}

}  // namespace dcm::toolkit

#include "dcm/embree/textures.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>
#include <OpenImageIO/ustring.h>

#include <cmath>
#include <filesystem>

#include "dcm/memory_budget.h"
#include "dcm/embree/sampling.h"

namespace dcm::embree {
namespace {

Vec2 Apply(const TextureDesc& d, Vec2 uv) { return {uv.x * d.scale.x + d.offset.x, uv.y * d.scale.y + d.offset.y}; }

RGB Lerp(RGB a, RGB b, float t) { return a * (1.f - t) + b * t; }

/// A checkerboard of unit squares, box-filtered over the footprint in closed
/// form (the integral of the square wave; pbrt's "closed-form" checkerboard).
class CheckerTexture final : public Texture {
 public:
  explicit CheckerTexture(const TextureDesc& d) : d_(d) {}
  RGB Eval(const TexCoord& tc) const override {
    Vec2 p = Apply(d_, tc.uv);
    float du = 0.5f * std::max(std::abs(tc.duvdx.x * d_.scale.x), std::abs(tc.duvdy.x * d_.scale.x));
    float dv = 0.5f * std::max(std::abs(tc.duvdx.y * d_.scale.y), std::abs(tc.duvdy.y * d_.scale.y));
    if (du < 1e-5f && dv < 1e-5f) {
      bool odd = (int64_t(std::floor(p.x)) + int64_t(std::floor(p.y))) & 1;
      return odd ? d_.color1 : d_.color0;
    }
    if (du >= 1.f || dv >= 1.f) return Lerp(d_.color0, d_.color1, 0.5f);
    // Integral of the unit-period square wave that is 1 on [1, 2) mod 2.
    auto bumpInt = [](float x) {
      float h = std::floor(x / 2.f);
      return h + 2.f * std::max(x / 2.f - h - 0.5f, 0.f);
    };
    auto avg = [&](float c, float w) {
      if (w < 1e-5f) return float(int64_t(std::floor(c)) & 1);
      return (bumpInt(c + w) - bumpInt(c - w)) / (2.f * w);
    };
    float s = avg(p.x, du), t = avg(p.y, dv);
    float odd = s + t - 2.f * s * t;  // fraction of the area where exactly one is odd
    return Lerp(d_.color0, d_.color1, odd);
  }

 private:
  TextureDesc d_;
};

/// Parquet in basket weave (see TextureDesc). Point sampled: its detail is
/// antialiased by the supersampling of the working image.
class PlanksTexture final : public Texture {
 public:
  explicit PlanksTexture(const TextureDesc& d)
      : d_(d), perTile_(std::max(1, int(std::lround(d.plankLength / d.plankWidth)))) {}
  RGB Eval(const TexCoord& tc) const override {
    Vec2 p = Apply(d_, tc.uv);
    const float L = d_.plankLength;
    float fi = std::floor(p.x / L), fj = std::floor(p.y / L);
    float a = p.x / L - fi, b = p.y / L - fj;  // position in the tile, [0,1)^2
    int64_t i = int64_t(fi), j = int64_t(fj);
    bool alongU = ((i + j) & 1) == 0;
    float across = alongU ? b : a;  // across the planks
    float along = alongU ? a : b;   // along the planks
    float k = std::floor(across * float(perTile_));
    float c = across * float(perTile_) - k;  // across one plank, [0,1)
    float plankW = L / float(perTile_);
    float half = 0.5f * d_.gap;
    if (std::min(c, 1.f - c) * plankW < half || std::min(along, 1.f - along) * L < half) return d_.gapColor;
    uint32_t h = HashU32(uint32_t(i) * 73856093u ^ uint32_t(j) * 19349663u ^ uint32_t(int(k)) * 83492791u);
    float tone = float(h & 0xffffu) / 65535.f;
    float phase = float((h >> 16) & 0xffffu) / 65535.f * 2.f * kPi;
    RGB base = Lerp(d_.wood0, d_.wood1, tone);
    // Grain: stripes along the plank that wobble slowly along it.
    float wobble = 0.35f * std::sin(along * L / plankW * 1.7f + phase) + 0.15f * std::sin(along * 23.f + 2.f * phase);
    float stripe = 0.5f + 0.5f * std::sin(2.f * kPi * (c * 5.f + wobble) + phase);
    float grain = 1.f - d_.grain * stripe * stripe * stripe;
    return base * grain;
  }

 private:
  TextureDesc d_;
  int perTile_;
};

float SrgbToLinear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

/// An image through the TextureSystem: trilinear mip-mapping over the pixel's
/// footprint (anisotropic where the derivatives are), periodic wrap.
class ImageTexture final : public Texture {
 public:
  ImageTexture(const TextureDesc& d, OIIO::TextureSystem* ts, int channels, bool srgb)
      : d_(d), ts_(ts), name_(d.file), channels_(channels), srgb_(srgb) {
    handle_ = ts_->get_texture_handle(name_);
  }
  RGB Eval(const TexCoord& tc) const override {
    OIIO::TextureOpt opt;
    opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
    Vec2 p = Apply(d_, tc.uv);
    // Images have t = 0 at the top row; texture coordinates have v = 0 at the bottom.
    float s = p.x, t = 1.f - p.y;
    float dsdx = tc.duvdx.x * d_.scale.x, dtdx = -tc.duvdx.y * d_.scale.y;
    float dsdy = tc.duvdy.x * d_.scale.x, dtdy = -tc.duvdy.y * d_.scale.y;
    float result[4] = {0.f, 0.f, 0.f, 0.f};
    int n = std::min(channels_, 3);
    if (!ts_->texture(handle_, nullptr, opt, s, t, dsdx, dtdx, dsdy, dtdy, n, result)) {
      return RGB::Gray(1.f);  // cannot happen for a file opened at creation
    }
    RGB c = n >= 3 ? RGB{result[0], result[1], result[2]} : RGB::Gray(result[0]);
    if (srgb_) c = {SrgbToLinear(c.r), SrgbToLinear(c.g), SrgbToLinear(c.b)};
    return c;
  }

 private:
  TextureDesc d_;
  OIIO::TextureSystem* ts_;
  OIIO::ustring name_;
  OIIO::TextureSystem::TextureHandle* handle_ = nullptr;
  int channels_;
  bool srgb_;
};

}  // namespace

Status CheckDeclaredTextureSize(const std::string& path, const std::string& what) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    (void)OIIO::geterror();
    return Status::Ok();  // the texture system's own message follows
  }
  const OIIO::ImageSpec& spec = in->spec();
  // An empty image (a TGA may declare 0 columns) divides by zero in OpenImageIO 2.4's texture lookups.
  if (spec.width <= 0 || spec.height <= 0 || spec.depth <= 0 || spec.nchannels <= 0)
    return Status::Error(what + ": texture '" + path + "' declares an empty image (" + std::to_string(spec.width) +
                         "x" + std::to_string(spec.height) + " pixels, " + std::to_string(spec.nchannels) +
                         " channels)");
  std::error_code ec;
  const auto fileBytes = std::filesystem::file_size(path, ec);
  if (ec) return Status::Ok();
  const std::string format = in->format_name();
  const double pixels = double(spec.width) * double(spec.height) * double(std::max(spec.depth, 1));
  const int bits = spec.get_int_attribute("oiio:BitsPerSample", int(spec.format.size()) * 8);
  const double stored = pixels * double(spec.nchannels) * double(bits) / 8.0;
  // PNM stores its samples raw (binary, or longer as ASCII text); any other
  // format is taken as compressed, up to kMaxCompressionRatio (OpenImageIO
  // names neither a TGA's RLE nor a BMP's or TIFF's palette, whose samples
  // are expanded to RGB).
  const bool raw = format == "pnm";
  const double least = raw ? stored : stored / kMaxCompressionRatio;
  const std::string declared = what + ": texture '" + path + "' declares " + std::to_string(spec.width) + "x" +
                               std::to_string(spec.height) + " pixels of " + std::to_string(spec.nchannels) +
                               " channels";
  if (least > double(fileBytes))
    return Status::Error(declared + ", " + ByteText(stored) + " of samples" +
                         (raw ? " stored raw, but the file holds " : ", more than any compression packs into its ") +
                         ByteText(double(fileBytes)) + " (truncated or corrupt)");
  // The texture system keeps float samples and a MIP pyramid (4/3 of the image).
  return CheckMemoryBudget(declared + ", which", pixels * double(spec.nchannels) * 4.0 * 4.0 / 3.0);
}

struct TextureCache::Impl {
  OIIO::TextureSystem* ts = nullptr;
};

TextureCache::TextureCache() : impl_(std::make_unique<Impl>()) {}

TextureCache::~TextureCache() {
  if (impl_->ts) OIIO::TextureSystem::destroy(impl_->ts);
}

Status TextureCache::Create(const TextureDesc& d, const std::string& what, std::unique_ptr<Texture>* out) {
  switch (d.kind) {
    case TextureKind::kChecker: *out = std::make_unique<CheckerTexture>(d); return Status::Ok();
    case TextureKind::kPlanks: *out = std::make_unique<PlanksTexture>(d); return Status::Ok();
    case TextureKind::kImage: break;
  }
  // The texture system reads (and MIP-maps) the whole image at the first
  // lookup: check what the header declares first.
  DCM_RETURN_IF_ERROR(CheckDeclaredTextureSize(d.file, what));
  if (!impl_->ts) {
    impl_->ts = OIIO::TextureSystem::create(/*shared=*/false);
    impl_->ts->attribute("automip", 1);  // mip-map plain images on the fly
    impl_->ts->attribute("autotile", 64);
  }
  OIIO::ustring name(d.file);
  int channels = 0;
  if (!impl_->ts->get_texture_info(name, 0, OIIO::ustring("channels"), OIIO::TypeDesc::INT, &channels) ||
      channels < 1) {
    std::string err = impl_->ts->geterror();
    return Status::Error(what + ": cannot read texture '" + d.file + "'" + (err.empty() ? "" : ": " + err));
  }
  // 8-bit formats (PNG, JPEG) hold sRGB-encoded values; OIIO says so in oiio:ColorSpace.
  OIIO::ustring colorSpace;
  bool srgb = false;
  if (impl_->ts->get_texture_info(name, 0, OIIO::ustring("oiio:ColorSpace"), OIIO::TypeDesc::STRING, &colorSpace)) {
    std::string cs = colorSpace.string();
    srgb = cs == "sRGB" || cs == "srgb" || cs == "srgb_rec709_scene";
  }
  *out = std::make_unique<ImageTexture>(d, impl_->ts, channels, srgb);
  return Status::Ok();
}

}  // namespace dcm::embree

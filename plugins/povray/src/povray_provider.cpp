// The POV-Ray provider: guide passes in full, exact samples through the mesh
// camera of the pass convention (docs/POVRAY.md).
#include "dcm/povray/povray_provider.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dcm/pipe/pipe_provider.h"
#include "povray_process.h"
#include "dcm/pipe/scratch_folder.h"
#include "scratch_dir.h"

namespace dcm::povray {

namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string PassText(Pass pass) {
  return "pass " + std::to_string(int(pass)) + " (" + std::string(PassName(pass)) + ")";
}

PovrayJob DenseJob(Pass pass, int width, int height) {
  PovrayJob job;
  job.pass = int(pass);
  job.width = width;
  job.height = height;
  job.what = PassText(pass);
  return job;
}

/// The names a scene of the convention uses: a scene without one of them
/// renders its beauty for every pass, or a perspective image for a pixel list.
Status CheckConvention(const std::string& scene, const std::string& name) {
  std::ifstream in(scene, std::ios::binary);
  if (!in) return Status::Error("cannot read the scene " + name);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  for (const char* word : {"Pass", "Sparse", "PixX", "PixY", "NPix"}) {
    if (s.find(word) == std::string::npos)
      return Status::Error(name + " does not follow the pass convention of docs/POVRAY.md: it never mentions '" +
                           word + "' (the pass is chosen by Declare=Pass=N, the pixels by Declare=Sparse=1 and "
                           "the arrays NPix, PixX, PixY of pixels.inc)");
  }
  return Status::Ok();
}

/// An ID pass: the same integer in R, G and B of every pixel.
Status ToIds(const std::vector<RGB>& rgb, int width, const std::string& what, std::vector<uint32_t>* ids) {
  ids->resize(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    const RGB c = rgb[i];
    if (!(c.r >= 0 && c.r < 2048 && c.r == std::floor(c.r) && c.g == c.r && c.b == c.r)) {
      std::ostringstream s;
      s << what << " does not hold one integer per pixel (pixel " << i % size_t(width) << "," << i / size_t(width)
        << " is " << c.r << " " << c.g << " " << c.b
        << "): does the scene give every texture through Tex() of the pass convention (docs/POVRAY.md)?";
      return Status::Error(s.str());
    }
    (*ids)[i] = uint32_t(c.r);
  }
  return Status::Ok();
}

/// Writes `pixels` as the scene's Sparse mode reads them: folder/pixels.inc.
Status WritePixelList(const std::string& folder, std::span<const Point2i> pixels) {
  const std::string path = folder + "/" + ScratchPixelList();
  const size_t n = pixels.size();
  std::ofstream inc(path);
  inc << "#declare NPix = " << n << ";\n#declare PixX = array[" << n << "] {";
  for (size_t i = 0; i < n; ++i) inc << (i ? (i % 24 ? "," : ",\n") : "\n") << pixels[i].x;
  inc << "\n}\n#declare PixY = array[" << n << "] {";
  for (size_t i = 0; i < n; ++i) inc << (i ? (i % 24 ? "," : ",\n") : "\n") << pixels[i].y;
  inc << "\n}\n";
  inc.close();
  if (!inc) return Status::Error("cannot write the pixel list " + path);
  return Status::Ok();
}

/// Where face k of n is in the render of a list: output pixel
/// (k mod w, k div w + 1) of an image w = min(n, frame width) wide, since
/// POV-Ray 3.7 traces face row r - 1 for output row r.
size_t FaceOutput(size_t k, size_t n, int frameWidth) {
  const size_t w = std::min(n, size_t(frameWidth));
  return (k / w + 1) * w + k % w;
}

}  // namespace

std::string_view PassName(Pass pass) {
  switch (pass) {
    case Pass::kBeauty: return "beauty";
    case Pass::kObjectId: return "object ID";
    case Pass::kShaderId: return "shader ID";
    case Pass::kTexture: return "texture";
    case Pass::kIllumination: return "illumination";
    case Pass::kNormal: return "normal";
    case Pass::kHighlight: return "highlight mask";
  }
  return "unknown";
}

Status PovrayProvider::Open(const PovrayOptions& options, std::unique_ptr<PovrayProvider>* out) {
  if (options.width < 1 || options.height < 1) return Status::Error("the frame size must be at least 1x1");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(options.scene, ec))
    return Status::Error("the scene " + options.scene + " is not a file" + (ec ? ": " + ec.message() : ""));
  DCM_RETURN_IF_ERROR(CheckConvention(options.scene, options.scene));
  std::unique_ptr<PovrayProvider> p(new PovrayProvider(options));
  p->options_.scene = std::filesystem::absolute(options.scene, ec).string();
  DCM_RETURN_IF_ERROR(FindExecutable(options.povray, &p->povrayPath_));
  std::unique_ptr<pipe::ScratchFolder> scratch;
  DCM_RETURN_IF_ERROR(pipe::ScratchFolder::Make("dcm-povray", &scratch));
  p->scratch_ = scratch->path();
  p->scratchFolder_ = std::move(scratch);
  DCM_RETURN_IF_ERROR(WriteSceneIni(p->scratch_, p->options_.scene));
  *out = std::move(p);
  return Status::Ok();
}

PovrayProvider::~PovrayProvider() = default;

void SignalCleanup() { pipe::KillAllChildren(); }

PovrayEnv PovrayProvider::Env() const {
  return PovrayEnv{povrayPath_, options_.scene, std::filesystem::path(options_.scene).filename().string(), scratch_,
                   options_.concurrency};
}

Status PovrayProvider::RenderGuides(std::span<const Pass> also, int alsoWidth, int alsoHeight,
                                    std::vector<std::vector<RGB>>* alsoOut) {
  const int w = options_.width, h = options_.height;
  std::vector<PovrayJob> jobs;
  for (Pass p : also) {
    jobs.push_back(DenseJob(p, alsoWidth, alsoHeight));
    stats_.litInvocations += p == Pass::kBeauty || p == Pass::kIllumination;
  }
  for (Pass p : {Pass::kObjectId, Pass::kShaderId, Pass::kTexture, Pass::kNormal, Pass::kHighlight})
    jobs.push_back(DenseJob(p, w, h));
  const PovrayEnv env = Env();
  stats_.invocations += int(jobs.size());
  DCM_RETURN_IF_ERROR(RunJobs(env, jobs));
  const size_t g = also.size();
  if (alsoOut) {
    alsoOut->assign(g, {});
    for (size_t i = 0; i < g; ++i) DCM_RETURN_IF_ERROR(ReadRender(env, jobs[i], &(*alsoOut)[i]));
  }
  std::vector<RGB> id, shader, slope;
  DCM_RETURN_IF_ERROR(ReadRender(env, jobs[g], &id));
  DCM_RETURN_IF_ERROR(ReadRender(env, jobs[g + 1], &shader));
  DCM_RETURN_IF_ERROR(ReadRender(env, jobs[g + 2], &tau_));
  DCM_RETURN_IF_ERROR(ReadRender(env, jobs[g + 3], &slope));
  std::vector<RGB> mask;
  DCM_RETURN_IF_ERROR(ReadRender(env, jobs[g + 4], &mask));
  // The mask is optional: a scene without pass 6 renders something else than
  // 0 and 1 there, and every exact pixel then gets its L_i rendered.
  haveHighlightMask_ = true;
  highlight_.resize(mask.size());
  for (size_t i = 0; i < mask.size() && haveHighlightMask_; ++i) {
    const RGB c = mask[i];
    haveHighlightMask_ = (c.r == 0 || c.r == 1) && c.g == c.r && c.b == c.r;
    highlight_[i] = c.r == 1;
  }
  if (!haveHighlightMask_) highlight_.clear();
  DCM_RETURN_IF_ERROR(ToIds(id, w, PassText(Pass::kObjectId) + " of " + env.sceneName, &objectId_));
  DCM_RETURN_IF_ERROR(ToIds(shader, w, PassText(Pass::kShaderId) + " of " + env.sceneName, &shaderId_));
  // slope gives v = 1 - angle/180 deg along each axis: N = -cos(pi v). No
  // surface (ID 0, the background): no normal.
  normal_.resize(slope.size());
  for (size_t i = 0; i < slope.size(); ++i) {
    if (objectId_[i] == 0) continue;
    const auto axis = [&](int c) { return -std::cos(float(M_PI) * std::clamp(slope[i][c], 0.f, 1.f)); };
    normal_[i] = Vec3f{axis(0), axis(1), axis(2)};
  }
  haveGuides_ = true;
  rendered_.assign(size_t(w) * size_t(h), 0);
  samples_.resize(size_t(w) * size_t(h));
  return Status::Ok();
}

Status PovrayProvider::RenderDense(std::span<const Pass> passes, int width, int height,
                                   std::vector<std::vector<RGB>>* out) {
  const PovrayEnv env = Env();
  std::vector<PovrayJob> jobs;
  for (Pass p : passes) jobs.push_back(DenseJob(p, width, height));
  stats_.invocations += int(jobs.size());
  for (Pass p : passes) stats_.litInvocations += p == Pass::kBeauty || p == Pass::kIllumination;
  DCM_RETURN_IF_ERROR(RunJobs(env, jobs));
  out->assign(jobs.size(), {});
  for (size_t i = 0; i < jobs.size(); ++i) DCM_RETURN_IF_ERROR(ReadRender(env, jobs[i], &(*out)[i]));
  return Status::Ok();
}

ProviderCapabilities PovrayProvider::Capabilities() const {
  ProviderCapabilities c;
  c.width = options_.width;
  c.height = options_.height;
  c.objectId = c.shaderId = c.texture = c.normal = true;
  c.splitRadiance = true;
  c.threadSafe = false;
  c.name = "povray";
  return c;
}

Status PovrayProvider::Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) {
  if (!haveGuides_) return Status::Error("povray: the guide passes were not rendered");
  out->region = region;
  const size_t n = size_t(region.area());
  out->objectId.clear();
  out->shaderId.clear();
  out->texture.clear();
  out->normal.clear();
  if (what.objectId) out->objectId.reserve(n);
  if (what.shaderId) out->shaderId.reserve(n);
  if (what.texture) out->texture.reserve(n);
  if (what.normal) out->normal.reserve(n);
  for (int y = region.min.y; y < region.max.y; ++y)
    for (int x = region.min.x; x < region.max.x; ++x) {
      const size_t i = size_t(y) * size_t(options_.width) + size_t(x);
      if (what.objectId) out->objectId.push_back(objectId_[i]);
      if (what.shaderId) out->shaderId.push_back(shaderId_[i]);
      if (what.texture) out->texture.push_back(tau_[i]);
      if (what.normal) out->normal.push_back(normal_[i]);
    }
  return Status::Ok();
}

Status PovrayProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                                std::span<ExactSample> out) {
  if (pixels.empty()) return Status::Ok();
  const auto t0 = Clock::now();
  const int W = options_.width;
  const PovrayEnv env = Env();
  const size_t n = pixels.size();
  auto index = [W](Point2i p) { return size_t(p.y) * size_t(W) + size_t(p.x); };
  // The pixels whose L_i must be rendered: those with highlights or
  // reflection (L_c may be non-zero) and those whose tau is too dark to
  // divide by; elsewhere L_c = 0 and L_i = L/tau.
  std::vector<size_t> needLi;
  if (what.split)
    for (size_t k = 0; k < n; ++k) {
      const size_t i = index(pixels[k]);
      const RGB t = tau_[i];
      const bool matte = haveHighlightMask_ && !highlight_[i] &&
                         (objectId_[i] == 0 || std::min({t.r, t.g, t.b}) >= kMinDivisibleTau);
      if (!matte) needLi.push_back(k);
    }
  std::vector<Point2i> liPixels;
  for (size_t k : needLi) liPixels.push_back(pixels[k]);
  const bool ownList = !needLi.empty() && needLi.size() < n;
  DCM_RETURN_IF_ERROR(WritePixelList(scratch_, pixels));
  if (ownList) {
    std::error_code ec;
    std::filesystem::create_directory(scratch_ + "/" + ScratchSubfolder(), ec);
    if (ec) return Status::Error("cannot make " + scratch_ + "/" + ScratchSubfolder() + ": " + ec.message());
    DCM_RETURN_IF_ERROR(WriteSceneIni(scratch_ + "/" + ScratchSubfolder(), options_.scene));
    DCM_RETURN_IF_ERROR(WritePixelList(scratch_ + "/" + ScratchSubfolder(), liPixels));
  }
  std::vector<PovrayJob> jobs = {SparseJob(Pass::kBeauty, pixels.size())};
  if (!needLi.empty()) {
    jobs.push_back(SparseJob(Pass::kIllumination, needLi.size()));
    if (ownList) jobs.back().folder = ScratchSubfolder();
  }
  stats_.invocations += int(jobs.size());
  stats_.litInvocations += int(jobs.size());
  DCM_RETURN_IF_ERROR(RunJobs(env, jobs));
  std::vector<RGB> L, Li;
  DCM_RETURN_IF_ERROR(ReadRender(env, jobs[0], &L));
  if (jobs.size() > 1) DCM_RETURN_IF_ERROR(ReadRender(env, jobs[1], &Li));
  for (size_t k = 0; k < n; ++k) {
    ExactSample& s = out[k];
    const size_t i = index(pixels[k]);
    s = ExactSample{};
    s.L = L[FaceOutput(k, n, W)];
    if (what.split) {
      // L_i = L/tau on matte surfaces (L_c = 0); the background is black.
      const RGB t = tau_[i];
      if (objectId_[i] != 0) s.Li = RGB{s.L.r / t.r, s.L.g / t.g, s.L.b / t.b};
    }
    rendered_[i] = 1;
  }
  for (size_t j = 0; j < needLi.size(); ++j) {
    ExactSample& s = out[needLi[j]];
    s.Li = Li[FaceOutput(j, needLi.size(), W)];
    s.Lc = s.L - s.Li * tau_[index(pixels[needLi[j]])];
  }
  for (size_t k = 0; k < n; ++k) samples_[index(pixels[k])] = out[k];
  stats_.roundS.push_back(Since(t0));
  stats_.roundPixels.push_back(int64_t(n));
  stats_.illuminationPixels += int64_t(needLi.size());
  return Status::Ok();
}

PovrayJob PovrayProvider::SparseJob(Pass pass, size_t n) const {
  // One mesh_camera face per pixel, rows from the second (+SR2, 1-based): see FaceOutput().
  const int W = options_.width;
  const int sw = int(std::min<size_t>(n, size_t(W)));
  PovrayJob job = DenseJob(pass, sw, int((n + size_t(sw) - 1) / size_t(sw)) + 1);
  job.args = {"+SR2", "Declare=Sparse=1", "Declare=FullW=" + std::to_string(W),
              "Declare=FullH=" + std::to_string(options_.height)};
  job.what = PassText(pass) + " for " + std::to_string(n) + " pixels";
  return job;
}

}  // namespace dcm::povray

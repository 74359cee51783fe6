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

}  // namespace

std::string_view PassName(Pass pass) {
  switch (pass) {
    case Pass::kBeauty: return "beauty";
    case Pass::kObjectId: return "object ID";
    case Pass::kShaderId: return "shader ID";
    case Pass::kTexture: return "texture";
    case Pass::kIllumination: return "illumination";
    case Pass::kNormal: return "normal";
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
  DCM_RETURN_IF_ERROR(MakeScratch(&p->scratch_));
  *out = std::move(p);
  return Status::Ok();
}

PovrayProvider::~PovrayProvider() { RemoveScratch(scratch_); }

void SignalCleanup() {
  pipe::KillAllChildren();
  RemoveScratchOnSignal();
}

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
  for (Pass p : {Pass::kObjectId, Pass::kShaderId, Pass::kTexture, Pass::kNormal}) jobs.push_back(DenseJob(p, w, h));
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
  const int W = options_.width, H = options_.height;
  const PovrayEnv env = Env();
  // The pixel list as the scene's Sparse mode reads it.
  const size_t n = pixels.size();
  {
    std::ofstream inc(scratch_ + "/" + ScratchPixelList());
    inc << "#declare NPix = " << n << ";\n#declare PixX = array[" << n << "] {";
    for (size_t i = 0; i < n; ++i) inc << (i ? (i % 24 ? "," : ",\n") : "\n") << pixels[i].x;
    inc << "\n}\n#declare PixY = array[" << n << "] {";
    for (size_t i = 0; i < n; ++i) inc << (i ? (i % 24 ? "," : ",\n") : "\n") << pixels[i].y;
    inc << "\n}\n";
    inc.close();
    if (!inc)
      return Status::Error("cannot write the pixel list " + scratch_ + "/" + ScratchPixelList());
  }
  // One mesh_camera face per pixel: face k is output pixel (k mod sw,
  // k div sw + 1), since POV-Ray 3.7 traces face row r - 1 for output row r;
  // rows from the second (+SR2, 1-based) are rendered.
  const int sw = int(std::min<size_t>(n, size_t(W)));
  const int sh = int((n + size_t(sw) - 1) / size_t(sw)) + 1;
  const std::vector<std::string> args = {"+SR2", "Declare=Sparse=1", "Declare=FullW=" + std::to_string(W),
                                         "Declare=FullH=" + std::to_string(H)};
  std::vector<PovrayJob> jobs;
  for (Pass p : {Pass::kBeauty, Pass::kIllumination}) {
    if (p == Pass::kIllumination && !what.split) continue;
    PovrayJob job = DenseJob(p, sw, sh);
    job.args = args;
    job.what = PassText(p) + " for " + std::to_string(n) + " pixels";
    jobs.push_back(std::move(job));
  }
  stats_.invocations += int(jobs.size());
  stats_.litInvocations += int(jobs.size());
  DCM_RETURN_IF_ERROR(RunJobs(env, jobs));
  std::vector<RGB> L, Li;
  DCM_RETURN_IF_ERROR(ReadRender(env, jobs[0], &L));
  if (what.split) DCM_RETURN_IF_ERROR(ReadRender(env, jobs[1], &Li));
  for (size_t k = 0; k < n; ++k) {
    const size_t at = (k / size_t(sw) + 1) * size_t(sw) + k % size_t(sw);
    ExactSample& s = out[k];
    const Point2i p = pixels[k];
    const size_t i = size_t(p.y) * size_t(W) + size_t(p.x);
    s.L = L[at];
    if (what.split) {
      s.Li = Li[at];
      s.Lc = s.L - s.Li * tau_[i];
    }
    rendered_[i] = 1;
    samples_[i] = s;
  }
  stats_.roundS.push_back(Since(t0));
  stats_.roundPixels.push_back(int64_t(n));
  return Status::Ok();
}

}  // namespace dcm::povray

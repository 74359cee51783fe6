// PipeProvider and `dcm pipe` against the Python example provider
// (examples/provider-python) and faulty variants of it (faulty_provider.py).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/image_io.h"
#include "common/metrics.h"
#include "dcm/pipe/pipe_provider.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"

namespace fs = std::filesystem;

namespace {

std::string Analytic(const std::string& args = "") {
  return std::string(DCM_PYTHON3) + " " + DCM_ANALYTIC_PROVIDER + (args.empty() ? "" : " " + args);
}
std::string Faulty(const std::string& mode) { return std::string(DCM_PYTHON3) + " " + DCM_FAULTY_PROVIDER + " " + mode; }

dcm::Status Start(const std::string& command, std::unique_ptr<dcm::pipe::PipeProvider>* p, double timeout = 60) {
  dcm::pipe::PipeOptions o;
  o.command = command;
  o.timeoutSeconds = timeout;
  o.startupTimeoutSeconds = 120;  // python3 + numpy on a loaded machine
  return dcm::pipe::PipeProvider::Start(o, p);
}

bool Contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// A fresh, empty directory for one test.
class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/dcm-pipe-test.XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (fs::path(path_) / name).string(); }
  bool empty() const { return fs::is_empty(path_); }

 private:
  std::string path_;
};

/// Runs a shell command; returns its exit status and its stdout+stderr.
int RunShell(const std::string& command, std::string* output) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return -1;
  output->clear();
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) output->append(buf, n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// The analytic example's noise-free image of w x h pixels (its --truth),
/// float RGB, row-major; empty where it could not be made.
std::vector<float> AnalyticTruth(const std::string& path, int w, int h) {
  std::string log;
  if (RunShell(Analytic("--width " + std::to_string(w) + " --height " + std::to_string(h) + " --truth " + path), &log))
    return {};
  std::vector<float> ref(size_t(w) * size_t(h) * 3);
  std::ifstream tf(path, std::ios::binary);
  tf.read(reinterpret_cast<char*>(ref.data()), std::streamsize(ref.size() * 4));
  return tf.good() ? ref : std::vector<float>{};
}

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

/// Runs `dcm pipe --quiet` on the child command `child` with `flags`, into
/// DIR/out.exr with DIR/stats.json (`dir` ends with a slash); false (and
/// `log` says why) where it failed or its outputs cannot be read.
bool RunDcmPipe(const std::string& dir, const std::string& child, const std::string& flags, std::string* log,
                nlohmann::json* stats, std::vector<dcm::RGB>* img, int* w, int* h) {
  const std::string out = dir + "out.exr", statsPath = dir + "stats.json";
  if (RunShell(std::string(DCM_BINARY) + " pipe --quiet --provider-cmd " + Quoted(child) + " -o " + out +
                   " --stats " + statsPath + " " + flags,
               log) != 0)
    return false;
  std::ifstream js(statsPath);
  *stats = nlohmann::json::parse(js, nullptr, false);
  return !stats->is_discarded() && dcm::toolkit::ReadRgb(out, w, h, img).ok() && size_t(*w) * size_t(*h) == img->size();
}

// --- PipeProvider ------------------------------------------------------------

TEST(PipeProvider, HandshakeAnnouncesTheScene) {
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(Analytic("--width 40 --height 24"), &p).ok());
  const dcm::ProviderCapabilities c = p->Capabilities();
  EXPECT_EQ(c.width, 40);
  EXPECT_EQ(c.height, 24);
  EXPECT_TRUE(c.objectId);
  EXPECT_TRUE(c.shaderId);
  EXPECT_TRUE(c.texture);
  EXPECT_TRUE(c.splitRadiance);
  EXPECT_FALSE(c.variance);
  EXPECT_FALSE(c.threadSafe);
  EXPECT_EQ(c.name, "analytic-python");
  EXPECT_EQ(p->childProtocolVersion(), 1);
  EXPECT_TRUE(p->Finish().ok());
}

TEST(PipeProvider, GuidesAndSamplesAgree) {
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(Analytic("--width 64 --height 48"), &p).ok());
  const dcm::Bounds2i region{{10, 5}, {60, 40}};
  dcm::GuideImage g;
  ASSERT_TRUE(p->Guides(region, {true, true, true}, &g).ok());
  ASSERT_EQ(g.region, region);
  ASSERT_EQ(g.objectId.size(), size_t(region.area()));
  ASSERT_EQ(g.shaderId.size(), size_t(region.area()));
  ASSERT_EQ(g.texture.size(), size_t(region.area()));
  int objects[4] = {0, 0, 0, 0};
  for (uint32_t id : g.objectId) {
    ASSERT_GE(id, 1u);
    ASSERT_LE(id, 3u);
    ++objects[id];
  }
  EXPECT_GT(objects[1], 0);
  EXPECT_GT(objects[2], 0);
  EXPECT_GT(objects[3], 0) << "the thin bar crosses the region";
  // Only what is asked for.
  dcm::GuideImage ids;
  ASSERT_TRUE(p->Guides(region, {true, false, false}, &ids).ok());
  EXPECT_EQ(ids.objectId, g.objectId);
  EXPECT_TRUE(ids.shaderId.empty());
  EXPECT_TRUE(ids.texture.empty());

  std::vector<dcm::Point2i> px;
  for (int y = region.min.y; y < region.max.y; y += 3)
    for (int x = region.min.x; x < region.max.x; x += 2) px.push_back({x, y});
  std::vector<dcm::ExactSample> s(px.size());
  ASSERT_TRUE(p->Evaluate(px, {true, false}, s).ok());
  for (size_t i = 0; i < px.size(); ++i) {
    const dcm::RGB tau = g.texture[size_t(region.offset(px[i]))];
    const dcm::RGB L = s[i].Li * tau + s[i].Lc;
    ASSERT_NEAR(L.r, s[i].L.r, 1e-5f);
    ASSERT_NEAR(L.g, s[i].L.g, 1e-5f);
    ASSERT_NEAR(L.b, s[i].L.b, 1e-5f);
  }
  // The same pixel gives the same bits in another batch.
  std::vector<dcm::ExactSample> one(1);
  ASSERT_TRUE(p->Evaluate(std::span(px).subspan(7, 1), {false, false}, one).ok());
  EXPECT_EQ(one[0].L, s[7].L);
  EXPECT_TRUE(p->Finish().ok());
  EXPECT_FALSE(p->Evaluate(px, {false, false}, s).ok()) << "no requests after Finish()";
}

TEST(PipeProvider, ReconstructsWithFewExactPixels) {
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(Analytic("--width 96 --height 64"), &p).ok());
  dcm::Reconstruction r;
  ASSERT_TRUE(dcm::Reconstruct(*p, dcm::ReconstructionOptions{}, &r).ok());
  EXPECT_GT(r.stats.exactFraction(), 0.0);
  EXPECT_LT(r.stats.exactFraction(), 0.5);
  EXPECT_TRUE(r.stats.usedSplit);
  EXPECT_TRUE(r.stats.usedShaderId);
  EXPECT_TRUE(p->Finish().ok());
}

TEST(PipeProvider, UnknownHandshakeKeysAndCapabilitiesAreIgnored) {
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(
      Start("printf 'dcm-pipe 1 width=4 height=3 caps=object_id,hyperspectral,hard_shadows_guided colour=blue\\n'; "
            "cat >/dev/null",
            &p)
          .ok());
  EXPECT_EQ(p->Capabilities().width, 4);
  EXPECT_TRUE(p->Capabilities().hardShadowsGuided);
  EXPECT_EQ(p->Capabilities().height, 3);
  EXPECT_TRUE(p->Capabilities().objectId);
  EXPECT_FALSE(p->Capabilities().texture);
  EXPECT_EQ(p->Capabilities().name, "pipe");
  EXPECT_TRUE(p->Finish().ok());
}

TEST(PipeProvider, HandshakeCarriesTheRoundCostAndThePreview) {
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start("printf 'dcm-pipe 1 width=4 height=3 caps=preview round_latency=0.25 sample_cost=2e-4\\n'; "
                    "cat >/dev/null",
                    &p)
                  .ok());
  EXPECT_TRUE(p->hasPreview());
  EXPECT_DOUBLE_EQ(p->roundCost().latencyS, 0.25);
  EXPECT_DOUBLE_EQ(p->roundCost().perSampleS, 2e-4);
  EXPECT_EQ(dcm::ChooseSchedule(p->roundCost()), dcm::RoundSchedule::kPreview);
  EXPECT_LT(p->roundCost().previewS, 0) << "not announced: unknown";
  EXPECT_TRUE(p->Finish().ok());
  // A request of 500 samples' cost: level by level, unless the preview is known to cost less than
  // the requests it saves.
  for (const auto& [preview, schedule] : {std::pair{"", dcm::RoundSchedule::kLevels},
                                          std::pair{" preview_cost=0", dcm::RoundSchedule::kPreview},
                                          std::pair{" preview_cost=20", dcm::RoundSchedule::kLevels}}) {
    ASSERT_TRUE(Start(std::string("printf 'dcm-pipe 1 width=4 height=3 caps=preview round_latency=0.5 "
                                  "sample_cost=1e-3") + preview + "\\n'; cat >/dev/null",
                      &p)
                    .ok());
    EXPECT_EQ(dcm::ChooseSchedule(p->roundCost()), schedule) << preview;
    EXPECT_TRUE(p->Finish().ok());
  }
  // A provider that says nothing costs nothing and has no preview: the levels schedule.
  ASSERT_TRUE(Start("printf 'dcm-pipe 1 width=4 height=3\\n'; cat >/dev/null", &p).ok());
  EXPECT_FALSE(p->hasPreview());
  EXPECT_EQ(p->roundCost().latencyS, 0);
  EXPECT_EQ(dcm::ChooseSchedule(p->roundCost()), dcm::RoundSchedule::kLevels);
  std::vector<dcm::ExactSample> s;
  EXPECT_FALSE(p->Preview({{0, 0}, {4, 3}}, {}, &s).ok());
  EXPECT_TRUE(p->Finish().ok());
  for (const char* bad :
       {"round_latency=-1", "round_latency=abc", "sample_cost=nan", "round_latency=1e9", "preview_cost=-1"}) {
    const dcm::Status st =
        Start(std::string("printf 'dcm-pipe 1 width=4 height=3 ") + bad + "\\n'; cat >/dev/null", &p);
    ASSERT_FALSE(st.ok()) << bad;
    EXPECT_TRUE(Contains(st.message(), "must be seconds")) << st.message();
  }
  // preview_samples=: a whole number, with the preview it describes.
  ASSERT_TRUE(Start("printf 'dcm-pipe 1 width=4 height=3 caps=preview preview_samples=16\\n'; cat >/dev/null", &p).ok());
  EXPECT_EQ(p->previewSamples(), 16);
  EXPECT_TRUE(p->Finish().ok());
  for (const char* bad : {"caps=preview preview_samples=-1", "caps=preview preview_samples=1.5", "preview_samples=16"}) {
    const dcm::Status st =
        Start(std::string("printf 'dcm-pipe 1 width=4 height=3 ") + bad + "\\n'; cat >/dev/null", &p);
    ASSERT_FALSE(st.ok()) << bad;
    EXPECT_TRUE(Contains(st.message(), "preview_samples")) << st.message();
  }
}

TEST(PipeProvider, PreviewPlannedRoundsAreOneEvalEach) {
  // A provider whose rounds cost a latency: the engine plans on its
  // half-resolution preview and asks for each round's pixels in one request.
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(Analytic("--width 96 --height 72 --round-latency 0.5"), &p).ok());
  ASSERT_TRUE(p->hasPreview());
  ASSERT_EQ(dcm::ChooseSchedule(p->roundCost()), dcm::RoundSchedule::kPreview);
  std::unique_ptr<dcm::SampleProvider> preview;
  ASSERT_TRUE(p->FetchPreview({true, false}, &preview).ok());
  std::vector<dcm::ExactSample> one(1);
  const dcm::Point2i odd{5, 7};
  ASSERT_TRUE(preview->Evaluate({&odd, 1}, {false, false}, one).ok());
  std::vector<dcm::ExactSample> s;
  ASSERT_TRUE(p->Preview({{4, 6}, {5, 7}}, {}, &s).ok());  // (5, 7) shows its block's corner (4, 6)
  EXPECT_EQ(one[0].L.r, s[0].L.r);
  dcm::ReconstructionOptions o;
  dcm::PreviewScheduleOptions sched;
  sched.maxRounds = 3;
  dcm::Reconstruction r;
  dcm::PreviewScheduleStats ss;
  ASSERT_TRUE(dcm::ReconstructWithPreview(*p, *preview, o, sched, &r, &ss).ok());
  EXPECT_GE(ss.rounds, 1);
  EXPECT_LE(ss.rounds, 3);
  EXPECT_EQ(p->evalRequests(), ss.rounds);  // one request per round, whatever its size
  EXPECT_GT(ss.pixelsPerRound[0], 4096 / 8);
  EXPECT_LT(r.stats.exactFraction(), 0.6);
  EXPECT_TRUE(p->Finish().ok());
}

TEST(PipeProvider, APreviewCarriesTheCovarianceOfItsTextureGuideWhereAnnounced) {
  // A child whose preview records end with `texcov` when asked (capability
  // texture_covariance): pixel k has L = k, L_i = 1, L_c = 0, variance 0.5 and
  // texcov 0.25 k in every channel.
  const std::string child = std::string(DCM_PYTHON3) + R"( -c "
import struct, sys
print('dcm-pipe 1 width=2 height=1 caps=texture,split,variance,preview,texture_covariance', flush=True)
for line in sys.stdin:
    t = line.split()
    if t and t[0] == 'preview':
        what = t[5].split(',')
        out = sys.stdout.buffer
        out.write(b'samples 2\n')
        for k in range(2):
            rec = [k] * 3 + [1] * 3 + [0] * 3 + [0.5] * 3 + ([0.25 * k] * 3 if 'texcov' in what else [])
            out.write(struct.pack('<%df' % len(rec), *rec))
        out.flush()
    elif t and t[0] == 'quit':
        break
")";
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(child, &p).ok());
  std::unique_ptr<dcm::SampleProvider> preview;
  std::vector<dcm::RGB> own, cov;
  ASSERT_TRUE(p->FetchPreview({true, true}, &preview, 0, &own, &cov).ok());
  ASSERT_EQ(cov.size(), 2u);
  EXPECT_EQ(cov[1].g, 0.25f);
  EXPECT_EQ(own[1].b, 0.5f);
  std::vector<dcm::ExactSample> s(1);
  const dcm::Point2i one{1, 0};
  ASSERT_TRUE(preview->Evaluate({&one, 1}, {true, true}, s).ok());
  EXPECT_EQ(s[0].L.r, 1.f);
  EXPECT_EQ(s[0].Li.r, 1.f);
  // Without the split (no texture guide to share) it is not asked for.
  ASSERT_TRUE(p->FetchPreview({false, true}, &preview, 0, &own, &cov).ok());
  EXPECT_TRUE(cov.empty());
  EXPECT_TRUE(p->Finish().ok());
}

TEST(PipeProvider, ExtraPixelsFollowTheSamplesWhereAnnounced) {
  // A child with capability `extra`: after the samples of an eval (L = x), the
  // pixels of the row not asked for (L = 10 + x); with 'bad' in its argument an
  // extra pixel outside the image.
  auto child = [](const std::string& mode) {
    return std::string(DCM_PYTHON3) + R"( -c "
import struct, sys
print('dcm-pipe 1 width=4 height=1 caps=extra', flush=True)
inp, out = sys.stdin.buffer, sys.stdout.buffer
while True:
    t = inp.readline().split()
    if not t or t[0] == b'quit':
        break
    if t[0] != b'eval':
        continue
    n = int(t[1])
    xy = struct.unpack('<%di' % (2 * n), inp.read(8 * n))
    asked = set(xy[0::2])
    out.write(b'samples %d\n' % n)
    for x in xy[0::2]:
        out.write(struct.pack('<3f', x, x, x))
    rest = [x for x in range(4) if x not in asked] + ([7] if ')" + mode + R"(' == 'bad' else [])
    out.write(b'extra %d\n' % len(rest))
    for x in rest:
        out.write(struct.pack('<2i', x, 0))
    for x in rest:
        out.write(struct.pack('<3f', 10 + x, 10 + x, 10 + x))
    out.flush()
")";
  };
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(child("good"), &p).ok());
  const std::vector<dcm::Point2i> px{{1, 0}, {3, 0}};
  std::vector<dcm::ExactSample> s(px.size());
  const dcm::Status good = p->Evaluate(px, {}, s);
  ASSERT_TRUE(good.ok()) << good.message();
  EXPECT_EQ(s[1].L.g, 3.f);
  std::vector<dcm::Point2i> extra;
  std::vector<dcm::ExactSample> values;
  p->TakeExtraSamples(&extra, &values);
  ASSERT_EQ(extra.size(), 2u);
  ASSERT_EQ(values.size(), 2u);
  EXPECT_EQ(extra[1].x, 2);
  EXPECT_EQ(values[1].L.b, 12.f);
  p->TakeExtraSamples(&extra, &values);
  EXPECT_TRUE(extra.empty()) << "taken once";
  EXPECT_TRUE(p->Finish().ok());

  ASSERT_TRUE(Start(child("bad"), &p).ok());
  const dcm::Status st = p->Evaluate(px, {}, s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("extra pixel (7, 0) outside the 4x1 image"), std::string::npos) << st.message();
}

TEST(PipeProvider, ExactSamplesAreSetWhereAnnounced) {
  // A child with capability `exact_samples` whose eval answers L = its
  // samples per pixel (64 until told otherwise; 'bad' answers another count);
  // one without the capability is not asked.
  auto child = [](const std::string& caps, const std::string& mode) {
    return std::string(DCM_PYTHON3) + R"( -c "
import struct, sys
print('dcm-pipe 1 width=4 height=1 samples=64 caps=)" + caps + R"(', flush=True)
inp, out = sys.stdin.buffer, sys.stdout.buffer
spp = 64
while True:
    t = inp.readline().split()
    if not t or t[0] == b'quit':
        break
    if t[0] == b'exact_samples':
        spp = int(t[1])
        out.write(b'exact_samples %d\n' % (spp + (1 if ')" + mode + R"(' == 'bad' else 0)))
    elif t[0] == b'eval':
        n = int(t[1])
        inp.read(8 * n)
        out.write(b'samples %d\n' % n)
        for _ in range(n):
            out.write(struct.pack('<3f', spp, spp, spp))
    out.flush()
")";
  };
  const std::vector<dcm::Point2i> px{{1, 0}};
  std::vector<dcm::ExactSample> s(px.size());
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(child("exact_samples", "good"), &p).ok());
  ASSERT_TRUE(p->hasExactSamples());
  ASSERT_TRUE(p->Evaluate(px, {}, s).ok());
  EXPECT_EQ(s[0].L.r, 64.f);
  const dcm::Status set = p->SetExactSamples(16);
  ASSERT_TRUE(set.ok()) << set.message();
  ASSERT_TRUE(p->Evaluate(px, {}, s).ok());
  EXPECT_EQ(s[0].L.r, 16.f) << "later evals at the samples set";
  EXPECT_FALSE(p->SetExactSamples(0).ok());
  EXPECT_TRUE(p->Finish().ok());

  ASSERT_TRUE(Start(child("", "good"), &p).ok());
  EXPECT_FALSE(p->hasExactSamples());
  const dcm::Status refused = p->SetExactSamples(16);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("did not announce exact_samples"), std::string::npos) << refused.message();
  EXPECT_TRUE(p->Finish().ok());

  ASSERT_TRUE(Start(child("exact_samples", "bad"), &p).ok());
  const dcm::Status wrong = p->SetExactSamples(16);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.message().find("malformed answer to 'exact_samples 16'"), std::string::npos) << wrong.message();
}

/// Starts `command` and drives it through guides and one batch; returns the
/// first error.
dcm::Status Drive(const std::string& command, double timeout = 60) {
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  DCM_RETURN_IF_ERROR(Start(command, &p, timeout));
  const dcm::ProviderCapabilities c = p->Capabilities();
  dcm::GuideImage g;
  DCM_RETURN_IF_ERROR(p->Guides({{0, 0}, {c.width, c.height}}, {true, true, true}, &g));
  std::vector<dcm::Point2i> px{{0, 0}, {1, 2}, {3, 1}, {c.width - 1, c.height - 1}};
  std::vector<dcm::ExactSample> s(px.size());
  DCM_RETURN_IF_ERROR(p->Evaluate(px, {true, false}, s));
  return p->Finish();
}

TEST(PipeProvider, TimeoutsOutOfRangeAreRefusedBeforeTheChildStarts) {
  // 1e10 s overflowed the nanosecond deadline and threw a good run away; a
  // library user gets the same refusal as --provider-timeout.
  for (double t : {1e10, -1.0, 0.0, std::numeric_limits<double>::quiet_NaN()}) {
    std::unique_ptr<dcm::pipe::PipeProvider> p;
    const dcm::Status st = Start(Analytic("--width 8 --height 8"), &p, t);
    ASSERT_FALSE(st.ok()) << t;
    EXPECT_NE(st.message().find("timeouts"), std::string::npos) << st.message();
  }
}

TEST(PipeProvider, VarianceOfANoisyProvider) {
  // The provider announces `variance` with --noise: samples then carry it
  // (noise sd 0.05 on L_i, so sigma^2 tau^2 in L), and the engine weighs it:
  // with the noise taken into account, fewer pixels are evaluated than with
  // the noise taken at face value.
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(Analytic("--width 96 --height 64 --noise 0.05"), &p).ok());
  ASSERT_TRUE(p->Capabilities().variance);
  dcm::GuideImage g;
  ASSERT_TRUE(p->Guides({{0, 0}, {96, 64}}, {false, false, true}, &g).ok());
  std::vector<dcm::Point2i> px{{0, 0}, {50, 30}, {95, 63}};
  std::vector<dcm::ExactSample> s(px.size());
  ASSERT_TRUE(p->Evaluate(px, {true, true}, s).ok());
  for (size_t i = 0; i < px.size(); ++i) {
    const dcm::RGB tau = g.texture[size_t(px[i].y) * 96 + size_t(px[i].x)];
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(s[i].variance[c], 0.0025f * tau[c] * tau[c], 1e-6f) << "pixel " << i << " channel " << c;
    // L = L_i tau + L_c holds for the noisy sample (float rounding).
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s[i].L[c], s[i].Li[c] * tau[c] + s[i].Lc[c], 1e-5f);
  }
  ASSERT_TRUE(p->Finish().ok());

  auto exactFraction = [](float significance) {
    std::unique_ptr<dcm::pipe::PipeProvider> q;
    EXPECT_TRUE(Start(Analytic("--width 96 --height 64 --noise 0.05"), &q).ok());
    dcm::ReconstructionOptions o;
    o.noiseSignificance = significance;
    dcm::Reconstruction r;
    const dcm::Status st = dcm::Reconstruct(*q, o, &r);
    EXPECT_TRUE(st.ok()) << st.message();
    EXPECT_TRUE(q->Finish().ok());
    return r.stats.exactFraction();
  };
  EXPECT_LT(exactFraction(1.5f), exactFraction(0.f));
}

TEST(PipeProvider, NormalGuides) {
  // With --normals the provider announces `normal` and serves 3 floats per
  // pixel after the other guides; without, dcm never asks for them.
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(Analytic("--width 96 --height 64 --normals"), &p).ok());
  ASSERT_TRUE(p->Capabilities().normal);
  dcm::GuideRequest req;
  req.objectId = req.texture = req.normal = true;
  dcm::GuideImage g;
  ASSERT_TRUE(p->Guides({{0, 0}, {96, 64}}, req, &g).ok());
  ASSERT_EQ(g.normal.size(), size_t(96 * 64));
  for (size_t i = 0; i < g.normal.size(); ++i) {
    const bool disc = g.objectId[i] == 2;
    ASSERT_EQ(g.normal[i].z, disc ? 1.f : 0.f) << "pixel " << i;
    ASSERT_EQ(g.normal[i].y, disc ? 0.f : 1.f) << "pixel " << i;
  }
  ASSERT_TRUE(p->Finish().ok());
  std::unique_ptr<dcm::pipe::PipeProvider> q;
  ASSERT_TRUE(Start(Analytic("--width 96 --height 64"), &q).ok());
  EXPECT_FALSE(q->Capabilities().normal);
  ASSERT_TRUE(q->Guides({{0, 0}, {4, 4}}, req, &g).ok());
  EXPECT_TRUE(g.normal.empty());
  ASSERT_TRUE(q->Finish().ok());
}

struct FaultCase {
  const char* mode;
  const char* message;
};
/// For gtest's messages.
void PrintTo(const FaultCase& f, std::ostream* os) { *os << f.mode; }

class PipeFault : public ::testing::TestWithParam<FaultCase> {};

TEST_P(PipeFault, BecomesAClearError) {
  const FaultCase& f = GetParam();
  const std::string command = Faulty(f.mode);
  const dcm::Status st = Drive(command, 5);
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(Contains(st.message(), "provider '" + command + "': ")) << st.message();
  EXPECT_TRUE(Contains(st.message(), f.message)) << st.message();
}

INSTANTIATE_TEST_SUITE_P(
    Modes, PipeFault,
    ::testing::Values(
        FaultCase{"crash-on-eval", "(signal 11, Segmentation fault)"},
        FaultCase{"exit-on-eval", "closed its output instead of answering 'eval 4 L,split' (it exited with status 3)"},
        FaultCase{"garbage-on-eval", "sent '\\x00\\xff\\x13garbage \\x80\\x81' in answer to 'eval 4 L,split'"},
        FaultCase{"garbage-handshake", "sent 'HELLO I am a renderer' in answer to 'dcm-pipe 1'"},
        FaultCase{"wrong-count", "answered 'samples 3' to 'eval 4 L,split', which asks for 4 pixels"},
        FaultCase{"short-payload", "closed its output in the middle of its answer to 'eval 4 L,split'"},
        FaultCase{"error-on-guides", "reported an error: scene file 'missing.scn' not found"},
        FaultCase{"bad-version", "speaks dcm-pipe protocol version 99, dcm speaks version 1"},
        FaultCase{"long-line", "sent a line longer than 4096 bytes"},
        FaultCase{"exit-after-quit", "exited with status 5 after 'quit'"}),
    [](const ::testing::TestParamInfo<FaultCase>& param) {
      std::string n = param.param.mode;
      for (char& c : n)
        if (c == '-') c = '_';
      return n;
    });

TEST(PipeProvider, TimeoutKillsTheChild) {
  const auto t0 = std::chrono::steady_clock::now();
  const dcm::Status st = Drive(Faulty("hang-on-eval"), 0.5);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(Contains(st.message(), "did not answer 'eval 4 L,split' within 0.5 s (killed)")) << st.message();
  EXPECT_LT(s, 30.0) << "the hanging child (sleep 120) was killed";
}

TEST(PipeProvider, MissingCommandAndBadHandshakes) {
  dcm::Status st = Drive("/nonexistent/renderer --fast");
  EXPECT_TRUE(Contains(st.message(), "closed its output instead of answering 'dcm-pipe 1' (it exited with status 127)"))
      << st.message();
  st = Drive("printf 'dcm-pipe 1 height=4\\n'; cat >/dev/null");
  EXPECT_TRUE(Contains(st.message(), "handshake without width= and height=")) << st.message();
  st = Drive("printf 'dcm-pipe 1 width=0 height=4\\n'; cat >/dev/null");
  EXPECT_TRUE(Contains(st.message(), "width must be from 1 to 131072, got '0'")) << st.message();
  st = Drive("printf 'dcm-pipe one width=4 height=4\\n'; cat >/dev/null");
  EXPECT_TRUE(Contains(st.message(), "handshake without a protocol version")) << st.message();
  dcm::pipe::PipeOptions o;
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  EXPECT_FALSE(dcm::pipe::PipeProvider::Start(o, &p).ok()) << "empty command";
  EXPECT_EQ(p, nullptr);
}

TEST(PipeProvider, AfterAFailureEveryCallReturnsTheSameError) {
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  ASSERT_TRUE(Start(Faulty("wrong-count"), &p).ok());
  std::vector<dcm::Point2i> px{{0, 0}, {1, 1}};
  std::vector<dcm::ExactSample> s(px.size());
  const dcm::Status first = p->Evaluate(px, {false, false}, s);
  ASSERT_FALSE(first.ok());
  EXPECT_EQ(p->Evaluate(px, {false, false}, s).message(), first.message());
  dcm::GuideImage g;
  EXPECT_EQ(p->Guides({{0, 0}, {2, 2}}, {true, false, false}, &g).message(), first.message());
  EXPECT_EQ(p->Finish().message(), first.message());
}

TEST(PipeProvider, DestructionWithoutFinishEndsAStubbornChild) {
  TempDir dir;
  const std::string pidFile = dir / "sleep.pid";
  std::unique_ptr<dcm::pipe::PipeProvider> p;
  // The shell ignores 'quit' and waits for a grandchild (sleep).
  ASSERT_TRUE(Start("printf 'dcm-pipe 1 width=4 height=4\\n'; sleep 30 & echo $! > " + pidFile + "; wait", &p).ok());
  // The pid file is written right after the handshake; wait for it.
  for (int i = 0; i < 500 && (!fs::exists(pidFile) || fs::is_empty(pidFile)); ++i) ::usleep(10000);
  std::ifstream pf(pidFile);
  pid_t sleeper = 0;
  pf >> sleeper;
  ASSERT_GT(sleeper, 0);
  ASSERT_EQ(::kill(sleeper, 0), 0) << "the grandchild runs";
  const auto t0 = std::chrono::steady_clock::now();
  p.reset();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, 10.0);
  EXPECT_GE(s, 1.5) << "it was given time to quit";
  bool gone = false;
  for (int i = 0; i < 300 && !gone; ++i) {  // init reaps the orphan
    gone = ::kill(sleeper, 0) != 0;
    if (!gone) ::usleep(10000);
  }
  EXPECT_TRUE(gone) << "the whole process group was killed";
}

// --- dcm pipe ----------------------------------------------------------------

TEST(DcmPipe, ReconstructsTheAnalyticScene) {
  TempDir dir;
  const std::string out = dir / "out.exr", stats = dir / "stats.json", count = dir / "count.txt",
                    truth = dir / "truth.raw", map = dir / "map.png";
  std::string log;
  ASSERT_EQ(RunShell(Analytic("--width 192 --height 144 --truth " + truth), &log), 0) << log;
  const int rc = RunShell(std::string(DCM_BINARY) + " pipe --provider-cmd " +
                         Quoted(Analytic("--width 192 --height 144 --count-file " + count)) + " -o " + out +
                         " --stats " + stats + " --sample-map " + map,
                     &log);
  ASSERT_EQ(rc, 0) << log;
  EXPECT_TRUE(Contains(log, "exact pixels")) << log;
  ASSERT_TRUE(fs::exists(out));
  ASSERT_TRUE(fs::exists(map));

  std::ifstream js(stats);
  const nlohmann::json j = nlohmann::json::parse(js);
  const double fraction = j.at("exact_fraction").get<double>();
  const int64_t exact = j.at("exact_pixels").get<int64_t>(), total = j.at("total_pixels").get<int64_t>();
  EXPECT_EQ(total, 192 * 144);
  EXPECT_GT(fraction, 0.0);
  EXPECT_LT(fraction, 0.15);
  EXPECT_DOUBLE_EQ(fraction, double(exact) / double(total));
  EXPECT_EQ(j.at("provider").get<std::string>(), "pipe");
  // The provider evaluated exactly the exact pixels, each once.
  std::ifstream cf(count);
  int64_t evaluated = -1;
  cf >> evaluated;
  EXPECT_EQ(evaluated, exact);

  int w = 0, h = 0;
  std::vector<dcm::RGB> img;
  ASSERT_TRUE(dcm::toolkit::ReadRgb(out, &w, &h, &img).ok());
  ASSERT_EQ(w, 192);
  ASSERT_EQ(h, 144);
  std::vector<float> ref(size_t(w * h * 3));
  std::ifstream tf(truth, std::ios::binary);
  tf.read(reinterpret_cast<char*>(ref.data()), std::streamsize(ref.size() * 4));
  ASSERT_TRUE(tf.good());
  double sum = 0;
  for (size_t i = 0; i < img.size(); ++i)
    for (int c = 0; c < 3; ++c) sum += std::fabs(double(img[i][c]) - double(ref[3 * i + size_t(c)]));
  EXPECT_LT(sum / double(3 * img.size()), 0.005) << "mean absolute error against the analytic image";
}

// A provider whose calls cost a latency (a render call over the whole frame,
// a process start) gets its exact pixels in a few large calls chosen on its
// preview, as PROTOCOL.md promises; --schedule levels asks step by step.
TEST(DcmPipe, ACallThatCostsALatencyIsPlannedOnThePreview) {
  TempDir dir;
  const std::vector<float> ref = AnalyticTruth(dir / "truth.raw", 192, 144);
  ASSERT_FALSE(ref.empty());
  std::string log;
  auto run = [&](const std::string& flags, nlohmann::json* j, double* meanError) {
    int w = 0, h = 0;
    std::vector<dcm::RGB> img;
    ASSERT_TRUE(RunDcmPipe(dir / "", Analytic("--width 192 --height 144 --round-latency 0.5"), flags, &log, j, &img,
                           &w, &h))
        << log;
    double sum = 0;
    for (size_t i = 0; i < img.size(); ++i)
      for (int c = 0; c < 3; ++c) sum += std::fabs(double(img[i][c]) - double(ref[3 * i + size_t(c)]));
    *meanError = sum / double(3 * img.size());
  };
  nlohmann::json preview, levels, goal;
  double previewError = 0, levelsError = 0, goalError = 0;
  run("", &preview, &previewError);
  run("--schedule levels", &levels, &levelsError);
  EXPECT_EQ(preview.at("schedule"), "preview");
  EXPECT_EQ(levels.at("schedule"), "levels");
  // At most --max-rounds (3) calls, against one per refinement step.
  EXPECT_LE(preview.at("provider_calls").get<int>(), 3);
  EXPECT_GT(levels.at("provider_calls").get<int>(), 3);
  EXPECT_EQ(preview.at("preview").at("pixels_per_call").size(), preview.at("provider_calls").get<size_t>());
  // The same accuracy as the level schedule's within what a few pixels left at
  // their (half-resolution) preview value cost: the analytic image's mean
  // absolute error 0.005 (DcmPipe.ReconstructsTheAnalyticScene).
  EXPECT_LT(previewError, 0.005);
  EXPECT_LT(levelsError, 0.005);
  // A goal: each run of the search in two calls at most, validation pixels with its first.
  run("--target-psnr 40", &goal, &goalError);
  EXPECT_EQ(goal.at("schedule"), "preview");
  EXPECT_TRUE(goal.at("quality").at("target_reached").get<bool>());
  EXPECT_LE(goal.at("provider_calls").get<int>(), 2 * goal.at("quality").at("runs").get<int>());
  // Parts of the frame follow the levels: a preview schedule asked for there is a usage error.
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " pipe --quiet --schedule preview --tile 0/2 --provider-cmd " +
                         Quoted(Analytic("--width 64 --height 64 --round-latency 0.5")) + " -o " + (dir / "t.exr"),
                     &log),
            2)
      << log;
  EXPECT_TRUE(Contains(log, "--schedule preview")) << log;
}

// A child whose preview is its own render at fewer samples (preview_samples=,
// with its variance) gets a goal judged by the preview's estimate, as `dcm
// blender` does: no validation pixel, the ladder's first run in one call.
TEST(DcmPipe, AGoalIsJudgedByAPreviewOfTheSameImageAtFewerSamples) {
  TempDir dir;
  const std::vector<float> ref = AnalyticTruth(dir / "truth.raw", 192, 144);
  ASSERT_FALSE(ref.empty());
  std::string log;
  const std::string child = Analytic("--width 192 --height 144 --round-latency 0.5 --preview-samples 64");
  auto run = [&](const std::string& flags, nlohmann::json* j, double* psnr) {
    int w = 0, h = 0;
    std::vector<dcm::RGB> img;
    ASSERT_TRUE(RunDcmPipe(dir / "", child, flags, &log, j, &img, &w, &h)) << log;
    std::vector<dcm::RGB> truthImg(img.size());
    for (size_t i = 0; i < img.size(); ++i) truthImg[i] = {ref[3 * i], ref[3 * i + 1], ref[3 * i + 2]};
    *psnr = dcm::toolkit::Compare(img, truthImg, w, h).psnr;
  };
  nlohmann::json byPreview, byValidation;
  double previewPsnr = 0, validationPsnr = 0;
  run("--target-psnr 45", &byPreview, &previewPsnr);
  run("--target-psnr 45 --estimate-from validation", &byValidation, &validationPsnr);
  EXPECT_EQ(byPreview.at("estimated_psnr_from"), "preview");
  EXPECT_EQ(byValidation.at("estimated_psnr_from"), "validation");
  EXPECT_TRUE(byPreview.at("quality").at("target_reached").get<bool>());
  EXPECT_EQ(byPreview.at("quality").at("validation_pixels").get<int64_t>(), 0);
  EXPECT_FALSE(byPreview.at("quality").at("ladder").empty());
  // The issue's tolerance: the truth at least the target less 0.5 dB.
  EXPECT_GE(previewPsnr, 45 - 0.5);
  // No validation pixels and no second call: fewer of both than the search.
  EXPECT_LE(byPreview.at("provider_calls").get<int>(), byValidation.at("provider_calls").get<int>());
  EXPECT_LT(byPreview.at("exact_pixels").get<int64_t>(), byValidation.at("exact_pixels").get<int64_t>());
  std::printf("by the preview: %.2f dB at %lld exact pixels in %d calls; by validation: %.2f dB at %lld in %d\n",
              previewPsnr, static_cast<long long>(byPreview.at("exact_pixels").get<int64_t>()),
              byPreview.at("provider_calls").get<int>(), validationPsnr,
              static_cast<long long>(byValidation.at("exact_pixels").get<int64_t>()),
              byValidation.at("provider_calls").get<int>());
  // A preview of another kind (half resolution, no preview_samples=) cannot judge.
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " pipe --quiet --estimate-from preview --target-psnr 45 --provider-cmd " +
                         Quoted(Analytic("--width 64 --height 64 --round-latency 0.5")) + " -o " + (dir / "h.exr"),
                     &log),
            1)
      << log;
  EXPECT_TRUE(Contains(log, "--estimate-from preview") && Contains(log, "preview_samples=")) << log;
  EXPECT_FALSE(fs::exists(dir / "h.exr"));
  // Nor without the preview schedule.
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " pipe --quiet --estimate-from preview --schedule levels "
                         "--target-psnr 45 --provider-cmd " + Quoted(child) + " -o " + (dir / "l.exr"),
                     &log),
            2)
      << log;
  EXPECT_TRUE(Contains(log, "--estimate-from preview")) << log;
}

TEST(DcmPipe, FullEvaluationAsksForEveryPixel) {
  TempDir dir;
  std::string log;
  const int rc = RunShell(std::string(DCM_BINARY) + " pipe --quiet --full --provider-cmd " +
                         Quoted(Analytic("--width 32 --height 32 --count-file " + (dir / "count.txt"))) + " -o " +
                         (dir / "out.exr"),
                     &log);
  ASSERT_EQ(rc, 0) << log;
  std::ifstream cf(dir / "count.txt");
  int64_t evaluated = -1;
  cf >> evaluated;
  EXPECT_EQ(evaluated, 32 * 32);
  EXPECT_FALSE(Contains(log, "exact pixels")) << "--quiet: no summary (the provider child still speaks on stderr)\n" << log;
  ASSERT_EQ(RunShell(std::string(DCM_BINARY) + " pipe --full --provider-cmd " +
                         Quoted(Analytic("--width 32 --height 32")) + " -o " + (dir / "out.exr"),
                     &log),
            0)
      << log;
  EXPECT_TRUE(Contains(log, "100.00 %")) << log;
}

// A renderer in a child process on a farm: each tile's dcm asks its child for
// the tile's window only; the merged parts are the whole frame, bit for bit.
TEST(DcmPipe, TilesMergeToTheWholeFrame) {
  TempDir dir;
  const int n = 3;
  std::string log;
  // Every tile runs the same command (merge checks it), one after another
  // here, so that each count can be read before the next tile writes it.
  const std::string provider = Quoted(Analytic("--width 96 --height 80 --count-file " + (dir / "count.txt")));
  auto count = [&] {
    std::ifstream cf(dir / "count.txt");
    int64_t e = -1;
    cf >> e;
    return e;
  };
  ASSERT_EQ(RunShell(std::string(DCM_BINARY) + " pipe --quiet --provider-cmd " + provider + " -o " +
                         (dir / "whole.exr") + " --stats " + (dir / "whole.json"),
                     &log),
            0)
      << log;
  const int64_t wholeEvaluated = count();
  std::string merge = std::string(DCM_BINARY) + " merge --quiet -o " + (dir / "merged.exr");
  int64_t evaluated = 0;
  for (int i = 0; i < n; ++i) {
    const std::string part = dir / ("part_" + std::to_string(i) + ".exr");
    // `dcm reconstruct --provider-cmd` for one of them: the same computation.
    const std::string command = i == 1 ? " reconstruct" : " pipe";
    ASSERT_EQ(RunShell(std::string(DCM_BINARY) + command + " --quiet --provider-cmd " + provider + " --tile " +
                           std::to_string(i) + "/" + std::to_string(n) + " -o " + part + " --stats " + part + ".json",
                       &log),
              0)
        << log;
    evaluated += count();
    std::ifstream js(part + ".json");
    EXPECT_EQ(nlohmann::json::parse(js).at("part").at("tile"), std::to_string(i) + "/" + std::to_string(n));
    merge += " " + part;
  }
  ASSERT_EQ(RunShell(merge, &log), 0) << log;
  std::vector<dcm::RGB> a, b;
  int w = 0, h = 0;
  ASSERT_TRUE(dcm::toolkit::ReadRgb(dir / "whole.exr", &w, &h, &a).ok());
  ASSERT_TRUE(dcm::toolkit::ReadRgb(dir / "merged.exr", &w, &h, &b).ok());
  ASSERT_EQ(a.size(), size_t(96 * 80));
  EXPECT_EQ(a, b) << "the merged tiles differ from the whole frame";
  // Each child was asked for its tile's window only: the windows overlap by
  // their halo, so together at least the frame's exact pixels, and less than
  // the whole frame's pixels.
  EXPECT_GE(evaluated, wholeEvaluated);
  EXPECT_LT(evaluated, 96 * 80);
  EXPECT_NE(RunShell(std::string(DCM_BINARY) + " pipe --quiet --provider-cmd " + provider + " --frames 1-2 -o " +
                         (dir / "f#.exr"),
                     &log),
            0);
  EXPECT_TRUE(Contains(log, "--frames is not for a provider command")) << log;
}

class DcmPipeFault : public ::testing::TestWithParam<FaultCase> {};

TEST_P(DcmPipeFault, ExitsWithAMessageAndNoOutput) {
  const FaultCase& f = GetParam();
  TempDir dir;
  std::string log;
  const int rc = RunShell(std::string(DCM_BINARY) + " pipe --quiet --provider-timeout 2 --provider-startup-timeout 120 --provider-cmd " +
                         Quoted(Faulty(f.mode)) + " -o " + (dir / "out.exr") + " --stats " + (dir / "s.json") +
                         " --sample-map " + (dir / "m.png"),
                     &log);
  EXPECT_EQ(rc, 1) << log;
  EXPECT_TRUE(Contains(log, "dcm pipe: error: provider '")) << log;
  EXPECT_TRUE(Contains(log, f.message)) << log;
  EXPECT_TRUE(dir.empty()) << "no output, not even a temporary file";
}

INSTANTIATE_TEST_SUITE_P(
    Modes, DcmPipeFault,
    ::testing::Values(FaultCase{"crash-on-eval", "Segmentation fault"},
                      FaultCase{"exit-on-eval", "(it exited with status 3)"},
                      FaultCase{"garbage-on-eval", "garbage"},
                      FaultCase{"wrong-count", "which asks for"},
                      FaultCase{"short-payload", "in the middle of its answer"},
                      FaultCase{"hang-on-eval", "within 2 s (killed)"},
                      FaultCase{"exit-after-quit", "exited with status 5 after 'quit'"}),
    [](const ::testing::TestParamInfo<FaultCase>& param) {
      std::string n = param.param.mode;
      for (char& c : n)
        if (c == '-') c = '_';
      return n;
    });

TEST(DcmReconstruct, ProviderCmdIsDcmPipe) {
  // `dcm reconstruct --provider-cmd` (the issue's spelling) runs the same
  // reconstruction as `dcm pipe`: same pixels, same exact-pixel count; the
  // child's failures and the flags that need EXR inputs are errors.
  TempDir dir;
  const std::string provider = Quoted(Analytic("--width 96 --height 64"));
  std::string log;
  ASSERT_EQ(RunShell(std::string(DCM_BINARY) + " reconstruct --quiet --provider-cmd " + provider + " -o " +
                         (dir / "r.exr") + " --stats " + (dir / "r.json"),
                     &log),
            0)
      << log;
  ASSERT_EQ(RunShell(std::string(DCM_BINARY) + " pipe --quiet --provider-cmd " + provider + " -o " + (dir / "p.exr") +
                         " --stats " + (dir / "p.json"),
                     &log),
            0)
      << log;
  std::vector<dcm::RGB> a, b;
  int w = 0, h = 0;
  ASSERT_TRUE(dcm::toolkit::ReadRgb(dir / "r.exr", &w, &h, &a).ok());
  ASSERT_TRUE(dcm::toolkit::ReadRgb(dir / "p.exr", &w, &h, &b).ok());
  EXPECT_EQ(a, b);
  std::ifstream rj(dir / "r.json"), pj(dir / "p.json");
  EXPECT_EQ(nlohmann::json::parse(rj).at("exact_pixels"), nlohmann::json::parse(pj).at("exact_pixels"));

  TempDir bad;
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " reconstruct --quiet --provider-cmd " + Quoted(Faulty("crash-on-eval")) +
                         " -o " + (bad / "o.exr"),
                     &log),
            1)
      << log;
  EXPECT_TRUE(Contains(log, "dcm reconstruct: error: provider '")) << log;
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " reconstruct --quiet --provider-cmd " + provider + " in.exr -o " +
                         (bad / "o.exr"),
                     &log),
            2)
      << log;
  EXPECT_TRUE(Contains(log, "--provider-cmd replaces the input files")) << log;
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " reconstruct --quiet -o " + (bad / "o.exr"), &log), 2) << log;
  EXPECT_TRUE(Contains(log, "no input files (EXR AOVs), and no --provider-cmd")) << log;
  EXPECT_TRUE(bad.empty());
}

TEST(DcmPipe, UsageErrors) {
  std::string log;
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " pipe -o /tmp/never.exr", &log), 2) << log;
  EXPECT_TRUE(Contains(log, "--provider-cmd")) << log;
  TempDir dir;
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " pipe --quiet --downsample 5 --provider-cmd " +
                    Quoted(Analytic("--width 32 --height 32")) + " -o " + (dir / "o.exr"),
                &log),
            2)
      << log;
  EXPECT_TRUE(Contains(log, "dcm pipe: error: --downsample 5: the provider's image 32x32 is not a multiple")) << log;
  EXPECT_TRUE(dir.empty());
}

// A value out of a flag's range is refused before the provider starts (exit
// 2, the flag named as typed, no output), for `dcm pipe` and for `dcm
// reconstruct --provider-cmd` alike; a timeout of 1e10 s no longer overflows
// the deadline, 10 million threads no longer reach TBB.
TEST(DcmPipe, HostileFlagsAreRefused) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--provider-timeout", "1e10"},        {"--provider-timeout", "-1"},
      {"--provider-timeout", "nan"},         {"--provider-timeout", "0"},
      {"--provider-startup-timeout", "inf"}, {"--threads", "10000000"},
      {"--threads", "-1"},                   {"--threshold", "nan"},
      {"--block", "3"},                      {"--tile-size", "0"},
  };
  const std::string provider = Quoted(Analytic("--width 32 --height 32"));
  for (const std::string command : {"pipe", "reconstruct"}) {
    for (const auto& [flag, value] : cases) {
      TempDir dir;
      std::string log;
      EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " " + command + " --provider-cmd " + provider + " " + flag + " " +
                             value + " -o " + (dir / "o.exr") + " --stats " + (dir / "s.json"),
                         &log),
                2)
          << command << " " << flag << " " << value << ": " << log;
      EXPECT_TRUE(Contains(log, "dcm " + command + ": error: " + flag + ": ")) << log;
      EXPECT_TRUE(Contains(log, value)) << "the value as typed: " << log;
      EXPECT_TRUE(dir.empty()) << command << " " << flag << " " << value;
    }
  }
  // The largest timeout is used as given (the run succeeds), and so is one thread.
  TempDir dir;
  std::string log;
  EXPECT_EQ(RunShell(std::string(DCM_BINARY) + " pipe -q --provider-cmd " + provider +
                         " --provider-timeout 1e6 --provider-startup-timeout 1e6 --threads 1 -o " + (dir / "o.exr") +
                         " --stats " + (dir / "s.json"),
                     &log),
            0)
      << log;
  std::ifstream in(dir / "s.json");
  EXPECT_EQ(nlohmann::json::parse(in)["options"]["threads"], 1);
}

}  // namespace

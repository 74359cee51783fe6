#include "test_util.h"

#include "../support/exr_declared_size.h"

#include <unistd.h>
#include <sys/wait.h>

#include <OpenImageIO/half.h>
#include <OpenImageIO/imageio.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <fstream>
#include <sstream>

namespace dcm::aov::test {

namespace fs = std::filesystem;

void WriteExr(const std::string& path, int width, int height, const std::vector<TestChannel>& channels,
              const Attributes& attributes) {
  const int n = int(channels.size());
  OIIO::ImageSpec spec(width, height, n, OIIO::TypeDesc::FLOAT);
  spec.channelnames.clear();
  spec.channelformats.clear();
  size_t bytesPerPixel = 0;
  for (const auto& c : channels) {
    spec.channelnames.push_back(c.name);
    const OIIO::TypeDesc t = !c.ids.empty() ? OIIO::TypeDesc::UINT32
                             : c.half       ? OIIO::TypeDesc::HALF
                                            : OIIO::TypeDesc::FLOAT;
    spec.channelformats.push_back(t);
    bytesPerPixel += t.size();
  }
  spec.attribute("compression", "zip");
  for (const auto& [k, v] : attributes) spec.attribute(k, v);
  // Native per-channel layout: pack each pixel's channels in their formats.
  std::vector<unsigned char> buffer(size_t(width) * size_t(height) * bytesPerPixel);
  size_t off = 0;
  for (size_t i = 0; i < size_t(width) * size_t(height); ++i) {
    for (const auto& c : channels) {
      if (!c.ids.empty()) {
        std::memcpy(&buffer[off], &c.ids[i], 4);
        off += 4;
      } else if (c.half) {
        const half h(c.values[i]);
        std::memcpy(&buffer[off], &h, 2);
        off += 2;
      } else {
        std::memcpy(&buffer[off], &c.values[i], 4);
        off += 4;
      }
    }
  }
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UNKNOWN, buffer.data())) << out->geterror();
  ASSERT_TRUE(out->close()) << out->geterror();
}

std::vector<RGB> ReadRgbExr(const std::string& path, int* width, int* height) {
  std::vector<RGB> px;
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return px;
  const auto& spec = in->spec();
  const size_t n = size_t(spec.width) * size_t(spec.height);
  px.resize(n);
  std::vector<float> plane(n);
  for (int c = 0; c < 3; ++c) {
    const int idx = spec.channelindex(c == 0 ? "R" : c == 1 ? "G" : "B");
    EXPECT_GE(idx, 0) << path;
    if (idx < 0) return {};
    EXPECT_TRUE(in->read_image(0, 0, idx, idx + 1, OIIO::TypeDesc::FLOAT, plane.data()));
    for (size_t i = 0; i < n; ++i) px[i][c] = plane[i];
  }
  if (width) *width = spec.width;
  if (height) *height = spec.height;
  return px;
}

bool HighlightScene::InHighlight(int x, int y) {
  const int u = x % 16, v = y % 16;
  return (x / 16 + y / 16) % 3 == 0 && u >= 5 && u <= 7 && v >= 9 && v <= 10;
}

std::vector<TestChannel> HighlightScene::Channels() const {
  std::vector<TestChannel> ch;
  for (const char* c : {"R", "G", "B"})
    ch.push_back(Fill(c, size, size, [](int x, int y) { return InHighlight(x, y) ? 3.f : 0.4f; }));
  ch.push_back(Fill("id", size, size, [](int, int) { return 1.f; }));
  ch.push_back(Fill("shader", size, size, [](int, int) { return 1.f; }));
  return ch;
}

TestChannel HighlightScene::Guide() const {
  return Fill("highlight", size, size, [](int x, int y) { return InHighlight(x, y) ? 9.f : 0.6f; });
}

TestChannel Fill(const std::string& name, int width, int height, const std::function<float(int, int)>& f) {
  TestChannel c;
  c.name = name;
  c.values.resize(size_t(width) * size_t(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) c.values[size_t(y) * size_t(width) + size_t(x)] = f(x, y);
  return c;
}

ScratchDir::ScratchDir() {
  static std::atomic<int> counter{0};
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "_" + info->name() : "aov";
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  path_ = fs::temp_directory_path() /
          ("dcm_aov_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + "_" + name);
  fs::remove_all(path_);
  fs::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

std::vector<std::string> ScratchDir::Files() const {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void MakeHugeExr(const std::string& path, int side) {
  const std::string small = path + ".small.exr";
  WriteExr(small, 16, 16, {Fill("R", 16, 16, [](int, int) { return 0.f; })});
  std::ifstream in(small, std::ios::binary);
  std::string d((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  fs::remove(small);
  std::ofstream out(path, std::ios::binary);
  out << dcm::testing::DeclareExrSize(d, side, 16);  // zip: 16 scanlines a chunk
}

namespace {
std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

RunResult RunDcm(const std::vector<std::string>& args, const ScratchDir& dir) {
  static std::atomic<int> counter{0};
  const std::string tag = std::to_string(counter++);
  // Outside the scratch folder, so that the "nothing left behind" checks see
  // only what dcm wrote.
  const fs::path base = dir.path().parent_path() / (dir.path().filename().string() + "_run" + tag);
  const std::string outFile = base.string() + ".out", errFile = base.string() + ".err";
  std::string cmd = ShellQuote(DCM_BINARY);
  // Appends, not "literal" + string: GCC 12 warns falsely (-Wrestrict) on those.
  for (const auto& a : args) {
    cmd += ' ';
    cmd += ShellQuote(a);
  }
  cmd += " >";
  cmd += ShellQuote(outFile);
  cmd += " 2>";
  cmd += ShellQuote(errFile);
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadText(outFile);
  r.err = ReadText(errFile);
  std::error_code ec;
  fs::remove(outFile, ec);
  fs::remove(errFile, ec);
  return r;
}

// The scene: floor (object 1, shader 3) with a checker texture, a disc
// (object 2, shader 5) at (0.45w, 0.55h), a diagonal shadow edge across the
// floor, and a glossy highlight (L_c) on the disc.
uint32_t Scene::ObjectId(int x, int y) const {
  const float dx = float(x) - 0.45f * float(width), dy = float(y) - 0.55f * float(height);
  return dx * dx + dy * dy < 0.09f * float(width * height) ? 2u : 1u;
}
uint32_t Scene::ShaderId(int x, int y) const { return ObjectId(x, y) == 2 ? 5u : 3u; }
RGB Scene::Tau(int x, int y) const {
  if (ObjectId(x, y) == 2) return {0.7f, 0.4f, 0.3f};
  return ((x / 4 + y / 4) % 2) ? RGB{0.8f, 0.8f, 0.75f} : RGB{0.25f, 0.3f, 0.35f};
}
RGB Scene::Li(int x, int y) const {
  const float fx = float(x) / float(width), fy = float(y) / float(height);
  RGB li{0.6f + 0.4f * fx, 0.7f + 0.2f * fy, 0.9f - 0.3f * fx};
  if (ObjectId(x, y) == 1 && fx + fy < 0.7f) li = li * 0.25f;  // shadow
  return li;
}
RGB Scene::Lc(int x, int y) const {
  if (ObjectId(x, y) != 2) return {};
  const float dx = float(x) - 0.4f * float(width), dy = float(y) - 0.5f * float(height);
  const float h = std::exp(-(dx * dx + dy * dy) / (0.002f * float(width * height)));
  return RGB::Gray(0.8f * h);
}

std::vector<TestChannel> Scene::GenericChannels(bool split, bool guidesOnly) const {
  std::vector<TestChannel> ch;
  TestChannel id{"id", {}, {}, false}, shader{"shader", {}, {}, false};
  id = Fill("id", width, height, [&](int x, int y) { return float(ObjectId(x, y)); });
  shader = Fill("shader", width, height, [&](int x, int y) { return float(ShaderId(x, y)); });
  ch.push_back(id);
  ch.push_back(shader);
  const char* comp[3] = {"R", "G", "B"};
  if (split) {
    for (int c = 0; c < 3; ++c)
      ch.push_back(Fill(std::string("tau.") + comp[c], width, height, [&](int x, int y) { return Tau(x, y)[c]; }));
  }
  if (guidesOnly) return ch;
  for (int c = 0; c < 3; ++c) {
    if (split) {
      ch.push_back(Fill(std::string("Li.") + comp[c], width, height, [&](int x, int y) { return Li(x, y)[c]; }));
      ch.push_back(Fill(std::string("Lc.") + comp[c], width, height, [&](int x, int y) { return Lc(x, y)[c]; }));
    } else {
      ch.push_back(Fill(comp[c], width, height, [&](int x, int y) { return L(x, y)[c]; }));
    }
  }
  return ch;
}

}  // namespace dcm::aov::test

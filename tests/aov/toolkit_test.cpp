// tools/common: metrics, atomic output, the OCIO preview, the sample map.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <thread>

#include "dcm/downsample.h"
#include "common/image_io.h"
#include "common/metrics.h"
#include "common/preview.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

TEST(Metrics, SrgbEncode) {
  EXPECT_EQ(toolkit::SrgbEncode(0.f), 0.f);
  EXPECT_EQ(toolkit::SrgbEncode(1.f), 1.f);
  EXPECT_EQ(toolkit::SrgbEncode(-3.f), 0.f);
  EXPECT_EQ(toolkit::SrgbEncode(7.f), 1.f);
  EXPECT_EQ(toolkit::SrgbEncode(std::numeric_limits<float>::quiet_NaN()), 0.f);
  // 18 % gray is 0.4613561 in sRGB (IEC 61966-2-1); float pow keeps 1e-6.
  EXPECT_NEAR(toolkit::SrgbEncode(0.18f), 0.4613561f, 1e-6f);
  EXPECT_NEAR(toolkit::SrgbEncode(0.002f), 12.92f * 0.002f, 1e-7f);  // linear segment
}

TEST(Metrics, CompareKnownErrors) {
  const int w = 16, h = 8;
  std::vector<RGB> ref(w * h, RGB::Gray(0.5f)), img = ref;
  auto e = toolkit::Compare(img, ref, w, h);
  EXPECT_TRUE(std::isinf(e.psnr));
  EXPECT_EQ(e.rmse, 0.0);
  EXPECT_EQ(e.relmse, 0.0);
  EXPECT_NEAR(e.ssim, 1.0, 1e-12);
  // A constant offset of 0.1 in linear: RMSE 0.1, relMSE 0.01/(0.25+0.01),
  // PSNR from the sRGB difference of 0.6 and 0.5.
  for (auto& p : img) p = RGB::Gray(0.6f);
  e = toolkit::Compare(img, ref, w, h);
  EXPECT_NEAR(e.rmse, 0.1, 1e-7);
  EXPECT_NEAR(e.relmse, 0.01 / 0.26, 1e-7);
  const double d = double(toolkit::SrgbEncode(0.6f)) - double(toolkit::SrgbEncode(0.5f));
  EXPECT_NEAR(e.psnr, -20.0 * std::log10(d), 1e-9);
  EXPECT_LT(e.ssim, 1.0);
  // Non-finite pixels are counted and left out of the means.
  img = ref;
  img[3] = {std::numeric_limits<float>::quiet_NaN(), 0, 0};
  img[4] = RGB::Gray(std::numeric_limits<float>::infinity());
  e = toolkit::Compare(img, ref, w, h);
  EXPECT_EQ(e.nonFinite, 2);
  EXPECT_TRUE(std::isinf(e.psnr));
  EXPECT_EQ(e.rmse, 0.0);
}

TEST(Metrics, SsimFallsWithStructure) {
  const int w = 32, h = 32;
  std::vector<RGB> ref(w * h), noisy(w * h), blurred(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y * w + x);
      ref[i] = RGB::Gray(((x / 4 + y / 4) % 2) ? 0.8f : 0.1f);
      noisy[i] = ref[i] * (1.f + 0.05f * float(((x * 7 + y * 13) % 5) - 2));
      blurred[i] = RGB::Gray(0.45f);
    }
  const double sNoisy = toolkit::Compare(noisy, ref, w, h).ssim;
  const double sFlat = toolkit::Compare(blurred, ref, w, h).ssim;
  EXPECT_GT(sNoisy, sFlat);
  EXPECT_LT(sNoisy, 1.0);
  EXPECT_LT(sFlat, 0.1);  // a flat image keeps none of the checker's structure
}

TEST(Metrics, BoxDownsample) {
  std::vector<RGB> in = {RGB::Gray(1), RGB::Gray(3), RGB::Gray(5), RGB::Gray(5), RGB::Gray(7), RGB::Gray(9)};
  int ow = 0, oh = 0;
  auto out = dcm::BoxDownsample(in, 3, 2, 2, &ow, &oh);
  ASSERT_EQ(ow, 2);
  ASSERT_EQ(oh, 1);
  EXPECT_EQ(out[0], RGB::Gray(4));  // (1+3+5+7)/4
  EXPECT_EQ(out[1], RGB::Gray(7));  // partial box: (5+9)/2
}

TEST(ImageIo, AtomicWriteRemovesTheTemporaryOnFailure) {
  ScratchDir dir;
  const std::string path = dir / "out.exr";
  { std::ofstream(path) << "old"; }
  std::string tmpSeen;
  Status st = toolkit::WriteAtomically(path, [&](const std::string& tmp) {
    tmpSeen = tmp;
    std::ofstream(tmp) << "partial";
    return Status::Error("disk full");
  });
  EXPECT_FALSE(st.ok());
  EXPECT_EQ(st.message(), "disk full");
  EXPECT_EQ(fs::path(tmpSeen).parent_path().parent_path(), dir.path())
      << "the temporary is in a folder of its own in the same folder";
  EXPECT_EQ(fs::path(tmpSeen).extension(), ".exr") << "OIIO picks the format by extension";
  EXPECT_EQ(ReadText(path), "old") << "the existing file is untouched";
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"out.exr"});
  // Exceptions are errors too.
  st = toolkit::WriteAtomically(path, [&](const std::string&) -> Status { throw std::runtime_error("boom"); });
  EXPECT_THAT(st.message(), HasSubstr("boom"));
  // Success renames.
  st = toolkit::WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream(tmp) << "new";
    return Status::Ok();
  });
  EXPECT_TRUE(st.ok());
  EXPECT_EQ(ReadText(path), "new");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"out.exr"});
}

TEST(ImageIo, TransactionPutsAllOutputsInPlaceAtCommitOrNone) {
  ScratchDir dir;
  auto write = [&](const std::string& name, const std::string& text) {
    return toolkit::WriteAtomically(dir / name, [&](const std::string& tmp) {
      std::ofstream(tmp) << text;
      return Status::Ok();
    });
  };
  {
    toolkit::OutputTransaction run;
    ASSERT_TRUE(write("a.exr", "A").ok());
    ASSERT_TRUE(write("b.json", "B").ok());
    EXPECT_EQ(dir.Files().size(), 2u) << "two temporaries";
    EXPECT_FALSE(fs::exists(dir / "a.exr")) << "nothing in place before the commit";
  }  // not committed: a failure or an early return
  EXPECT_TRUE(dir.Files().empty()) << "the temporaries are gone";
  {
    toolkit::OutputTransaction run;
    ASSERT_TRUE(write("a.exr", "A").ok());
    ASSERT_TRUE(write("b.json", "B").ok());
    ASSERT_TRUE(run.Commit().ok());
  }
  EXPECT_EQ(ReadText(dir / "a.exr"), "A");
  EXPECT_EQ(ReadText(dir / "b.json"), "B");
  EXPECT_EQ(dir.Files(), (std::vector<std::string>{"a.exr", "b.json"}));
}

// A folder made inside one an earlier MakeFolder call made (dcm bench's
// OUT/SCENE): without a commit both go, the inner one first.
TEST(ImageIo, TransactionRemovesNestedFoldersItMade) {
  ScratchDir dir;
  const fs::path out = fs::path(dir / "out"), inner = out / "scene";
  {
    toolkit::OutputTransaction run;
    ASSERT_TRUE(run.MakeFolder(out.string()).ok());
    ASSERT_TRUE(run.MakeFolder(inner.string()).ok());
    ASSERT_TRUE(fs::is_directory(inner));
  }
  EXPECT_FALSE(fs::exists(out)) << "the outer folder stayed behind";
}

// Blender's multilayer EXR: without R, G, B, the one layer *.Combined is the image.
TEST(ImageIo, ReadRgbTakesBlendersCombinedLayer) {
  ScratchDir dir;
  auto write = [&](const std::string& name, const std::vector<std::string>& channels) {
    OIIO::ImageSpec spec(2, 1, int(channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = channels;
    std::vector<float> px(2 * channels.size());
    for (size_t c = 0; c < channels.size(); ++c) px[c] = px[channels.size() + c] = float(c + 1);
    const std::string path = dir / name;
    auto o = OIIO::ImageOutput::create(path);
    EXPECT_TRUE(o && o->open(path, spec) && o->write_image(OIIO::TypeDesc::FLOAT, px.data()) && o->close());
    return path;
  };
  // OpenEXR sorts the channels by name: Combined's R, G, B are not the first three.
  const std::string one = write("one.exr", {"ViewLayer.Combined.A", "ViewLayer.Combined.B", "ViewLayer.Combined.G",
                                            "ViewLayer.Combined.R", "ViewLayer.Depth.Z"});
  int w = 0, h = 0;
  std::vector<RGB> rgb;
  ASSERT_TRUE(toolkit::ReadRgb(one, &w, &h, &rgb).ok());
  ASSERT_EQ(rgb.size(), 2u);
  EXPECT_EQ(rgb[1].r, 4.f);  // the value written to ViewLayer.Combined.R
  EXPECT_EQ(rgb[1].g, 3.f);
  EXPECT_EQ(rgb[1].b, 2.f);
  // Two view layers: which is meant is not known; the message lists the channels.
  const std::string two = write("two.exr", {"A.Combined.R", "A.Combined.G", "A.Combined.B", "B.Combined.R",
                                            "B.Combined.G", "B.Combined.B"});
  const Status st = toolkit::ReadRgb(two, &w, &h, &rgb);
  ASSERT_FALSE(st.ok());
  EXPECT_THAT(st.message(), HasSubstr("two.exr"));
  EXPECT_THAT(st.message(), HasSubstr("B.Combined.R"));
}

// SIGTERM while two threads write outputs without pause: whichever thread
// takes the signal, and wherever the other one is in its write, no temporary
// is left. Many trials at random moments, since a miss is a narrow window.
TEST(ImageIo, ASignalInAnyThreadLeavesNoTemporary) {
  ScratchDir dir;
  std::mt19937 rng(7);
  for (int trial = 0; trial < 150; ++trial) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      toolkit::InstallSignalCleanup();
      auto writeForever = [&](const std::string& name) {
        for (;;)
          (void)toolkit::WriteAtomically(dir / name, [](const std::string& tmp) {
            std::ofstream(tmp) << "output";
            return Status::Ok();
          });
      };
      std::thread other(writeForever, "t1.txt");
      writeForever("t0.txt");
    }
    while (!fs::exists(dir / "t0.txt") || !fs::exists(dir / "t1.txt"))
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, 3000)(rng)));
    ::kill(pid, SIGTERM);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << "status " << status;
    for (const auto& name : dir.Files()) ASSERT_EQ(name.find(".dcmtmp"), std::string::npos) << "trial " << trial << ": " << name;
    for (const auto& name : dir.Files()) fs::remove(dir / name);
  }
}

TEST(ImageIo, ExrRoundTripWithMetadataAndAlpha) {
  ScratchDir dir;
  std::vector<RGB> px = {{0.1f, 2.f, -1.f}, {1e6f, 0.f, 0.5f}};
  toolkit::Metadata meta;
  meta.strings.push_back({"dcm:method", "paper"});
  meta.floats.push_back({"dcm:exact_fraction", 0.125f});
  ASSERT_TRUE(toolkit::WriteRgbExr(dir / "a.exr", 2, 1, px, meta, /*alpha=*/true).ok());
  int w = 0, h = 0;
  std::vector<RGB> back;
  ASSERT_TRUE(toolkit::ReadRgb(dir / "a.exr", &w, &h, &back).ok());
  EXPECT_EQ(back, px);
  auto in = OIIO::ImageInput::open(dir / "a.exr");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().nchannels, 4);
  EXPECT_EQ(in->spec().get_string_attribute("dcm:method"), "paper");
  EXPECT_EQ(in->spec().get_float_attribute("dcm:exact_fraction"), 0.125f);
  // Wrong sizes and unwritable folders are errors, never partial files.
  EXPECT_FALSE(toolkit::WriteRgbExr(dir / "b.exr", 3, 1, px).ok());
  EXPECT_FALSE(toolkit::WriteRgbExr(dir / "no/such/dir.exr", 2, 1, px).ok());
  EXPECT_FALSE(toolkit::ReadRgb(dir / "missing.exr", &w, &h, &back).ok());
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"a.exr"});
  // The memory guard.
  EXPECT_THAT(toolkit::CheckImageDimensions("x.exr", 300000, 10, 3).message(), HasSubstr("absurd"));
  EXPECT_THAT(toolkit::CheckImageDimensions("x.exr", 100000, 100000, 3).message(), HasSubstr("MiB"));
  EXPECT_TRUE(toolkit::CheckImageDimensions("x.exr", 4096, 4096, 3).ok());
}

TEST(Preview, BuiltInTransformIsTheSrgbCurve) {
  // Without $OCIO the preview is the sRGB encoding of clipped values, done by
  // OpenColorIO's ExponentWithLinearTransform; 8-bit rounding allows 1 step.
  const char* saved = std::getenv("OCIO");
  std::string keep = saved ? saved : "";
  ::unsetenv("OCIO");
  std::vector<RGB> px;
  for (int i = 0; i < 64; ++i) px.push_back({float(i) / 50.f, float(i * i) / 4096.f, 0.002f * float(i)});
  px.push_back({-1.f, std::numeric_limits<float>::quiet_NaN(), 1e9f});
  std::vector<uint8_t> rgb;
  ASSERT_TRUE(toolkit::DisplayEncode(int(px.size()), 1, px, &rgb).ok());
  for (size_t i = 0; i < px.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float want = std::isfinite(px[i][c]) ? toolkit::SrgbEncode(px[i][c]) * 255.f : 0.f;
      EXPECT_NEAR(float(rgb[i * 3 + size_t(c)]), want, 1.0f) << i << "," << c;
    }
  // A bad $OCIO is an error, not a crash.
  ::setenv("OCIO", "/nonexistent/config.ocio", 1);
  EXPECT_FALSE(toolkit::DisplayEncode(int(px.size()), 1, px, &rgb).ok());
  if (saved) ::setenv("OCIO", keep.c_str(), 1);
  else ::unsetenv("OCIO");
}

TEST(SampleMap, DistinctColoursPerReason) {
  std::set<std::array<uint8_t, 3>> colours;
  for (int i = 0; i < kSampleReasonCount; ++i) colours.insert(toolkit::ReasonColor(SampleReason(i)));
  EXPECT_EQ(int(colours.size()), kSampleReasonCount);
  Reconstruction r;
  r.workWidth = 2;
  r.workHeight = 1;
  r.sampleMap = {SampleReason::kInterpolated, SampleReason::kBorder};
  const auto img = toolkit::SampleMapImage(r);
  ASSERT_EQ(img.size(), 6u);
  EXPECT_EQ(img[3], toolkit::ReasonColor(SampleReason::kBorder)[0]);
}

TEST(StatsJson, WritesAtomically) {
  ScratchDir dir;
  ReconstructionStats s;
  s.totalPixels = 100;
  s.exactPixels = 7;
  s.byReason[size_t(SampleReason::kCorner)] = 7;
  auto j = toolkit::StatsToJson(s);
  j["options"] = toolkit::OptionsToJson(ReconstructionOptions::Guo());  // a threshold set: 0.06
  ASSERT_TRUE(toolkit::WriteJson(dir / "s.json", j).ok());
  const auto back = nlohmann::json::parse(ReadText(dir / "s.json"));
  EXPECT_EQ(back["exact_fraction"], 0.07);
  EXPECT_EQ(back["by_reason"]["corner"], 7);
  // Float options read back as the same float, written as a short decimal.
  const auto& t = back["options"]["contrast_threshold"];
  EXPECT_EQ(float(double(t)), *ReconstructionOptions::Guo().contrastThreshold);
  EXPECT_LE(t.dump().size(), 10u) << t.dump();
  EXPECT_FALSE(toolkit::WriteJson(dir / "no/s.json", j).ok());
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"s.json"});
}

}  // namespace
}  // namespace dcm::aov::test

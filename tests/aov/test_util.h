// Helpers of the AOV tests: EXRs written by the tests, a scratch folder, and
// running the built `dcm` binary.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "dcm/color.h"

namespace dcm::aov::test {

/// One channel of a test EXR: name, per-pixel values, storage type.
struct TestChannel {
  std::string name;
  std::vector<float> values;           ///< as float (ignored when `ids` is set)
  std::vector<uint32_t> ids;           ///< stored as UINT32 when not empty
  bool half = false;                   ///< stored as HALF
};

/// Metadata attributes of a test EXR.
using Attributes = std::vector<std::pair<std::string, std::string>>;

/// Writes an EXR with exactly these channels (in this order); fails the test on error.
void WriteExr(const std::string& path, int width, int height, const std::vector<TestChannel>& channels,
              const Attributes& attributes = {});

/// Reads an EXR's RGB (by name) as float; fails the test on error.
std::vector<RGB> ReadRgbExr(const std::string& path, int* width = nullptr, int* height = nullptr);

/// A channel filled from a function of (x, y).
TestChannel Fill(const std::string& name, int width, int height, const std::function<float(int, int)>& f);

/// A fresh folder for one test, removed afterwards.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }
  /// Files in the folder (names), to check that nothing was left behind.
  std::vector<std::string> Files() const;

 private:
  std::filesystem::path path_;
};

/// The outcome of running `dcm`.
struct RunResult {
  int exitCode = -1;
  std::string out, err;
};

/// Runs the built `dcm` with `args` (each quoted for the shell).
RunResult RunDcm(const std::vector<std::string>& args, const ScratchDir& dir);

/// Writes a scanline EXR whose header and offset table claim side x side
/// pixels (zip compression, one real chunk that every table entry points at):
/// opens fine, and would need absurd memory to read.
void MakeHugeExr(const std::string& path, int side);

/// Reads a whole text file.
std::string ReadText(const std::string& path);

/// Small sharp highlights off the lattice: a glossy surface (0.4, one
/// object, one shader) with highlights of 3.0, 3x2 pixels, in 1/3 of its
/// 16x16 cells, where no corner, border or probe of a 4x4 block falls.
struct HighlightScene {
  int size = 128;
  static bool InHighlight(int x, int y);
  /// R, G, B, id, shader.
  std::vector<TestChannel> Channels() const;
  /// The highlight guide (direct glossy light, R + G + B): 9 on a
  /// highlight, 0.6 elsewhere.
  TestChannel Guide() const;
};

/// The analytic test scene (sizes multiple of 8 or not): a disc object on a
/// floor, a shadow edge, a checker texture on the floor and a highlight.
struct Scene {
  int width = 64, height = 64;
  uint32_t ObjectId(int x, int y) const;
  uint32_t ShaderId(int x, int y) const;
  RGB Tau(int x, int y) const;
  RGB Li(int x, int y) const;
  RGB Lc(int x, int y) const;
  RGB L(int x, int y) const { return Li(x, y) * Tau(x, y) + Lc(x, y); }

  /// Channels of the generic preset: id, shader, and either the beauty R,G,B
  /// (split = false) or tau, Li, Lc (split = true).
  std::vector<TestChannel> GenericChannels(bool split, bool guidesOnly = false) const;
};

}  // namespace dcm::aov::test

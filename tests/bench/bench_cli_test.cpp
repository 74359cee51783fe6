// `dcm bench --quick` on a bundled scene: the outputs exist and are sane. Only
// properties that must hold whatever the machine are checked — never timings
// against each other.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <thread>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cur += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cur += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

double Num(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : std::nan(""); }

TEST(BenchQuick, RoomOutputsAreSane) {
  const fs::path dir = fs::temp_directory_path() / ("dcm_bench_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string scene = std::string(DCM_SOURCE_DIR) + "/examples/scenes/room.json";
  const std::string cmd = ShellQuote(DCM_BINARY) + " bench " + ShellQuote(scene) + " --quick --threads 2 --out " +
                          ShellQuote(dir.string()) + " --quiet";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;

  for (const char* f : {"bench.csv", "bench.json", "summary.md", "room_error_dcm.png", "room_error_bilinear.png",
                        "room_error_jbu.png"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
    EXPECT_GT(fs::is_regular_file(dir / f) ? fs::file_size(dir / f) : 0u, 0u) << f;
  }
  if (DCM_HAVE_MATPLOTLIB) {
    for (const char* f : {"room_psnr_vs_time.png", "room_psnr_vs_exact.png"})
      EXPECT_TRUE(fs::is_regular_file(dir / f)) << f << " (python3-matplotlib is installed)";
  }
  // No temporary files left behind by the atomic writes.
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    EXPECT_TRUE(ext == ".csv" || ext == ".json" || ext == ".md" || ext == ".png") << e.path();
  }

  std::ifstream in(dir / "bench.json");
  nlohmann::json j;
  ASSERT_NO_THROW(j = nlohmann::json::parse(in));
  const auto& points = j.at("points");
  ASSERT_GT(points.size(), 20u);

  // The CSV has one row per point, with the same columns on every row.
  std::ifstream csv(dir / "bench.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const size_t columns = SplitCsvLine(line).size();
  size_t rows = 0;
  while (std::getline(csv, line)) {
    EXPECT_EQ(SplitCsvLine(line).size(), columns) << line;
    ++rows;
  }
  EXPECT_EQ(rows, points.size());

  std::map<std::string, const nlohmann::json*> byLabel;
  std::map<std::string, std::vector<std::pair<double, double>>> thresholdSweep;  // method -> (threshold, fraction)
  for (const auto& p : points) {
    const std::string label = p.at("label");
    EXPECT_EQ(byLabel.count(label), 0u) << "duplicate label " << label;
    byLabel[label] = &p;
    const double frac = Num(p.at("exact_fraction"));
    EXPECT_GT(frac, 0.0) << label;
    EXPECT_LE(frac, 1.0) << label;
    EXPECT_GT(p.at("exact_pixels").get<int64_t>(), 0) << label;
    for (const char* t : {"time_illum_s", "time_guides_s", "time_engine_s", "time_total_s"}) {
      EXPECT_TRUE(std::isfinite(Num(p.at(t))) && Num(p.at(t)) >= 0.0) << label << " " << t;
    }
    EXPECT_EQ(p.at("non_finite").get<int64_t>(), 0) << label;
    if (p.at("method") == "full") {
      EXPECT_EQ(frac, 1.0);
      EXPECT_TRUE(p.at("psnr_db").is_null()) << "identical to the reference: PSNR is infinite";
      EXPECT_NEAR(Num(p.at("ssim")), 1.0, 1e-9);
      continue;
    }
    const double psnr = Num(p.at("psnr_db")), ssim = Num(p.at("ssim")), relmse = Num(p.at("relmse"));
    EXPECT_TRUE(std::isfinite(psnr) && psnr > 10.0 && psnr < 200.0) << label << " psnr " << psnr;
    EXPECT_TRUE(std::isfinite(ssim) && ssim > 0.0 && ssim <= 1.0) << label << " ssim " << ssim;
    EXPECT_TRUE(std::isfinite(relmse) && relmse >= 0.0) << label << " relmse " << relmse;
    EXPECT_LT(frac, 1.0) << label;
    const std::string sweeps = p.at("sweeps");
    if (sweeps.find("threshold") != std::string::npos) {
      thresholdSweep[p.at("method")].push_back({Num(p.at("options").at("contrast_threshold")), frac});
    }
  }
  ASSERT_TRUE(byLabel.count("full"));

  // A higher contrast threshold classifies fewer blocks as edges: the exact
  // fraction never grows with the threshold, for every method.
  for (const char* m : {"dcm", "paper", "guo"}) {
    auto& v = thresholdSweep[m];
    ASSERT_GE(v.size(), 3u) << m;
    std::sort(v.begin(), v.end());
    for (size_t i = 1; i < v.size(); ++i)
      EXPECT_LE(v[i].second, v[i - 1].second) << m << ": threshold " << v[i].first << " vs " << v[i - 1].first;
    EXPECT_LT(v.back().second, v.front().second) << m << ": the threshold changes nothing";
  }

  // Rivals run at the budget of the point they match (within 5 %), and DCM
  // at its default settings beats bilinear upsampling at that budget.
  int rivals = 0;
  for (const auto& p : points) {
    if (p.at("method") != "bilinear" && p.at("method") != "jbu") continue;
    ++rivals;
    const std::string of = p.at("budget_of");
    if (!byLabel.count(of)) continue;  // a fixed fraction (25 %, 50 %)
    const double want = double(byLabel[of]->at("exact_pixels").get<int64_t>());
    EXPECT_NEAR(double(p.at("exact_pixels").get<int64_t>()), want, 0.05 * want + 2) << p.at("label");
  }
  EXPECT_GE(rivals, 8);
  // DCM at its default settings beats bilinear upsampling at its budget.
  const auto& goal = j.at("inputs").at(0).at("goal");
  const std::string dcmLabel = goal.at("dcm_label");
  ASSERT_TRUE(byLabel.count(dcmLabel)) << dcmLabel;
  ASSERT_TRUE(byLabel.count("bilinear @" + dcmLabel));
  ASSERT_TRUE(byLabel.count("jbu @" + dcmLabel));
  const double dcm = Num(byLabel[dcmLabel]->at("psnr_db"));
  EXPECT_GT(dcm, Num(byLabel["bilinear @" + dcmLabel]->at("psnr_db")));
  // More exact pixels, less error: bilinear at 50 % beats bilinear at the
  // smallest budget of the sweep (the largest dcm threshold).
  const auto& dcmSweep = thresholdSweep["dcm"];
  const std::string smallest = "dcm t=" + [&] {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", dcmSweep.back().first);
    return std::string(buf);
  }();
  ASSERT_TRUE(byLabel.count("bilinear @" + smallest)) << smallest;
  ASSERT_TRUE(byLabel.count("bilinear @50 %"));
  EXPECT_GT(Num(byLabel["bilinear @50 %"]->at("psnr_db")), Num(byLabel["bilinear @" + smallest]->at("psnr_db")));

  // The goal check is recorded (its outcome is reported, not required here).
  EXPECT_TRUE(goal.at("beats_rivals_by_3db").is_boolean());
  EXPECT_TRUE(goal.at("faster_at_equal_error").is_boolean());
  fs::remove_all(dir);
}

}  // namespace

namespace {

// SIGTERM while the bench runs: nothing of the run appears (no table, error
// map or plot, no temporary), and the folders of --out that it made are gone.
TEST(BenchQuick, SignalMidRunLeavesNothing) {
  const fs::path parent = fs::temp_directory_path() / ("dcm_bench_signal_" + std::to_string(::getpid()));
  fs::remove_all(parent);
  fs::create_directories(parent);
  const fs::path out = parent / "made" / "by bench";
  const std::string scene = std::string(DCM_SOURCE_DIR) + "/examples/scenes/room.json";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl(DCM_BINARY, DCM_BINARY, "bench", scene.c_str(), "--quick", "--threads", "1", "--out", out.c_str(),
            "--quiet", static_cast<char*>(nullptr));
    _exit(127);
  }
  // With matplotlib, the signal comes once the first output (an error map) is
  // written as a temporary: the plots take a second or more after it. Without,
  // a second into the sweeps (the quick bench of the room takes several).
  const auto holdsAFile = [&] {
    std::error_code ec;
    return fs::exists(out, ec) && !fs::is_empty(out, ec);
  };
  if (DCM_HAVE_MATPLOTLIB) {
    for (int i = 0; i < 120000 && !holdsAFile() && ::waitpid(pid, nullptr, WNOHANG) == 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
  } else {
    for (int i = 0; i < 600 && !fs::exists(out); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, WNOHANG), 0) << "dcm bench ended before the signal";
  ::kill(pid, SIGTERM);
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << "status " << status;
  EXPECT_FALSE(fs::exists(parent / "made")) << "the folders the run made are left";
  EXPECT_TRUE(fs::is_empty(parent));
  fs::remove_all(parent);
}

TEST(BenchNoise, SppSweepAgainstAConvergedReference) {
  // dcm bench --spp on a path-traced room at 64x64: the noise points exist
  // for every spp and method, the reference is the high-spp render, and
  // (the property of issue #8 that holds at any size) dcm, weighing the
  // noise, evaluates fewer pixels than the paper's method, which chases it.
  const fs::path dir = fs::temp_directory_path() / ("dcm_bench_noise_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string scene = std::string(DCM_SOURCE_DIR) + "/examples/scenes/room.json";
  const std::string cmd = ShellQuote(DCM_BINARY) + " bench " + ShellQuote(scene) +
                          " --scale 0.125 --spp 4,16 --reference-spp 256 --set render.shadow_rays=1"
                          " --set render.glossy_rays=1 --set render.supersampling=1 --quiet --out " +
                          ShellQuote(dir.string());
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
  std::ifstream in(dir / "bench.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["inputs"].size(), 1u);
  EXPECT_EQ(j["inputs"][0]["reference_spp"], 256);
  std::map<std::string, nlohmann::json> byLabel;
  for (const auto& p : j["points"]) byLabel[p["label"].get<std::string>()] = p;
  EXPECT_EQ(byLabel["full"]["spp"], 256);
  for (int spp : {4, 16}) {
    const std::string sfx = " spp=" + std::to_string(spp);
    for (const char* m : {"full", "dcm", "dcm noise ignored", "paper"})
      ASSERT_TRUE(byLabel.count(m + sfx)) << m << sfx;
    EXPECT_EQ(byLabel["full" + sfx]["exact_fraction"], 1.0);
    EXPECT_LT(Num(byLabel["dcm" + sfx]["exact_fraction"]), Num(byLabel["paper" + sfx]["exact_fraction"]));
    EXPECT_TRUE(std::isfinite(Num(byLabel["dcm" + sfx]["psnr_db"])));
  }
  if (DCM_HAVE_MATPLOTLIB) {
    EXPECT_TRUE(fs::is_regular_file(dir / "room_noise.png"));
  }
  fs::remove_all(dir);
}

TEST(BenchNoise, UsageErrors) {
  const std::string scene = std::string(DCM_SOURCE_DIR) + "/examples/scenes/room.json";
  const fs::path dir = fs::temp_directory_path() / ("dcm_bench_noise_err_" + std::to_string(::getpid()));
  const std::string cmd = ShellQuote(DCM_BINARY) + " bench " + ShellQuote(scene) +
                          " --scale 0.125 --spp 4,16 --reference-spp 16 --quiet --no-plots --out " +
                          ShellQuote(dir.string()) + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << out;
  EXPECT_NE(out.find("--reference-spp 16 is also in --spp"), std::string::npos) << out;
  fs::remove_all(dir);
}

// A value out of a flag's range is refused at parse time (exit 2, the flag
// named as typed), before the output folder is made; never replaced by the
// default.
TEST(BenchFlags, HostileValuesAreRefused) {
  const std::string scene = std::string(DCM_SOURCE_DIR) + "/examples/scenes/room.json";
  const fs::path dir = fs::temp_directory_path() / ("dcm_bench_flags_" + std::to_string(::getpid()));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--threads", "10000000"}, {"--threads", "-1"},     {"--scale", "nan"},
      {"--scale", "0"},          {"--thresholds", "0.1,nan"}, {"--thresholds", "-0.1"},
      {"--spp", "1"},            {"--reference-spp", "0"},  {"--jbu-spatial-sigma", "nan"},
      {"--jbu-range-sigma", "inf"},
  };
  for (const auto& [flag, value] : cases) {
    const std::string cmd = ShellQuote(DCM_BINARY) + " bench " + ShellQuote(scene) + " --quick --no-plots " + flag +
                            " " + ShellQuote(value) + " --out " + ShellQuote(dir.string()) + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[512];
    while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    const int status = pclose(p);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << flag << " " << value << ": " << out;
    EXPECT_NE(out.find("dcm bench: error: " + flag + ": "), std::string::npos) << out;
    EXPECT_NE(out.find(value.substr(value.find(',') + 1)), std::string::npos) << "the value as typed: " << out;
    EXPECT_FALSE(fs::exists(dir)) << flag << " " << value;
  }
}

}  // namespace

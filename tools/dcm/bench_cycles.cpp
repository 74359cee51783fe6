// dcm bench on a .blend: the noise axis for Cycles. At each number of
// samples per pixel, the full render of the file and `dcm blender`, each a
// process of its own timed from the command to its EXR (Blender's start-up
// included), then Cycles' adaptive sampling at the largest; all against one
// converged render (bench.h, MeasureCycles).
#include "bench.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace dcm::cli {

namespace fs = std::filesystem;

bool IsBlendInput(const std::string& input) {
  std::string ext = fs::path(input).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".blend";
}

}  // namespace dcm::cli

#ifdef DCM_HAVE_PIPE

#include "blender_files.h"
#include "common/elapsed.h"
#include "common/image_io.h"
#include "common/output_transaction.h"
#include "dcm/pipe/pipe_provider.h"
#include "dcm/pipe/run_command.h"
#include "dcm/pipe/scratch_folder.h"

namespace dcm::cli {

namespace {

using pipe::ShellQuote;

using Clock = std::chrono::steady_clock;

/// A render may take long (a converged reference at thousands of samples);
/// a day is a hang.
constexpr std::chrono::seconds kRunTimeout{24 * 3600};

std::string Fixed(double v, int digits) {
  if (!std::isfinite(v)) return v > 0 ? "inf" : "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

/// The image of `path` (R, G, B or Blender's Combined layer), `what` in
/// messages; the first image read fixes the size (`*sizeOf` says which).
Status ReadImage(const std::string& path, const std::string& what, int* w, int* h, std::string* sizeOf,
                 std::vector<RGB>* rgb) {
  int iw = 0, ih = 0;
  if (Status st = toolkit::ReadRgb(path, &iw, &ih, rgb); !st.ok()) return Status::Error(what + ": " + st.message());
  auto size = [](int x, int y) { return std::to_string(x) + "x" + std::to_string(y); };
  if (*w == 0) {
    *w = iw;
    *h = ih;
    *sizeOf = what;
  } else if (iw != *w || ih != *h) {
    return Status::Error(what + " is " + size(iw, ih) + ", " + *sizeOf + " " + size(*w, *h));
  }
  return Status::Ok();
}

/// The runs of a curve (the full renders, the adaptive ones) in order of wall time.
std::vector<Point> ByTime(std::vector<Point> curve) {
  std::sort(curve.begin(), curve.end(), [](const Point& a, const Point& b) { return a.timeTotalS < b.timeTotalS; });
  return curve;
}

/// The PSNR of a curve sorted by ByTime at wall time `t`: linear in log time
/// between the two runs around it; NaN outside their range.
double PsnrAtTime(const std::vector<Point>& curve, double t) {
  if (curve.size() == 1 && t == curve[0].timeTotalS) return curve[0].error.psnr;
  for (size_t i = 0; i + 1 < curve.size(); ++i) {
    const double t0 = curve[i].timeTotalS, t1 = curve[i + 1].timeTotalS;
    if (t < t0 || t > t1 || t0 <= 0) continue;
    const double a = t1 == t0 ? 0.0 : std::log(t / t0) / std::log(t1 / t0);
    return curve[i].error.psnr + a * (curve[i + 1].error.psnr - curve[i].error.psnr);
  }
  return std::nan("");
}

/// A run beside a curve sorted by ByTime, whose PSNR at the run's wall time is
/// `at`: "at (the run's less it)", or, outside the curve's times, that the run
/// is faster or slower than all of it.
std::string AtTimeCell(const std::vector<Point>& curve, const Point& p, double at) {
  if (curve.empty()) return "";
  if (std::isfinite(at))
    return Fixed(at, 2) + " dB (" + (p.error.psnr >= at ? "+" : "") + Fixed(p.error.psnr - at, 2) + ")";
  const bool faster = p.timeTotalS < curve.front().timeTotalS;
  const Point& end = faster ? curve.front() : curve.back();
  const std::string what = end.config.method == "adaptive" ? end.config.label.substr(0, end.config.label.rfind(" spp="))
                                                           : std::to_string(end.config.spp) + "-spp render";
  return std::string(faster ? "faster" : "slower") + " than the " + what + "'s " + Fixed(end.timeTotalS, 2) + " s";
}

double Number(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
}

}  // namespace

Status MeasureCycles(const BenchFlags& f, const std::string& input, const std::string& dir,
                     std::vector<Point>* points, std::ostringstream* summary, nlohmann::json* inputJson) {
  const bool talk = !f.quiet;
  const std::string name = fs::path(input).stem().string();
  std::string blender, script, self;
  DCM_RETURN_IF_ERROR(CheckBlendFile(input));
  DCM_RETURN_IF_ERROR(FindBlender(f.blender, &blender));
  DCM_RETURN_IF_ERROR(FindBlenderScript("render_main.py", "DCM_BLENDER_RENDER", &script));
  {
    std::error_code ec;
    self = fs::read_symlink("/proc/self/exe", ec).string();
    if (ec) return Status::Error("cannot find this dcm executable (/proc/self/exe): " + ec.message());
  }
  // Each run writes into a scratch folder (removed even if dcm is killed);
  // what it wrote is copied into the output transaction after it.
  std::unique_ptr<pipe::ScratchFolder> scratch;
  DCM_RETURN_IF_ERROR(pipe::ScratchFolder::Make("dcm-bench-cycles", &scratch));
  toolkit::SetSignalHook(pipe::KillAllChildren);
  auto staged = [&](const std::string& file) { return scratch->path() + "/" + file; };
  auto keep = [&](const std::string& file) {
    return toolkit::WriteAtomically((fs::path(dir) / file).string(), [&](const std::string& tmp) {
      std::error_code ec;
      fs::copy_file(staged(file), tmp, fs::copy_options::overwrite_existing, ec);
      return ec ? Status::Error("cannot copy " + staged(file) + ": " + ec.message()) : Status::Ok();
    });
  };

  std::vector<int> spps = f.spp;
  std::sort(spps.begin(), spps.end());
  spps.erase(std::unique(spps.begin(), spps.end()), spps.end());
  const int top = spps.back();
  const int referenceSpp = f.referenceSpp ? *f.referenceSpp : 16 * top;

  // Runs `command` to its end `times` times: the median of the seconds from
  // its start to its end (a render's are the same images each time).
  int runs = 0;
  auto run = [&](const std::string& what, const std::string& command, int times, double* seconds,
                 std::vector<double>* all) -> Status {
    std::vector<double> t;
    for (int i = 0; i < times; ++i) {
      const std::string log = staged("run" + std::to_string(++runs) + ".log");
      const std::string step = what + (times > 1 ? " (" + std::to_string(i + 1) + " of " + std::to_string(times) + ")" : "");
      if (talk) std::cerr << "dcm bench: " << name << ": " << step << " ...\n";
      const auto t0 = Clock::now();
      Status st = pipe::RunCommand(command, log, kRunTimeout);
      t.push_back(toolkit::SecondsSince(t0));
      if (!st.ok()) return Status::Error(input + ": " + step + ": " + st.message());
      if (talk) std::cerr << "dcm bench: " << name << ": " << step << ": " << Fixed(t.back(), 2) << " s\n";
    }
    if (all) *all = t;
    std::sort(t.begin(), t.end());
    *seconds = t.size() % 2 ? t[t.size() / 2] : (t[t.size() / 2 - 1] + t[t.size() / 2]) / 2;
    return Status::Ok();
  };
  // The full render of the file as Blender makes it (render_main.py).
  auto cycles = [&](const std::string& what, int spp, int seedOffset, double adaptive, const std::string& file,
                    int times, double* seconds, std::vector<double>* all) {
    // Blender's own session folder in the scratch folder: gone with it, also when Blender is killed.
    std::string cmd = "TMPDIR=" + ShellQuote(scratch->path()) + " " + ShellQuote(blender) + " -b " + ShellQuote(input) + " --python-exit-code 1 --python " + ShellQuote(script) +
                      " -- --out " + ShellQuote(staged(file)) + " --samples " + std::to_string(spp);
    if (seedOffset) cmd += " --seed-offset " + std::to_string(seedOffset);
    if (adaptive > 0) cmd += " --adaptive-threshold " + Fixed(adaptive, 6);
    if (f.renderThreads > 0) cmd += " --threads " + std::to_string(f.renderThreads);
    return run(what, cmd, times, seconds, all);
  };

  int w = 0, h = 0;
  std::string sizeOf;
  std::vector<RGB> reference;
  std::string referenceText;
  if (!f.reference.empty()) {
    DCM_RETURN_IF_ERROR(ReadImage(f.reference, "--reference '" + f.reference + "'", &w, &h, &sizeOf, &reference));
    referenceText = "the converged render " + f.reference;
  } else {
    // Another seed: with the file's, the reference's first samples would be
    // the full renders' own, and their errors against it too small.
    double seconds = 0;
    DCM_RETURN_IF_ERROR(cycles("the reference, " + std::to_string(referenceSpp) + " spp", referenceSpp, 1000, 0,
                               "reference.exr", 1, &seconds, nullptr));
    DCM_RETURN_IF_ERROR(ReadImage(staged("reference.exr"), "the reference render", &w, &h, &sizeOf, &reference));
    DCM_RETURN_IF_ERROR(keep("reference.exr"));
    referenceText = "a render of " + std::to_string(referenceSpp) + " spp with the file's seed + 1000 (reference.exr, " +
                    Fixed(seconds, 1) + " s)";
  }

  auto point = [&](const std::string& method, const std::string& label, int spp) {
    Point p;
    p.input = input;
    p.scene = name;
    p.external = true;
    p.config.method = method;
    p.config.label = label + " spp=" + std::to_string(spp);
    p.config.sweeps = "cycles";
    p.config.spp = spp;
    p.totalPixels = int64_t(w) * h;
    p.exactPixels = p.totalPixels;
    p.exactFraction = 1.0;
    return p;
  };
  auto compare = [&](Point* p, const std::string& file) -> Status {
    std::vector<RGB> img;
    if (Status st = ReadImage(staged(file), file + " (" + p->config.label + ")", &w, &h, &sizeOf, &img); !st.ok())
      return Status::Error(input + ": " + st.message());
    p->error = toolkit::Compare(img, reference, w, h);
    return keep(file);
  };
  const std::vector<std::string> variants = f.variants.empty() ? std::vector<std::string>{""} : f.variants;
  std::vector<Point> pts, full, adaptive;
  for (int spp : spps) {
    Point p = point("full", "full Cycles", spp);
    const std::string file = "full_" + std::to_string(spp) + ".exr";
    std::vector<double> times;
    DCM_RETURN_IF_ERROR(
        cycles("full render, " + std::to_string(spp) + " spp", spp, 0, 0, file, f.repeat, &p.timeTotalS, &times));
    DCM_RETURN_IF_ERROR(compare(&p, file));
    p.extra = {{"times_s", times}};
    full.push_back(p);
    pts.push_back(p);
    for (size_t v = 0; v < variants.size(); ++v) {
      const std::string label = variants[v].empty() ? "dcm blender" : "dcm blender " + variants[v];
      Point d = point("dcm blender", label, spp);
      const std::string stem = "dcm" + (variants.size() > 1 ? std::to_string(v) : std::string()) + "_" +
                               std::to_string(spp);
      const std::string cmd = ShellQuote(self) + " blender " + ShellQuote(input) + " -q -o " + ShellQuote(staged(stem + ".exr")) +
                              " --stats " + ShellQuote(staged(stem + ".json")) + " --samples " + std::to_string(spp) +
                              " --blender " + ShellQuote(blender) +
                              (f.renderThreads > 0 ? " --render-threads " + std::to_string(f.renderThreads) : "") +
                              (variants[v].empty() ? "" : " " + variants[v]);
      std::vector<double> dcmTimes;
      DCM_RETURN_IF_ERROR(run(label + ", " + std::to_string(spp) + " spp", cmd, f.repeat, &d.timeTotalS, &dcmTimes));
      DCM_RETURN_IF_ERROR(compare(&d, stem + ".exr"));
      nlohmann::json stats;
      try {
        std::ifstream in(staged(stem + ".json"));
        stats = nlohmann::json::parse(in);
      } catch (const std::exception& e) {
        return Status::Error(input + ": " + label + ": its stats are not JSON: " + e.what());
      }
      DCM_RETURN_IF_ERROR(keep(stem + ".json"));
      d.exactFraction = Number(stats, "exact_fraction");
      d.exactPixels = int64_t(std::llround(d.exactFraction * double(d.totalPixels)));
      const nlohmann::json b = stats.value("blender", nlohmann::json::object());
      d.timeIllumS = Number(b, "rounds_s");
      d.timeGuidesS = Number(b, "guides_s") + Number(b, "preview_s");
      d.timeEngineS = Number(b, "engine_s");
      d.extra = {{"flags", variants[v]},
                 {"times_s", dcmTimes},
                 {"estimated_psnr", Number(stats, "estimated_psnr")},
                 {"startup_s", Number(b, "startup_s")},
                 {"stats", stem + ".json"}};
      pts.push_back(d);
    }
  }
  for (double t : f.adaptive) {
    Point p = point("adaptive", "adaptive " + Fmt("%g", t), top);
    p.exactFraction = std::nan("");  // every pixel, each with as many samples as it needs
    p.exactPixels = 0;
    const std::string file = "adaptive_" + Fmt("%g", t) + ".exr";
    std::vector<double> times;
    DCM_RETURN_IF_ERROR(cycles("adaptive sampling " + Fmt("%g", t) + ", " + std::to_string(top) + " spp at most", top,
                               0, t, file, f.repeat, &p.timeTotalS, &times));
    DCM_RETURN_IF_ERROR(compare(&p, file));
    p.extra = {{"adaptive_threshold", t}, {"times_s", times}};
    pts.push_back(p);
    adaptive.push_back(p);
  }

  // The table: each run beside the full render at its samples and at its wall time.
  *summary << "## " << name << " (" << input << "): Cycles\n\n"
           << w << "x" << h << ", the file's settings but the samples (adaptive sampling and denoising off unless "
           << "named). Each row is one run, timed from the command to its EXR (Blender's start-up included), in the "
           << "order of the table" << (f.repeat > 1 ? ", each " + std::to_string(f.repeat) + " times (the median)" : "")
           << ". PSNR, display-referred, against " << referenceText << ".\n\n"
           << "| spp | method | exact % | PSNR dB | SSIM | wall s | speed-up | the full render at this wall time |"
           << (adaptive.empty() ? "" : " adaptive sampling at this wall time |") << "\n"
           << "|---|---|---|---|---|---|---|---|" << (adaptive.empty() ? "" : "---|") << "\n";
  const std::vector<Point> fullByTime = ByTime(full), adaptiveByTime = ByTime(adaptive);
  for (Point& p : pts) {
    const Point* same = nullptr;
    for (const Point& q : full)
      if (q.config.spp == p.config.spp) same = &q;
    const bool dcm = p.config.method != "full" && p.config.method != "adaptive";
    const double fullAt = PsnrAtTime(fullByTime, p.timeTotalS), adaptiveAt = PsnrAtTime(adaptiveByTime, p.timeTotalS);
    if (dcm) {
      // The comparison a user makes: the other two ways to spend the same wall time.
      p.extra["full_psnr_at_time"] = fullAt;
      if (!adaptive.empty()) p.extra["adaptive_psnr_at_time"] = adaptiveAt;
    }
    *summary << "| " << p.config.spp << " | " << p.config.label.substr(0, p.config.label.rfind(" spp=")) << " | "
             << (std::isfinite(p.exactFraction) ? Fixed(100 * p.exactFraction, 2) : "adaptive") << " | "
             << Fixed(p.error.psnr, 2) << " | " << Fixed(p.error.ssim, 4) << " | " << Fixed(p.timeTotalS, 2) << " | "
             << (same && p.timeTotalS > 0 ? Fixed(same->timeTotalS / p.timeTotalS, 2) + "x" : "") << " | "
             << (p.config.method != "full" ? AtTimeCell(fullByTime, p, fullAt) : "") << " |"
             << (adaptive.empty() ? "" : " " + (dcm ? AtTimeCell(adaptiveByTime, p, adaptiveAt) : std::string()) + " |")
             << "\n";
  }
  *summary << "\nSpeed-up: the full render at the same samples (adaptive sampling: at its largest) over this run's "
              "wall time. The full render at this wall time: its PSNR interpolated in log time between the full "
              "renders around it, and this run's PSNR less it"
           << (adaptive.empty() ? "" : "; adaptive sampling at this wall time: the same between the adaptive runs")
           << ".\n\n";
  *inputJson = {{"input", input},
                {"scene", name},
                {"kind", "blend"},
                {"resolution", {w, h}},
                {"reference", f.reference.empty() ? "reference.exr" : f.reference},
                {"reference_spp", f.reference.empty() ? nlohmann::json(referenceSpp) : nlohmann::json(nullptr)},
                {"spp", spps},
                {"variants", variants},
                {"adaptive", f.adaptive},
                {"blender", blender}};
  for (auto& p : pts) points->push_back(std::move(p));
  return Status::Ok();
}

}  // namespace dcm::cli

#endif  // DCM_HAVE_PIPE

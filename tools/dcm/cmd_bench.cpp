// dcm bench: what accuracy costs in time. For each scene (rendered with the
// internal Embree tracer) or dense AOV EXR (when plugins/aov is built), renders
// or reads the full reference once, then sweeps the settings that trade
// accuracy for time (contrast threshold, minimum and elementary block size,
// supersampling, each enhancement on/off, the methods dcm/paper/guo) and runs
// the rivals (uniform grid + bilinear, uniform grid + joint bilateral
// upsampling guided by the provider's guides) at the same exact-pixel budgets.
// Writes bench.csv, bench.json and summary.md (the paper's tables beside ours,
// the goal check), error heat maps, and the plots (tools/bench/plot_tradeoff.py).
// A .blend input is measured by bench_cycles.cpp instead: Cycles' full render,
// `dcm blender` and adaptive sampling at each --spp, timed end to end.
//
// Builds only with the Embree plugin (like `dcm render`); AOV inputs only when
// plugins/aov is available.
#if __has_include("dcm/embree/embree_provider.h")

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "dcm/downsample.h"
#include "bench.h"
#include "bench_rivals.h"
#include "commands.h"
#include "common/image_io.h"
#include "common/metrics.h"
#include "common/progress.h"
#include "common/sample_map.h"
#include "common/output_guard.h"
#include "common/output_transaction.h"
#include "common/stats_json.h"
#include "common/elapsed.h"
#include "dcm/pipe/run_command.h"
#include "dcm/pipe/scratch_folder.h"
#include "dcm/reconstructor.h"
#include "dcm/embree/embree_provider.h"
#include "dcm/embree/scene_file.h"
#include "engine_flags.h"
#include "flag_checks.h"

#if __has_include("dcm/aov/aov_provider.h")
#include "dcm/aov/aov_provider.h"
#define DCM_BENCH_HAVE_AOV 1
#else
#define DCM_BENCH_HAVE_AOV 0
#endif

namespace dcm::cli {
namespace {

using pipe::ShellQuote;

namespace fs = std::filesystem;

/// An input: a scene file or a dense AOV EXR, with a provider factory.
struct Subject {
  std::string input, name, kind;
  int width = 0, height = 0;  ///< output resolution
  int defaultSs = 1;
  std::vector<std::string> effects;
  embree::Scene scene;  ///< scenes only (after --scale)
#if DCM_BENCH_HAVE_AOV
  aov::AovOptions aovOptions;
#endif
  /// By (supersampling, samples per pixel); spp 0 is the scene's own setting.
  std::map<std::pair<int, int>, std::unique_ptr<SampleProvider>> providers;
};

std::string Join(const std::vector<std::string>& v, const char* sep = ",") {
  std::string s;
  for (const auto& e : v) s += (s.empty() ? "" : sep) + e;
  return s;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

/// The provider at supersampling `ss` and `spp` estimates per pixel (0: the
/// scene's own). Noisy renders (spp > 0) use another seed than the scene's,
/// so that they are independent of a reference rendered with its seed.
Status GetProvider(Subject& s, int ss, SampleProvider** out, int spp = 0) {
  auto it = s.providers.find({ss, spp});
  if (it == s.providers.end()) {
    if (s.kind != "scene") return Status::Error(s.input + ": supersampling applies to scenes only");
    embree::Scene scene = s.scene;
    scene.render.supersampling = ss;
    if (spp > 0) {
      scene.render.samplesPerPixel = spp;
      scene.render.seed += uint32_t(spp);  // each spp its own random streams
    }
    std::unique_ptr<embree::EmbreeProvider> p;
    DCM_RETURN_IF_ERROR(embree::EmbreeProvider::Create(scene, &p));
    it = s.providers.emplace(std::pair{ss, spp}, std::move(p)).first;
  }
  *out = it->second.get();
  return Status::Ok();
}

/// `usage`: set when the flags do not fit the input (exit 2).
Status OpenSubject(const BenchFlags& f, const std::string& input, Subject* s, bool* usage) {
  s->input = input;
  s->name = fs::path(input).stem().string();
  if (EndsWith(input, ".exr")) {
#if DCM_BENCH_HAVE_AOV
    s->kind = "aov";
    aov::AovOptions o;
    DCM_RETURN_IF_ERROR(aov::ParsePreset(f.preset, &o.preset));
    for (const auto& m : f.maps) DCM_RETURN_IF_ERROR(aov::ParseMapping(m, &o.mappings));
    if (f.highlightLevel) o.highlightLevel = *f.highlightLevel;
    o.sparse = false;
    o.split = true;
    std::unique_ptr<aov::AovProvider> p;
    DCM_RETURN_IF_ERROR(aov::AovProvider::Open({input}, o, &p));
    if (!p->dense()) return Status::Error(input + ": dcm bench needs a dense AOV input (every pixel has a sample)");
    const auto caps = p->Capabilities();
    if (Status st = CheckDownsample(caps.width, caps.height, f.downsample, input + ":"); !st.ok()) {
      *usage = true;
      return st;
    }
    s->defaultSs = f.downsample;
    s->width = (caps.width + f.downsample - 1) / f.downsample;
    s->height = (caps.height + f.downsample - 1) / f.downsample;
    s->effects = {"aov"};
    s->providers.emplace(std::pair{f.downsample, 0}, std::move(p));
    return Status::Ok();
#else
    return Status::Error(input + ": AOV EXR inputs need plugins/aov (dcm_aov), which this build does not have; "
                                 "dcm bench takes scene files only");
#endif
  }
  s->kind = "scene";
  DCM_RETURN_IF_ERROR(embree::LoadSceneFile(input, &s->scene, f.overrides));
  const float scale = f.scale ? *f.scale : (f.quick ? 0.125f : 1.f);
  s->scene.camera.width = std::max(8, int(std::lround(float(s->scene.camera.width) * scale)));
  s->scene.camera.height = std::max(8, int(std::lround(float(s->scene.camera.height) * scale)));
  s->width = s->scene.camera.width;
  s->height = s->scene.camera.height;
  s->defaultSs = s->scene.render.supersampling;
  SampleProvider* p = nullptr;
  DCM_RETURN_IF_ERROR(GetProvider(*s, s->defaultSs, &p));
  s->effects = static_cast<embree::EmbreeProvider*>(p)->effects().Names();
  return Status::Ok();
}

/// The enhancement fields switched one at a time: off from dcm's defaults, on
/// from Guo's (the paper's three take the paper's value, dcm's own take dcm's).
struct Enhancement {
  const char* name;
  void (*off)(ReconstructionOptions*);
  void (*on)(ReconstructionOptions*);
};
const Enhancement kEnhancements[] = {
    {"thinObjects", [](ReconstructionOptions* o) { o->thinObjects = ThinObjectTest::kOff; },
     [](ReconstructionOptions* o) { o->thinObjects = ThinObjectTest::kNoneMatches; }},
    {"neighbourDirections", [](ReconstructionOptions* o) { o->neighbourDirections = 0; },
     [](ReconstructionOptions* o) { o->neighbourDirections = ReconstructionOptions{}.neighbourDirections; }},
    {"objectTest", [](ReconstructionOptions* o) { o->objectTest = ObjectTest::kObjectId; },
     [](ReconstructionOptions* o) { o->objectTest = ObjectTest::kObjectAndShader; }},
    {"textureSplit", [](ReconstructionOptions* o) { o->textureSplit = false; },
     [](ReconstructionOptions* o) { o->textureSplit = true; }},
    {"adaptiveBorders", [](ReconstructionOptions* o) { o->adaptiveBorders = false; },
     [](ReconstructionOptions* o) { o->adaptiveBorders = true; }},
    {"displayWeightedContrast", [](ReconstructionOptions* o) { o->contrastMetric = ContrastMetric::kMitchell; },
     [](ReconstructionOptions* o) { o->contrastMetric = ContrastMetric::kDisplayWeighted; }},
    {"crossingFill", [](ReconstructionOptions* o) { o->crossingFillReach = 0; },
     [](ReconstructionOptions* o) { o->crossingFillReach = ReconstructionOptions{}.crossingFillReach; }},
    {"smoothRefinement", [](ReconstructionOptions* o) { o->smoothRefinement = SmoothRefinement::kAlways; },
     [](ReconstructionOptions* o) { o->smoothRefinement = SmoothRefinement::kCentreProbe; }},
    {"finestCentreProbe", [](ReconstructionOptions* o) { o->finestCentreProbe = false; },
     [](ReconstructionOptions* o) { o->finestCentreProbe = true; }},
    {"firstOrderFromGuides", [](ReconstructionOptions* o) { o->firstOrderFromGuides = false; },
     [](ReconstructionOptions* o) { o->firstOrderFromGuides = true; }},
    {"probeLcShare", [](ReconstructionOptions* o) { o->probeLcShare = 0.f; },
     [](ReconstructionOptions* o) { o->probeLcShare = ReconstructionOptions{}.probeLcShare; }},
    {"simpleSurfaceChanges", [](ReconstructionOptions* o) { o->simpleSurfaceChanges = 2; },
     [](ReconstructionOptions* o) { o->simpleSurfaceChanges = ReconstructionOptions{}.simpleSurfaceChanges; }},
    {"fallbackShadingChanges", [](ReconstructionOptions* o) { o->fallbackShadingChanges = -1; },
     [](ReconstructionOptions* o) { o->fallbackShadingChanges = ReconstructionOptions{}.fallbackShadingChanges; }},
    {"objectOrShader", [](ReconstructionOptions* o) { o->objectTest = ObjectTest::kObjectAndShader; },
     [](ReconstructionOptions* o) { o->objectTest = ObjectTest::kObjectOrShader; }},
    {"checkerboard", [](ReconstructionOptions* o) { o->checkerboard = false; },
     [](ReconstructionOptions* o) { o->checkerboard = true; }},
    {"lazyEvaluation", [](ReconstructionOptions* o) { o->lazyEvaluation = false; },
     [](ReconstructionOptions* o) { o->lazyEvaluation = true; }},
};

ReconstructionOptions MethodOptions(const std::string& m) {
  if (m == "paper") return ReconstructionOptions::Paper();
  if (m == "guo") return ReconstructionOptions::Guo();
  return ReconstructionOptions{};
}

/// Every switch of the options (OptionsToJson plus the fields it leaves out).
nlohmann::json AllOptionsJson(const ReconstructionOptions& o) {
  nlohmann::json j = toolkit::OptionsToJson(o);
  j["adaptive_borders"] = o.adaptiveBorders;
  j["finest_centre_probe"] = o.finestCentreProbe;
  return j;
}
std::string OptionsKey(const ReconstructionOptions& o) { return AllOptionsJson(o).dump(); }

/// A method's default threshold for this much supersampling (the accuracy
/// sweeps' samples are not noisy).
float DefaultThreshold(const std::string& method, int supersampling) {
  ReconstructionOptions o = MethodOptions(method);
  o.downsample = supersampling;
  return ResolveSettings(o, ProviderCapabilities{}).contrastThreshold;
}

/// The label of a method's point at its default settings ("dcm t=0.14").
std::string DefaultLabel(const std::string& method, int supersampling) {
  return method + " t=" + Fmt("%g", double(DefaultThreshold(method, supersampling)));
}

/// The DCM-family points of the sweep, deduplicated (a point that belongs to
/// several sweeps is run once and lists them all).
std::vector<Config> SweepConfigs(const BenchFlags& f, const Subject& s) {
  std::vector<float> thresholds = f.thresholds;
  if (thresholds.empty())
    thresholds = f.quick ? std::vector<float>{0.03f, 0.06f, 0.12f, 0.3f}
                         : std::vector<float>{0.015f, 0.03f, 0.06f, 0.1f, 0.12f, 0.15f, 0.25f, 0.5f};
  const std::vector<int> minBlocks = f.quick ? std::vector<int>{2, 4, 8} : std::vector<int>{1, 2, 4, 8};
  const std::vector<int> blocks = f.quick ? std::vector<int>{8, 16, 32} : std::vector<int>{4, 8, 16, 32};
  std::vector<int> sss;
  if (s.kind == "scene") {
    sss = f.quick ? std::vector<int>{1, s.defaultSs > 1 ? s.defaultSs : 2} : std::vector<int>{1, 2, 4};
    if (std::find(sss.begin(), sss.end(), s.defaultSs) == sss.end()) sss.push_back(s.defaultSs);
    std::sort(sss.begin(), sss.end());
  }

  std::vector<Config> out;
  auto add = [&](Config c) {
    // The options as run: what a field is worth depends on the supersampling.
    c.options.downsample = c.supersampling;
    const std::string key = OptionsKey(c.options) + "#" + std::to_string(c.supersampling);
    for (auto& e : out) {
      if (OptionsKey(e.options) + "#" + std::to_string(e.supersampling) == key) {
        e.sweeps += "|" + c.sweeps;
        return;
      }
    }
    out.push_back(std::move(c));
  };
  auto base = [&](const std::string& method) {
    Config c;
    c.method = method;
    c.options = MethodOptions(method);
    c.options.threads = f.threads;
    c.supersampling = s.defaultSs;
    return c;
  };
  for (const char* m : {"dcm", "paper", "guo"}) {
    // The method's default threshold is always part of its sweep.
    std::vector<float> ts = thresholds;
    const float def = DefaultThreshold(m, s.defaultSs);
    if (std::find(ts.begin(), ts.end(), def) == ts.end()) ts.push_back(def);
    std::sort(ts.begin(), ts.end());
    for (float t : ts) {
      Config c = base(m);
      c.options.contrastThreshold = t;
      c.label = std::string(m) + " t=" + Fmt("%g", t);
      c.sweeps = "threshold";
      add(c);
    }
  }
  for (int mb : minBlocks) {
    Config c = base("dcm");
    c.options.minBlock = mb;
    c.label = "dcm min_block=" + std::to_string(mb);
    c.sweeps = "min_block";
    add(c);
  }
  for (int b : blocks) {
    Config c = base("dcm");
    c.options.elementaryBlock = b;  // noisy samples or not
    c.options.minBlock = std::min(c.options.minBlock, b);
    c.label = "dcm block=" + std::to_string(b);
    c.sweeps = "block";
    add(c);
  }
  for (int ss : sss) {
    Config c = base("dcm");
    c.supersampling = ss;
    c.label = "dcm ss=" + std::to_string(ss);
    c.sweeps = "supersampling";
    add(c);
  }
  for (const auto& e : kEnhancements) {
    Config off = base("dcm");
    e.off(&off.options);
    off.label = std::string("dcm -") + e.name;
    off.sweeps = "enhancement";
    add(off);
    Config on = base("guo");
    e.on(&on.options);
    on.label = std::string("guo +") + e.name;
    on.sweeps = "enhancement";
    add(on);
  }
  return out;
}

/// The noise sweep (--spp): at each number of estimates per pixel, the full
/// noisy render, dcm (noise weighed), dcm with the noise taken at face value,
/// and the paper's method as written.
std::vector<Config> NoiseConfigs(const BenchFlags& f, const Subject& s) {
  std::vector<Config> out;
  for (int spp : f.spp) {
    auto add = [&](const std::string& method, const std::string& label, ReconstructionOptions o) {
      Config c;
      c.method = method;
      c.label = label + " spp=" + std::to_string(spp);
      c.sweeps = "noise";
      c.options = o;
      c.options.threads = f.threads;
      c.supersampling = c.options.downsample = s.defaultSs;
      c.spp = spp;
      out.push_back(std::move(c));
    };
    ReconstructionOptions full;
    full.fullEvaluation = true;
    add("full", "full", full);
    add("dcm", "dcm", MethodOptions("dcm"));
    ReconstructionOptions literal = MethodOptions("dcm");
    literal.noiseSignificance = 0.f;
    add("dcm", "dcm noise ignored", literal);
    add("paper", "paper", MethodOptions("paper"));
  }
  return out;
}

/// Output-resolution image of a working image.
std::vector<RGB> ToOutput(const std::vector<RGB>& work, int w, int h, int ds, int* ow, int* oh) {
  if (ds <= 1) {
    *ow = w;
    *oh = h;
    return work;
  }
  return dcm::BoxDownsample(work, w, h, ds, ow, oh);
}

nlohmann::json PointToJson(const Point& p) {
  const auto& o = p.config.options;
  nlohmann::json j = {{"input", p.input},
                      {"scene", p.scene},
                      {"method", p.config.method},
                      {"label", p.config.label},
                      {"sweeps", p.config.sweeps},
                      {"supersampling", p.config.supersampling},
                      {"spp", p.config.spp},
                      {"exact_pixels", p.exactPixels},
                      {"total_pixels", p.totalPixels},
                      {"exact_fraction", p.exactFraction},
                      {"time_illum_s", p.timeIllumS},
                      {"time_guides_s", p.timeGuidesS},
                      {"time_engine_s", p.timeEngineS},
                      {"time_total_s", p.timeTotalS},
                      {"psnr_db", p.error.psnr},
                      {"rmse", p.error.rmse},
                      {"relmse", p.error.relmse},
                      {"ssim", p.error.ssim},
                      {"non_finite", p.error.nonFinite}};
  if (p.rival) {
    j["budget_of"] = p.config.budgetOf;
  } else if (p.config.method != "full" && !p.external) {
    j["options"] = AllOptionsJson(o);
  }
  j.update(p.extra);
  return j;
}

const char* kCsvHeader =
    "scene,input,method,label,sweeps,threshold,elementary_block,min_block,supersampling,thin_objects,object_test,"
    "texture_split,adaptive_borders,smooth_refinement,finest_centre_probe,lazy_evaluation,budget_of,exact_pixels,"
    "total_pixels,exact_fraction,time_illum_s,time_guides_s,time_engine_s,time_total_s,psnr_db,rmse,relmse,ssim,spp\n";

std::string CsvNum(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string CsvQuote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string PointToCsv(const Point& p) {
  const auto& o = p.config.options;
  const bool engine = !p.rival && p.config.method != "full" && !p.external;
  std::ostringstream s;
  s << CsvQuote(p.scene) << ',' << CsvQuote(p.input) << ',' << p.config.method << ',' << CsvQuote(p.config.label)
    << ',' << p.config.sweeps << ',';
  if (engine) {
    s << CsvNum(p.settings.contrastThreshold) << ',' << p.settings.elementaryBlock << ',' << o.minBlock << ',';
  } else {
    s << ",,,";
  }
  s << p.config.supersampling << ',';
  if (engine) {
    s << ToString(p.settings.thinObjects) << ',' << ToString(o.objectTest) << ',' << int(o.textureSplit) << ','
      << int(o.adaptiveBorders) << ',' << ToString(p.settings.smoothRefinement) << ',' << int(o.finestCentreProbe) << ','
      << int(o.lazyEvaluation) << ',';
  } else {
    s << ",,,,,,,";
  }
  s << CsvQuote(p.config.budgetOf) << ',' << p.exactPixels << ',' << p.totalPixels << ',' << CsvNum(p.exactFraction)
    << ',' << CsvNum(p.timeIllumS) << ',' << CsvNum(p.timeGuidesS) << ',' << CsvNum(p.timeEngineS) << ','
    << CsvNum(p.timeTotalS) << ',' << CsvNum(p.error.psnr) << ',' << CsvNum(p.error.rmse) << ','
    << CsvNum(p.error.relmse) << ',' << CsvNum(p.error.ssim) << ',' << p.config.spp << '\n';
  return s.str();
}

Status WriteText(const std::string& path, const std::string& text) {
  return toolkit::WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream o(tmp, std::ios::binary);
    o << text;
    o.close();
    if (!o) return Status::Error("cannot write '" + tmp + "'");
    return Status::Ok();
  });
}

const Point* Find(const std::vector<Point>& pts, const std::string& label) {
  for (const auto& p : pts)
    if (p.config.label == label) return &p;
  return nullptr;
}

/// Total time a rival needs to reach `psnr`, interpolated in (log time, PSNR)
/// along its budget sweep; nullopt when no point of the sweep reaches it.
std::optional<double> TimeToReach(std::vector<const Point*> curve, double psnr) {
  std::sort(curve.begin(), curve.end(), [](const Point* a, const Point* b) { return a->exactPixels < b->exactPixels; });
  for (size_t k = 0; k < curve.size(); ++k) {
    if (curve[k]->error.psnr >= psnr) {
      if (k == 0) return curve[k]->timeTotalS;
      const Point* a = curve[k - 1];
      const Point* b = curve[k];
      const double t = (psnr - a->error.psnr) / (b->error.psnr - a->error.psnr);
      const double la = std::log(std::max(a->timeTotalS, 1e-9)), lb = std::log(std::max(b->timeTotalS, 1e-9));
      return std::exp(la + t * (lb - la));
    }
  }
  return std::nullopt;
}

struct PaperRow {
  const char* ours;  ///< our label, or "full"
  const char* name;
  const char* pixels;
  const char* timeDcm;
  const char* timeIllum;
};

/// The paper's tables (Scheel et al. 2001, section 4), keyed by our scene name.
std::vector<PaperRow> PaperTable(const std::string& scene, std::string* title) {
  if (scene == "room" || scene == "room-paper") {
    *title = "Baseline vs DCM (paper Figure 4 scene; the paper's DCM row is Guo's method)";
    return {{"full", "Baseline", "100 %", "–", "3672 s"},
            {"guo", "DCM (Guo)", "5.9 %", "43 s", "245 s"},
            {"paper", "", "", "", ""},
            {"dcm", "", "", "", ""}};
  }
  if (scene == "cactus") {
    *title = "Guo vs thin-object extension (paper Figure 7 scene)";
    return {{"guo", "Guo", "7.28 %", "70.82 s", "52.38 s"},
            {"guo +thinObjects", "New", "8.17 %", "94.16 s", "55.42 s"},
            {"dcm", "", "", "", ""}};
  }
  if (scene == "parquet") {
    *title = "Guo vs texture extension (paper Figure 6 scene)";
    return {{"guo", "Guo", "17.8 %", "40.66 s", "27.93 s"},
            {"guo +textureSplit", "New", "3.6 %", "42.64 s", "7.08 s"},
            {"dcm", "", "", "", ""}};
  }
  return {};
}

std::string CpuName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      auto c = line.find(':');
      if (c != std::string::npos) return line.substr(c + 2);
    }
  }
  return "unknown";
}

std::string FindPlotScript(const BenchFlags& f) {
  std::vector<fs::path> candidates;
  if (!f.plotScript.empty()) return f.plotScript;
  if (const char* e = std::getenv("DCM_PLOT_SCRIPT")) candidates.emplace_back(e);
  // The source tree this binary was built from (absolute, unlike __FILE__ under ccache's base_dir).
  candidates.push_back(fs::path(DCM_SOURCE_DIR) / "tools" / "bench" / "plot_tradeoff.py");
  candidates.push_back(fs::path("tools/bench/plot_tradeoff.py"));
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(c, ec)) return c.string();
  }
  return "";
}

int Fail(const Status& st, int code = kExitFailure) {
  std::cerr << "dcm bench: error: " << st.message() << "\n";
  return code;
}

int RunBench(const BenchFlags& f) {
  std::vector<toolkit::FileArg> inputs;
  for (const auto& in : f.inputs) inputs.push_back({"input", in});
  if (!f.reference.empty()) inputs.push_back({"--reference", f.reference});
  std::vector<toolkit::FileArg> outputs;
  for (const char* name : {"bench.csv", "bench.json", "summary.md", "*.png"})
    outputs.push_back({"--out", (fs::path(f.out) / name).string(), std::string(name).find('*') != std::string::npos});
  // .blend inputs: their renders and dcm's stats in OUT/STEM/.
  const size_t blends = size_t(std::count_if(f.inputs.begin(), f.inputs.end(), IsBlendInput));
  auto usageError = [](const std::string& why) {
    std::cerr << "dcm bench: error: " << why << "\n";
    return kExitUsage;
  };
  if (blends == 0) {
    for (const auto& [given, flag] : {std::pair{!f.reference.empty(), "--reference"}, {!f.adaptive.empty(), "--adaptive"},
                                      {!f.variants.empty(), "--variant"}, {f.renderThreads != 0, "--render-threads"},
                                      {f.repeat != 1, "--repeat"}})
      if (given) return usageError(std::string(flag) + " applies to .blend inputs only");
  } else {
#ifndef DCM_HAVE_PIPE
    return usageError("this dcm was built without plugins/pipe: .blend inputs need it");
#endif
    if (f.spp.empty()) return usageError(".blend inputs need --spp: the samples per pixel to compare at (e.g. --spp 64,512)");
    if (!f.reference.empty() && blends > 1) return usageError("--reference needs a single .blend input");
    std::vector<std::string> stems;
    for (const auto& in : f.inputs) {
      if (!IsBlendInput(in)) continue;
      const std::string stem = fs::path(in).stem().string();
      if (std::find(stems.begin(), stems.end(), stem) != stems.end())
        return usageError("two .blend inputs named '" + stem + "': their renders would share --out's folder " + stem);
      stems.push_back(stem);
      outputs.push_back({"--out", (fs::path(f.out) / stem / "*").string(), true});
    }
  }
  if (Status st = toolkit::CheckOutputs(inputs, outputs); !st.ok()) {
    std::cerr << "dcm bench: error: " << st.message() << "\n";
    return kExitUsage;
  }
  std::error_code ec;
  // Every output of the run (tables, error maps, plots) appears at the end,
  // together, or none does; a folder --out that the run made goes with them.
  toolkit::OutputTransaction transaction;
  if (Status st = transaction.MakeFolder(f.out); !st.ok()) return Fail(Status::Error("--out: " + st.message()));
  const bool talk = !f.quiet;
  const auto tBench = std::chrono::steady_clock::now();

  std::vector<Point> all;
  nlohmann::json inputsJson = nlohmann::json::array();
  std::ostringstream summary;
  summary << "# dcm bench summary\n\n";
  summary << "Machine: " << CpuName() << ", " << std::thread::hardware_concurrency()
          << " hardware threads; engine threads " << (f.threads ? std::to_string(f.threads) : "all")
          << (f.quick ? "; --quick" : "") << ".\n\n";

  for (const std::string& input : f.inputs) {
#ifdef DCM_HAVE_PIPE
    if (IsBlendInput(input)) {
      const std::string dir = (fs::path(f.out) / fs::path(input).stem()).string();
      if (Status st = transaction.MakeFolder(dir); !st.ok()) return Fail(Status::Error("--out: " + st.message()));
      std::vector<Point> pts;
      nlohmann::json ij;
      if (Status st = MeasureCycles(f, input, dir, &pts, &summary, &ij); !st.ok()) return Fail(st);
      inputsJson.push_back(ij);
      for (auto& p : pts) all.push_back(std::move(p));
      continue;
    }
#endif
    Subject s;
    bool usage = false;
    if (Status st = OpenSubject(f, input, &s, &usage); !st.ok()) return Fail(st, usage ? kExitUsage : kExitFailure);
    if (talk) {
      std::cerr << "dcm bench: " << input << ": " << s.width << "x" << s.height << " (supersampling " << s.defaultSs
                << "), effects " << Join(s.effects) << "\n";
    }
    // --spp: the noise sweep against a reference of many estimates per pixel.
    const bool noise = !f.spp.empty();
    int referenceSpp = 0;
    if (noise) {
      if (s.kind != "scene") return Fail(Status::Error(input + ": --spp applies to scene files only"));
      referenceSpp = f.referenceSpp ? *f.referenceSpp : 16 * *std::max_element(f.spp.begin(), f.spp.end());
      if (std::find(f.spp.begin(), f.spp.end(), referenceSpp) != f.spp.end())
        return Fail(Status::Error("--reference-spp " + std::to_string(referenceSpp) + " is also in --spp"));
    }
    SampleProvider* provider = nullptr;
    if (Status st = GetProvider(s, s.defaultSs, &provider, referenceSpp); !st.ok()) return Fail(st);

    // The full reference, once.
    Point full;
    full.input = input;
    full.scene = s.name;
    full.config.method = "full";
    full.config.label = "full";
    full.config.sweeps = "baseline";
    full.config.supersampling = s.defaultSs;
    full.config.spp = referenceSpp;
    full.config.options.fullEvaluation = true;
    full.config.options.threads = f.threads;
    full.config.options.downsample = s.defaultSs;
    std::vector<RGB> reference;
    {
      if (talk) std::cerr << "dcm bench: " << s.name << ": full reference ...\n";
      Reconstruction rec;
      const auto t0 = std::chrono::steady_clock::now();
      if (Status st = Reconstruct(*provider, full.config.options, &rec); !st.ok()) return Fail(st);
      full.timeTotalS = toolkit::SecondsSince(t0);
      full.exactPixels = rec.stats.exactPixels;
      full.totalPixels = rec.stats.totalPixels;
      full.exactFraction = rec.stats.exactFraction();
      full.timeIllumS = rec.stats.timeProviderS;
      full.timeGuidesS = rec.stats.timeGuidesS;
      full.timeEngineS = rec.stats.timeEngineS;
      reference = std::move(rec.image);
      if (rec.width != s.width || rec.height != s.height)
        return Fail(Status::Error(input + ": reference has an unexpected size"));
      full.error = toolkit::Compare(reference, reference, s.width, s.height);
    }
    std::vector<Point> pts;
    pts.push_back(full);
    if (talk) {
      std::cerr << "dcm bench: " << s.name << ": full: illumination " << Fmt("%.3f", full.timeIllumS) << " s, total "
                << Fmt("%.3f", full.timeTotalS) << " s\n";
    }

    auto measure = [&](const Config& c, Point* p, std::vector<RGB>* image) -> Status {
      p->input = input;
      p->scene = s.name;
      p->config = c;
      SampleProvider* prov = nullptr;
      DCM_RETURN_IF_ERROR(GetProvider(s, c.supersampling, &prov, c.spp));
      int ow = 0, oh = 0;
      if (c.method == "bilinear" || c.method == "jbu") {
        p->rival = true;
        bench::RivalResult r;
        DCM_RETURN_IF_ERROR(bench::RunRival(
            *prov, c.method == "jbu" ? bench::Upsampler::kJointBilateral : bench::Upsampler::kBilinear, c.budget,
            f.threads, &r, f.jbu));
        const auto t0 = std::chrono::steady_clock::now();
        *image = ToOutput(r.workImage, r.width, r.height, c.supersampling, &ow, &oh);
        const double tDown = toolkit::SecondsSince(t0);
        p->exactPixels = r.exactPixels;
        p->totalPixels = int64_t(r.width) * r.height;
        p->timeIllumS = r.timeIllumS;
        p->timeGuidesS = r.timeGuidesS;
        p->timeEngineS = r.timeEngineS + tDown;
        p->timeTotalS = r.wallS + tDown;
      } else {
        ReconstructionOptions o = c.options;
        o.downsample = c.supersampling;
        Reconstruction rec;
        const auto t0 = std::chrono::steady_clock::now();
        DCM_RETURN_IF_ERROR(Reconstruct(*prov, o, &rec));
        p->timeTotalS = toolkit::SecondsSince(t0);
        p->exactPixels = rec.stats.exactPixels;
        p->totalPixels = rec.stats.totalPixels;
        p->timeIllumS = rec.stats.timeProviderS;
        p->timeGuidesS = rec.stats.timeGuidesS;
        p->timeEngineS = rec.stats.timeEngineS;
        p->settings = rec.stats.settings;
        ow = rec.width;
        oh = rec.height;
        *image = std::move(rec.image);
      }
      if (ow != s.width || oh != s.height) return Status::Error(input + ": " + c.label + ": unexpected output size");
      p->exactFraction = p->totalPixels ? double(p->exactPixels) / double(p->totalPixels) : 0.0;
      p->error = toolkit::Compare(*image, reference, s.width, s.height);
      return Status::Ok();
    };

    std::vector<Config> configs = noise ? NoiseConfigs(f, s) : SweepConfigs(f, s);
    // Rival budgets: those of the dcm threshold sweep, plus 25 % and 50 %.
    size_t nDcmThresholds = 0;
    for (const Config& c : configs)
      if (c.method == "dcm" && c.sweeps.find("threshold") != std::string::npos) ++nDcmThresholds;
    const size_t nTotal = configs.size() + (noise ? 0 : 2 * (nDcmThresholds + 2));
    size_t done = 0;
    auto report = [&](const Point& p) {
      ++done;
      if (!talk) return;
      std::cerr << "dcm bench: " << s.name << " [" << done << "/" << nTotal << "] " << p.config.label << ": exact "
                << Fmt("%.2f", 100.0 * p.exactFraction) << " %, PSNR " << Fmt("%.2f", p.error.psnr) << " dB, total "
                << Fmt("%.3f", p.timeTotalS) << " s";
      if (f.verbose) {
        std::cerr << " (illumination " << Fmt("%.3f", p.timeIllumS) << " s, guides " << Fmt("%.3f", p.timeGuidesS)
                  << " s, engine " << Fmt("%.3f", p.timeEngineS) << " s; " << p.exactPixels << " of "
                  << p.totalPixels << " pixels; SSIM " << Fmt("%.4f", p.error.ssim) << ")";
      }
      std::cerr << "\n";
    };
    std::vector<RGB> dcmDefaultImage;
    const std::string defaultLabel = DefaultLabel("dcm", s.defaultSs);
    for (const Config& c : configs) {
      Point p;
      std::vector<RGB> img;
      if (Status st = measure(c, &p, &img); !st.ok()) return Fail(st);
      if (c.label == defaultLabel) dcmDefaultImage = std::move(img);
      report(p);
      pts.push_back(std::move(p));
    }
    if (noise) {
      summary << "## " << s.name << " (" << input << "): noise\n\n"
              << s.width << "x" << s.height << ", supersampling " << s.defaultSs << ", effects "
              << Join(s.effects, ", ") << "; shadow rays " << s.scene.render.shadowRays << ", glossy rays "
              << s.scene.render.glossyRays << ", indirect " << s.scene.render.indirectBounces << " bounces x "
              << s.scene.render.indirectRays << " rays per estimate. Reference: " << referenceSpp
              << " estimates per pixel (" << Fmt("%.1f", full.timeTotalS) << " s), another seed.\n\n"
              << "| spp | method | exact % | PSNR dB | relMSE | SSIM | total s | vs full noisy |\n"
              << "|---|---|---|---|---|---|---|---|\n";
      for (const Point& p : pts) {
        if (p.config.sweeps != "noise") continue;
        const Point* noisy = Find(pts, "full spp=" + std::to_string(p.config.spp));
        summary << "| " << p.config.spp << " | " << p.config.label.substr(0, p.config.label.rfind(" spp=")) << " | "
                << Fmt("%.1f", 100 * p.exactFraction) << " | " << Fmt("%.2f", p.error.psnr) << " | "
                << Fmt("%.3g", p.error.relmse) << " | " << Fmt("%.4f", p.error.ssim) << " | "
                << Fmt("%.3f", p.timeTotalS) << " | "
                << (noisy ? Fmt("%+.2f dB", p.error.psnr - noisy->error.psnr) : std::string("")) << " |\n";
      }
      summary << "\n";
      inputsJson.push_back({{"input", input},
                            {"scene", s.name},
                            {"kind", s.kind},
                            {"resolution", {s.width, s.height}},
                            {"supersampling", s.defaultSs},
                            {"effects", s.effects},
                            {"reference_spp", referenceSpp}});
      for (auto& p : pts) all.push_back(std::move(p));
      continue;
    }
    // Rivals at the same budgets.
    std::vector<std::pair<int64_t, std::string>> budgets;
    for (const auto& p : pts) {
      if (p.config.method == "dcm" && p.config.sweeps.find("threshold") != std::string::npos)
        budgets.push_back({p.exactPixels, p.config.label});
    }
    for (double frac : {0.25, 0.5}) {
      budgets.push_back({int64_t(std::llround(frac * double(full.totalPixels))), Fmt("%g", 100 * frac) + " %"});
    }
    std::vector<RGB> rivalImages[2];
    for (const auto& [budget, of] : budgets) {
      for (const char* m : {"bilinear", "jbu"}) {
        Config c;
        c.method = m;
        c.label = std::string(m) + " @" + of;
        c.sweeps = "rival";
        c.supersampling = s.defaultSs;
        c.budget = budget;
        c.budgetOf = of;
        Point p;
        std::vector<RGB> img;
        if (Status st = measure(c, &p, &img); !st.ok()) return Fail(st);
        if (of == defaultLabel) rivalImages[std::string(m) == "jbu" ? 1 : 0] = std::move(img);
        report(p);
        pts.push_back(std::move(p));
      }
    }

    // Error heat maps: dcm's default and both rivals at its budget.
    std::vector<std::string> maps;
    auto writeMap = [&](const std::string& what, const std::vector<RGB>& img) -> Status {
      if (img.empty()) return Status::Ok();
      const std::string path = (fs::path(f.out) / (s.name + "_error_" + what + ".png")).string();
      DCM_RETURN_IF_ERROR(toolkit::WriteErrorMap(path, img, reference, s.width, s.height));
      maps.push_back(fs::path(path).filename().string());
      return Status::Ok();
    };
    if (Status st = writeMap("dcm", dcmDefaultImage); !st.ok()) return Fail(st);
    if (Status st = writeMap("bilinear", rivalImages[0]); !st.ok()) return Fail(st);
    if (Status st = writeMap("jbu", rivalImages[1]); !st.ok()) return Fail(st);

    // The goal: at the default settings DCM beats both rivals by >= 3 dB at its
    // budget, and at equal error needs less total time than any of them.
    nlohmann::json goal;
    summary << "## " << s.name << " (" << input << ")\n\n"
            << s.width << "x" << s.height << ", supersampling " << s.defaultSs << " (working "
            << s.width * s.defaultSs << "x" << s.height * s.defaultSs << "), effects " << Join(s.effects, ", ")
            << ". Full reference: illumination " << Fmt("%.2f", full.timeIllumS) << " s, total "
            << Fmt("%.2f", full.timeTotalS) << " s.\n\n";
    if (const Point* d = Find(pts, defaultLabel)) {
      summary << "Equal budget (dcm default, " << Fmt("%.2f", 100 * d->exactFraction) << " % exact):\n\n"
              << "| method | exact % | PSNR dB | relMSE | SSIM | total s | DCM margin dB |\n|---|---|---|---|---|---|---|\n";
      summary << "| dcm | " << Fmt("%.2f", 100 * d->exactFraction) << " | " << Fmt("%.2f", d->error.psnr) << " | "
              << Fmt("%.3g", d->error.relmse) << " | " << Fmt("%.4f", d->error.ssim) << " | "
              << Fmt("%.3f", d->timeTotalS) << " | |\n";
      bool budgetGoal = true;
      bool timeGoal = true;
      std::ostringstream timeLines;
      for (const char* m : {"bilinear", "jbu"}) {
        const Point* r = Find(pts, std::string(m) + " @" + defaultLabel);
        if (!r) continue;
        const double margin = d->error.psnr - r->error.psnr;
        budgetGoal = budgetGoal && margin >= 3.0;
        summary << "| " << m << " | " << Fmt("%.2f", 100 * r->exactFraction) << " | " << Fmt("%.2f", r->error.psnr)
                << " | " << Fmt("%.3g", r->error.relmse) << " | " << Fmt("%.4f", r->error.ssim) << " | "
                << Fmt("%.3f", r->timeTotalS) << " | " << Fmt("%+.2f", margin) << " |\n";
        goal[std::string("margin_db_") + m] = margin;
        std::vector<const Point*> curve;
        for (const auto& q : pts)
          if (q.config.method == m) curve.push_back(&q);
        const auto t = TimeToReach(curve, d->error.psnr);
        double maxT = 0, maxFrac = 0, maxPsnr = 0;
        for (const Point* q : curve) {
          if (q->exactFraction > maxFrac) {
            maxFrac = q->exactFraction;
            maxT = q->timeTotalS;
            maxPsnr = q->error.psnr;
          }
        }
        if (t) {
          timeGoal = timeGoal && d->timeTotalS < *t;
          goal[std::string("time_to_equal_error_s_") + m] = *t;
          timeLines << "- " << m << " reaches " << Fmt("%.2f", d->error.psnr) << " dB at about " << Fmt("%.3f", *t)
                    << " s total (interpolated along its budget sweep); dcm takes " << Fmt("%.3f", d->timeTotalS)
                    << " s.\n";
        } else {
          // Not reached in the sweep: dcm wins on time only if it is faster
          // than the rival's largest budget (which is still worse).
          timeGoal = timeGoal && d->timeTotalS < maxT;
          goal[std::string("time_to_equal_error_s_") + m] = nullptr;
          timeLines << "- " << m << " does not reach " << Fmt("%.2f", d->error.psnr) << " dB within the sweep: at "
                    << Fmt("%.0f", 100 * maxFrac) << " % exact pixels it has " << Fmt("%.2f", maxPsnr) << " dB in "
                    << Fmt("%.3f", maxT) << " s; dcm takes " << Fmt("%.3f", d->timeTotalS) << " s.\n";
        }
      }
      timeGoal = timeGoal && d->timeTotalS < full.timeTotalS;
      timeLines << "- the full render (exact) takes " << Fmt("%.3f", full.timeTotalS) << " s.\n";
      goal["dcm_label"] = defaultLabel;
      goal["dcm_psnr_db"] = d->error.psnr;
      goal["dcm_exact_fraction"] = d->exactFraction;
      goal["dcm_time_total_s"] = d->timeTotalS;
      goal["beats_rivals_by_3db"] = budgetGoal;
      goal["faster_at_equal_error"] = timeGoal;
      summary << "\nGoal, >= 3 dB over both rivals at equal budget: **" << (budgetGoal ? "holds" : "fails")
              << "**.\n\nEqual error (" << Fmt("%.2f", d->error.psnr) << " dB):\n\n"
              << timeLines.str() << "\nGoal, less total time than any rival at equal error: **"
              << (timeGoal ? "holds" : "fails") << "**.\n\n";
    }
    std::string title;
    const auto table = PaperTable(s.name, &title);
    if (!table.empty()) {
      summary << "### " << title << "\n\n"
              << "| method | paper: pixels | paper: time DCM | paper: time illum | ours: method | ours: pixels | "
                 "ours: time DCM (engine) | ours: time guides | ours: time illum | ours: total | ours: PSNR dB |\n"
              << "|---|---|---|---|---|---|---|---|---|---|---|\n";
      for (const auto& row : table) {
        const std::string ours = row.ours;
        const Point* p = Find(pts, ours == "dcm" || ours == "paper" || ours == "guo" ? DefaultLabel(ours, s.defaultSs) : ours);
        if (!p) continue;
        summary << "| " << row.name << " | " << row.pixels << " | " << row.timeDcm << " | " << row.timeIllum << " | "
                << p->config.label << " | " << Fmt("%.2f", 100 * p->exactFraction) << " % | "
                << (p->config.method == "full" ? std::string("–") : Fmt("%.3f", p->timeEngineS) + " s") << " | "
                << Fmt("%.3f", p->timeGuidesS) << " s | " << Fmt("%.3f", p->timeIllumS) << " s | "
                << Fmt("%.3f", p->timeTotalS) << " s | "
                << (std::isfinite(p->error.psnr) ? Fmt("%.2f", p->error.psnr) : std::string("exact")) << " |\n";
      }
      summary << "\n";
    }

    nlohmann::json ij = {{"input", input},
                         {"scene", s.name},
                         {"kind", s.kind},
                         {"resolution", {s.width, s.height}},
                         {"supersampling", s.defaultSs},
                         {"effects", s.effects},
                         {"error_maps", maps},
                         {"goal", goal}};
    if (s.kind == "scene") {
      ij["shadow_rays"] = s.scene.render.shadowRays;
      ij["glossy_rays"] = s.scene.render.glossyRays;
    }
    inputsJson.push_back(ij);
    for (auto& p : pts) all.push_back(std::move(p));
  }

  // CSV and JSON.
  std::string csv = kCsvHeader;
  nlohmann::json points = nlohmann::json::array();
  for (const auto& p : all) {
    csv += PointToCsv(p);
    points.push_back(PointToJson(p));
  }
  const std::string csvPath = (fs::path(f.out) / "bench.csv").string();
  if (Status st = WriteText(csvPath, csv); !st.ok()) return Fail(st);

  // Plots: the script reads a copy of the CSV and draws in a scratch folder
  // (removed even if dcm is killed meanwhile); the PNGs join the transaction.
  std::vector<std::string> plots;
  std::string plotNote;
  if (!f.noPlots) {
    const std::string script = FindPlotScript(f);
    std::unique_ptr<pipe::ScratchFolder> staging;
    if (script.empty()) {
      plotNote = "plot script tools/bench/plot_tradeoff.py not found (--plot-script)";
    } else if (Status st = pipe::ScratchFolder::Make("dcm-bench-plots", &staging); !st.ok()) {
      return Fail(st);
    } else {
      const std::string stagedCsv = staging->path() + "/bench.csv";
      std::ofstream(stagedCsv, std::ios::binary) << csv;
      const std::string cmd = ShellQuote(f.python) + " " + ShellQuote(script) + " " + ShellQuote(stagedCsv) + " " +
                              ShellQuote(staging->path()) + (f.quiet ? " --quiet" : "");
      if (talk) std::cerr << "dcm bench: plotting: " << cmd << "\n";
      const int rc = std::system(cmd.c_str());
      if (rc != 0) plotNote = "plot command failed (exit " + std::to_string(rc) + "): " + cmd;
    }
    if (!plotNote.empty() && !f.quiet) std::cerr << "dcm bench: warning: " << plotNote << "\n";
    for (const auto& ij : inputsJson) {
      for (const char* kind : {"psnr_vs_time", "psnr_vs_exact", "noise", "cycles"}) {
        const std::string name = ij["scene"].get<std::string>() + "_" + kind + ".png";
        if (!staging || !fs::is_regular_file(fs::path(staging->path()) / name, ec)) continue;
        const fs::path from = fs::path(staging->path()) / name;
        Status st = toolkit::WriteAtomically((fs::path(f.out) / name).string(), [&](const std::string& tmp) {
          std::error_code cec;
          fs::copy_file(from, tmp, fs::copy_options::overwrite_existing, cec);
          return cec ? Status::Error("cannot copy the plot " + from.string() + ": " + cec.message()) : Status::Ok();
        });
        if (!st.ok()) return Fail(st);
        plots.push_back(name);
      }
    }
  }

  nlohmann::json j = {{"tool", "dcm bench"},
                      {"quick", f.quick},
                      {"scale", f.scale ? double(*f.scale) : (f.quick ? 0.125 : 1.0)},
                      {"machine", {{"cpu", CpuName()}, {"hardware_threads", std::thread::hardware_concurrency()}}},
                      {"threads", f.threads},
                      {"inputs", inputsJson},
                      {"points", points},
                      {"plots", plots},
                      {"plot_note", plotNote},
                      {"time_s", toolkit::SecondsSince(tBench)}};
  if (Status st = toolkit::WriteJson((fs::path(f.out) / "bench.json").string(), j); !st.ok()) return Fail(st);
  if (Status st = WriteText((fs::path(f.out) / "summary.md").string(), summary.str()); !st.ok()) return Fail(st);
  if (Status st = transaction.Commit(); !st.ok()) return Fail(st);
  if (!f.quiet) std::cout << summary.str();
  if (talk) {
    std::cout << "dcm bench: " << all.size() << " points in " << Fmt("%.1f", toolkit::SecondsSince(tBench)) << " s; wrote "
              << f.out << "/{bench.csv,bench.json,summary.md}\n";
  }
  return kExitOk;
}

Registration reg(
    "bench", "What accuracy costs in time: sweeps, rivals at equal budget, the paper's tables, plots",
    [](CLI::App* app) -> std::function<int()> {
      auto f = std::make_shared<BenchFlags>();
      app->option_defaults()->group(kGroupIo);
      app->add_option("inputs", f->inputs,
                      DCM_BENCH_HAVE_AOV ? "scene files (JSON), dense AOV EXRs or .blend files (Cycles, with --spp)"
                                         : "scene files (JSON) or .blend files (Cycles, with --spp)")
          ->required();
      app->add_option("--out", f->out, "output folder (bench.csv, bench.json, summary.md, PNGs)")->required();
      app->add_option("--scale", f->scale, "scale the scenes' resolution (default 1, 0.125 with --quick)")
          ->transform(FiniteNumber(1e-3, 4));
      app->add_option("--set", f->overrides,
                      "scenes: override a setting before the scene is read, KEY.PATH=JSON (repeatable; as dcm render)")
          ->allow_extra_args(false);
      app->add_flag("--no-plots", f->noPlots, "do not run the plot script");
      app->add_option("--python", f->python, "Python with matplotlib")->capture_default_str();
      app->add_option("--plot-script", f->plotScript, "the plot script (default tools/bench/plot_tradeoff.py)");
#if DCM_BENCH_HAVE_AOV
      app->add_option("--preset", f->preset, "AOV inputs: channel names, generic or blender")
          ->check(CLI::IsMember({"generic", "blender"}))
          ->capture_default_str();
      app->add_option("--map", f->maps, "AOV inputs: ROLE=CHANNEL (as dcm reconstruct)");
      app->add_option("--downsample", f->downsample,
                      "AOV inputs: supersampled N times per axis (their size a multiple of N)")
          ->transform(Integer(1, 16))
          ->capture_default_str();
#endif
      app->option_defaults()->group(kGroupQuality);
      app->add_flag("--quick", f->quick, "tiny size (scale 0.125) and few sweep points: a smoke test");
      app->add_option("--thresholds", f->thresholds, "contrast thresholds of the sweep")
          ->delimiter(',')
          ->transform(FiniteNumber(0));
      app->add_option("--jbu-spatial-sigma", f->jbu.spatialSigma,
                      "joint bilateral rival: spatial Gaussian sigma in grid spacings (Kopf et al.)")
          ->transform(FiniteNumber(0.05, 10.0))
          ->capture_default_str();
      app->add_option("--jbu-range-sigma", f->jbu.tauSigma,
                      "joint bilateral rival: range Gaussian sigma on the texture guide tau")
          ->transform(FiniteNumber(1e-4, 100.0))
          ->capture_default_str();
#if DCM_BENCH_HAVE_AOV
      app->add_option("--highlight-level", f->highlightLevel,
                      "AOV inputs: a pixel whose highlight guide exceeds this is a highlight (as dcm reconstruct)")
          ->transform(FiniteNumber(0))
          ->default_str(Fmt("%g", aov::AovOptions{}.highlightLevel))
          ->group(kGroupGuides);
#endif
      app->option_defaults()->group(kGroupNoise);
      app->add_option("--spp", f->spp,
                      "scenes: the noise sweep instead of the accuracy sweeps: at each number of estimates per "
                      "pixel (render.samples_per_pixel), full noisy render, dcm, dcm with the noise ignored, paper; "
                      ".blend files: the full Cycles render and dcm blender at each number of samples, timed")
          ->delimiter(',')
          ->transform(Integer(2, 1 << 20));
      app->add_option("--reference-spp", f->referenceSpp,
                      "--spp: estimates per pixel of the reference (default 16x the largest --spp)")
          ->transform(Integer(2, 1 << 20));
      app->add_option("--reference", f->reference,
                      ".blend inputs: the converged render to compare with (R,G,B or Blender's Combined layer; "
                      "default: rendered at --reference-spp with another seed)");
      app->add_option("--adaptive", f->adaptive,
                      ".blend inputs: also Cycles' adaptive sampling at these noise thresholds, at the largest --spp")
          ->delimiter(',')
          ->transform(FiniteNumber(1e-6, 1));
      app->add_option("--variant", f->variants,
                      ".blend inputs: flags of one dcm blender run at each --spp (repeatable, e.g. "
                      "--variant '--target-psnr 45'; default one run with dcm's defaults)")
          ->allow_extra_args(false);
      app->add_option("--blender", f->blender, ".blend inputs: the Blender executable")->capture_default_str();
      app->add_option("--repeat", f->repeat, ".blend inputs: time each run N times, back to back (the median)")
          ->transform(Integer(1, 100))
          ->capture_default_str();
      app->add_option("--render-threads", f->renderThreads, ".blend inputs: Cycles threads (0: Blender's choice)")
          ->transform(Integer(0, kMaxThreads))
          ->capture_default_str();
      app->option_defaults()->group(kGroupInternals);
      app->add_option("--threads", f->threads, "worker threads (0: all cores)")
          ->transform(Integer(0, kMaxThreads))
          ->capture_default_str();
      app->option_defaults()->group(kGroupGeneral);
      app->add_flag("-v,--verbose", f->verbose, "per point: the time split, pixel counts and SSIM");
      app->add_flag("-q,--quiet", f->quiet, "no progress on stderr, no summary on stdout");
      return [f] { return RunBench(*f); };
    });

}  // namespace
}  // namespace dcm::cli

#endif  // __has_include("dcm/embree/embree_provider.h")

// The Python module `dcm` (as dcm._dcm; python/dcm/__init__.py re-exports
// it): dcm.reconstruct_exr, what `dcm reconstruct` does on EXR AOVs, and
// dcm.reconstruct, the engine driven by a renderer written in Python. numpy
// in and out; options by the names of the C API (dcm/option_names.h); errors
// are Python exceptions carrying dcm's message. The GIL is released while the
// engine runs and taken again for the Python evaluate function.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/stats_json.h"
#include "dcm/option_names.h"
#include "dcm/quality_target.h"
#include "dcm/reconstructor.h"
#include "engine_flags.h"
#include "reconstruct_exr.h"

namespace py = pybind11;

namespace dcm::python {
namespace {

/// dcm.Error: a failure of dcm itself (a file, a channel, the engine); the
/// message is dcm's.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Raises dcm.Error with the status's message when it is not OK.
void Check(const Status& st) {
  if (!st.ok()) throw Error(st.message());
}

/// The engine options of a call, and the method they started from (for
/// the statistics).
struct Settings {
  ReconstructionOptions options;
  std::string method = "dcm";
  bool batchSizeSet = false;
};

std::string TypeName(py::handle value) { return py::str(py::type::of(value).attr("__name__")); }

std::string JoinNames(OptionKind kind) {
  std::string s;
  for (std::string_view n : OptionNames(kind)) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

/// Sets one option by its C API name from a Python value: str for string
/// options; int (or a whole float) for integer options; int or float for
/// float options; bool (or 0/1) for bool options; None for dcm's default of
/// the regime (an option whose default depends on it). Wrong names and
/// values raise ValueError, wrong types TypeError, naming the option.
void SetOption(Settings* s, const std::string& name, py::handle value) {
  ReconstructionOptions& o = s->options;
  if (value.is_none() && KindOfOption(name) != OptionKind::kUnknown) {
    const Status st = ResetOption(&o, name);
    if (!st.ok()) throw py::value_error(st.message());
    return;
  }
  const bool isBool = py::isinstance<py::bool_>(value);
  const bool isInt = !isBool && py::isinstance<py::int_>(value);
  const bool isFloat = py::isinstance<py::float_>(value);
  auto wrongType = [&](const char* expected) {
    throw py::type_error("option " + name + ": expected " + expected + ", got " + TypeName(value));
  };
  switch (KindOfOption(name)) {
    case OptionKind::kString: {
      if (!py::isinstance<py::str>(value)) wrongType("a str");
      const std::string v = value.cast<std::string>();
      const Status st = SetStringOption(&o, name, v);
      if (!st.ok()) throw py::value_error("option " + st.message());
      if (name == "method") s->method = v;
      return;
    }
    case OptionKind::kInt: {
      long long v = 0;
      if (isInt) {
        v = value.cast<long long>();
      } else if (isFloat) {
        const double d = value.cast<double>();
        if (!(d == double((long long)d))) throw py::value_error("option " + name + ": expected a whole number");
        v = (long long)d;
      } else {
        wrongType("an int");
      }
      if (v < INT_MIN || v > INT_MAX) throw py::value_error("option " + name + ": out of range");
      SetIntOption(o, name, int(v));
      if (name == "batch_size") s->batchSizeSet = true;
      return;
    }
    case OptionKind::kFloat:
      if (!isInt && !isFloat) wrongType("a float");
      SetFloatOption(o, name, value.cast<float>());
      return;
    case OptionKind::kBool:
      if (isBool) {
        *FindBoolOption(o, name) = value.cast<bool>();
      } else if (isInt && (value.cast<long long>() == 0 || value.cast<long long>() == 1)) {
        *FindBoolOption(o, name) = value.cast<long long>() != 0;
      } else {
        wrongType("a bool");
      }
      return;
    case OptionKind::kUnknown:
      break;
  }
  throw py::value_error("unknown option '" + name + "' (string: " + JoinNames(OptionKind::kString) +
                        "; int: " + JoinNames(OptionKind::kInt) + "; float: " + JoinNames(OptionKind::kFloat) +
                        "; bool: " + JoinNames(OptionKind::kBool) + ")");
}

/// The settings of **options: "method" first (it resets every option to its
/// preset), then the others; then the ranges are checked.
Settings ParseOptions(const py::dict& kwargs) {
  Settings s;
  if (kwargs.contains("method")) SetOption(&s, "method", kwargs["method"]);
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (name != "method") SetOption(&s, name, value);
  }
  const Status st = s.options.Validate();
  if (!st.ok()) throw py::value_error(st.message());
  return s;
}

/// target_psnr and budget (dcm/quality_target.h): a PSNR in (0, 99] dB or
/// "render", a share of the pixels in (0, 1]; None: not asked.
struct Goal {
  std::optional<double> targetPsnr, budget;  ///< as cli::EngineFlags (cli::kTargetRender: "render")
  bool any() const { return targetPsnr || budget; }
};

/// Reads and checks target_psnr and budget. With either, the threshold is the
/// goal's to choose: contrast_threshold and full_evaluation raise ValueError,
/// as --threshold and --full do with the flags.
Goal ParseGoal(py::handle target, py::handle budget, const py::dict& kwargs) {
  Goal g;
  if (!target.is_none()) {
    if (py::isinstance<py::str>(target)) {
      if (target.cast<std::string>() != "render")
        throw py::value_error("target_psnr: a PSNR in dB or \"render\", got '" + target.cast<std::string>() + "'");
      g.targetPsnr = cli::kTargetRender;
    } else if (py::isinstance<py::float_>(target) || (py::isinstance<py::int_>(target) && !py::isinstance<py::bool_>(target))) {
      const double t = target.cast<double>();
      if (!(t > 0 && t <= 99)) throw py::value_error("target_psnr: must be in (0, 99] dB, got " + std::string(py::str(target)));
      g.targetPsnr = t;
    } else {
      throw py::type_error("target_psnr: expected a float or \"render\", got " + TypeName(target));
    }
  }
  if (!budget.is_none()) {
    if (py::isinstance<py::bool_>(budget) || !(py::isinstance<py::float_>(budget) || py::isinstance<py::int_>(budget)))
      throw py::type_error("budget: expected a float, got " + TypeName(budget));
    const double b = budget.cast<double>();
    if (!(b > 0 && b <= 1)) throw py::value_error("budget: must be a share of the pixels in (0, 1], got " + std::string(py::str(budget)));
    g.budget = b;
  }
  if (g.any()) {
    const char* goal = g.targetPsnr ? "target_psnr" : "budget";
    for (const char* fixed : {"contrast_threshold", "full_evaluation"})
      if (kwargs.contains(fixed) && !kwargs[fixed].is_none() && py::bool_(kwargs[fixed]))
        throw py::value_error(std::string(goal) + ": not with " + fixed + " (the goal chooses the threshold)");
  }
  return g;
}

/// The warning of a target not reached, empty when it was (or none was asked).
std::string GoalWarning(const QualityReport& r, const Goal& g) {
  if (!g.targetPsnr || r.targetReached) return "";
  char buf[256];
  std::snprintf(buf, sizeof buf, "target_psnr %.4g: not reached%s; estimated %.2f dB (lower bound %.2f) at %.2f %% exact pixels",
                r.targetPsnr, r.budgetBound ? " within the budget" : "", r.estimate.psnr, r.estimate.low,
                100 * r.exactFraction());
  return buf;
}

/// Issues each of `warnings` as a RuntimeWarning.
void Warn(const nlohmann::json& warnings) {
  const py::object warnFn = py::module_::import("warnings").attr("warn");
  for (const auto& w : warnings)
    warnFn(w.get<std::string>(), py::reinterpret_borrow<py::object>(PyExc_RuntimeWarning), 2);
}

/// File names from a str or os.PathLike, or an iterable of them.
std::vector<std::string> StringList(py::handle value, const char* what) {
  if (value.is_none()) return {};
  auto fspath = py::module_::import("os").attr("fspath");
  if (py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__")) return {py::str(fspath(value))};
  std::vector<std::string> out;
  for (py::handle item : py::iter(value)) {
    if (!py::isinstance<py::str>(item) && !py::hasattr(item, "__fspath__"))
      throw py::type_error(std::string(what) + ": expected file names (str), got " + TypeName(item));
    out.push_back(py::str(fspath(item)));
  }
  return out;
}

/// "ROLE=EXPR" / "SHADER=FILE" items from a dict {left: right} or a list of
/// such strings.
std::vector<std::string> Pairs(py::handle value, const char* what) {
  if (value.is_none()) return {};
  if (!py::isinstance<py::dict>(value)) return StringList(value, what);
  std::vector<std::string> out;
  for (const auto& [k, v] : value.cast<py::dict>()) out.push_back(std::string(py::str(k)) + "=" + std::string(py::str(v)));
  return out;
}

/// "(a, b, c)": a shape as Python writes it.
std::string ShapeText(const std::vector<py::ssize_t>& dims) {
  std::string s = "(";
  for (size_t i = 0; i < dims.size(); ++i) s += (i ? ", " : "") + std::to_string(dims[i]);
  return s + (dims.size() == 1 ? ",)" : ")");
}

/// A float array of exactly the shape `dims` (last 3), as float32, copied
/// into RGB-like triples in row-major order.
template <typename Triple>
std::vector<Triple> Triples(py::handle value, const std::vector<py::ssize_t>& dims, const std::string& what) {
  auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a)
    throw py::type_error(what + ": expected a float array of shape " + ShapeText(dims) + ", got " + TypeName(value));
  const std::vector<py::ssize_t> got(a.shape(), a.shape() + a.ndim());
  if (got != dims) throw py::value_error(what + ": expected shape " + ShapeText(dims) + ", got " + ShapeText(got));
  const size_t rows = size_t(a.size()) / 3;
  std::vector<Triple> out(rows);
  const float* v = a.data();
  for (size_t i = 0; i < rows; ++i) out[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  return out;
}

/// An (H, W, 3) float32 numpy array of an image of RGB.
py::array_t<float> ImageArray(const std::vector<RGB>& image, int width, int height) {
  py::array_t<float> a({py::ssize_t(height), py::ssize_t(width), py::ssize_t(3)});
  float* v = a.mutable_data();
  for (size_t i = 0; i < image.size(); ++i) v[3 * i] = image[i].r, v[3 * i + 1] = image[i].g, v[3 * i + 2] = image[i].b;
  return a;
}

/// What both functions return.
struct Result {
  py::object image;       ///< (H, W, 3) float32, linear RGB at the output resolution
  py::object sampleMap;   ///< (workH, workW) uint8: why each working pixel was exact (REASON_NAMES)
  py::object stats;       ///< dict: the statistics JSON
};

/// The result's numpy arrays and the statistics as a dict.
Result MakeResult(const Reconstruction& r, const nlohmann::json& stats) {
  Result out;
  out.image = ImageArray(r.image, r.width, r.height);
  py::array_t<uint8_t> map({py::ssize_t(r.workHeight), py::ssize_t(r.workWidth)});
  uint8_t* m = map.mutable_data();
  for (size_t i = 0; i < r.sampleMap.size(); ++i) m[i] = uint8_t(r.sampleMap[i]);
  out.sampleMap = map;
  // As in the --stats files, non-finite numbers are null (nlohmann::json
  // writes them so); a file name that is not UTF-8 gets U+FFFD.
  const std::string text = stats.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  out.stats = py::module_::import("json").attr("loads")(text);
  return out;
}

/// dcm.reconstruct_exr: the AOV flags as keyword arguments, then the code of
/// `dcm reconstruct` (ToAovOptions, AovProvider::Open, ReconstructWholeExr).
Result ReconstructExr(py::object inputs, const std::string& preset, py::object map, py::object texture,
                      const std::string& layer, py::object samples, py::object secondRender, bool estimateVariance,
                      std::optional<float> highlightLevel, py::object reference, py::object targetPsnr,
                      py::object budget, bool warn, py::kwargs kwargs) {
  const Settings s = ParseOptions(kwargs);
  const Goal goal = ParseGoal(targetPsnr, budget, kwargs);
  cli::aov_common::AovFlags f;
  f.inputs = StringList(inputs, "inputs");
  if (f.inputs.empty()) throw py::value_error("no input files (EXR AOVs)");
  f.preset = preset;
  f.maps = Pairs(map, "map");
  f.textures = Pairs(texture, "texture");
  f.layer = layer;
  f.samples = StringList(samples, "samples");
  f.secondRender = StringList(secondRender, "second_render");
  f.estimateVariance = estimateVariance;
  if (highlightLevel) f.highlightLevel = *highlightLevel;
  const std::vector<std::string> ref = StringList(reference, "reference");
  if (ref.size() > 1) throw py::value_error("reference: one file");
  cli::EngineFlags engine;
  engine.method = s.method;
  engine.quiet = true;
  engine.targetPsnr = goal.targetPsnr;
  engine.budget = goal.budget;

  aov::AovOptions aovOptions;
  Status st = cli::aov_common::ToAovOptions(f, !f.samples.empty(), s.options.textureSplit, &aovOptions);
  if (!st.ok()) throw py::value_error(st.message());

  cli::ExrReconstruction run;
  bool usage = false;
  {
    py::gil_scoped_release release;
    std::unique_ptr<aov::AovProvider> provider;
    st = aov::AovProvider::Open(f.inputs, aovOptions, &provider);  // as the command, without its -v notes
    if (st.ok()) cli::ApplyNoisyDefaultGoal(*provider, !f.samples.empty(), &engine);
    if (st.ok())
      st = cli::ReconstructWholeExr("reconstruct", *provider, f, engine, s.options, ref.empty() ? "" : ref[0], &run,
                                    &usage);
  }
  if (!st.ok()) {
    if (usage) throw py::value_error(st.message());
    throw Error(st.message());
  }
  if (run.quality)
    if (const std::string w = GoalWarning(*run.quality, goal); !w.empty()) run.stats["warnings"].push_back(w);
  if (warn) Warn(run.stats["warnings"]);
  return MakeResult(run.result, run.stats);
}

/// A provider whose guides are numpy arrays and whose samples come from a
/// Python function, called with the GIL from the engine's thread, one batch
/// per round.
class PythonProvider final : public SampleProvider {
 public:
  PythonProvider(int width, int height, py::object evaluate, bool split, bool variance, bool hardShadowsGuided)
      : width_(width), height_(height), evaluate_(std::move(evaluate)), split_(split), variance_(variance),
        hardShadowsGuided_(hardShadowsGuided) {}

  /// Reads the guides dict: "id", "shader" (H, W) integers; "tau", "normal" (H, W, 3) floats.
  void SetGuides(const py::dict& guides) {
    const size_t n = size_t(width_) * size_t(height_);
    const std::vector<py::ssize_t> hw = {height_, width_}, hw3 = {height_, width_, 3};
    for (const auto& [k, v] : guides) {
      const std::string key = py::str(k);
      const std::string what = "guides['" + key + "']";
      if (key == "id" || key == "shader") {
        py::array a = py::array::ensure(v);
        if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
          throw py::type_error(what + ": expected an integer array of shape " + ShapeText(hw) + ", got " +
                               (a ? std::string(py::str(a.dtype())) : TypeName(v)));
        const std::vector<py::ssize_t> got(a.shape(), a.shape() + a.ndim());
        if (got != hw) throw py::value_error(what + ": expected shape " + ShapeText(hw) + ", got " + ShapeText(got));
        auto ids = py::array_t<uint32_t, py::array::c_style | py::array::forcecast>::ensure(a);
        (key == "id" ? objectIds_ : shaderIds_).assign(ids.data(), ids.data() + n);
      } else if (key == "tau") {
        texture_ = Triples<RGB>(v, hw3, what);
      } else if (key == "normal") {
        normals_ = Triples<Vec3f>(v, hw3, what);
      } else {
        throw py::value_error("unknown guide '" + key + "' (valid: id, shader, tau, normal)");
      }
    }
  }

  ProviderCapabilities Capabilities() const override {
    ProviderCapabilities c;
    c.width = width_;
    c.height = height_;
    c.objectId = !objectIds_.empty();
    c.shaderId = !shaderIds_.empty();
    c.texture = !texture_.empty();
    c.normal = !normals_.empty();
    c.splitRadiance = split_;
    c.variance = variance_;
    c.hardShadowsGuided = hardShadowsGuided_;
    c.threadSafe = false;  // one thread at a time: the GIL
    c.name = "Python evaluate";
    return c;
  }

  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    const Bounds2i all{{0, 0}, {width_, height_}};
    if (Intersect(region, all) != region) return Status::Error("guide region outside the image");
    out->region = region;
    const size_t n = size_t(region.area());
    auto copy = [&](const auto& src, auto* dst) {
      dst->resize(n);
      size_t k = 0;
      for (int y = region.min.y; y < region.max.y; ++y)
        for (int x = region.min.x; x < region.max.x; ++x) (*dst)[k++] = src[size_t(all.offset({x, y}))];
    };
    if (what.objectId && !objectIds_.empty()) copy(objectIds_, &out->objectId);
    if (what.shaderId && !shaderIds_.empty()) copy(shaderIds_, &out->shaderId);
    if (what.texture && !texture_.empty()) copy(texture_, &out->texture);
    if (what.normal && !normals_.empty()) copy(normals_, &out->normal);
    return Status::Ok();
  }

  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    py::gil_scoped_acquire gil;
    try {
      EvaluateWithGil(pixels, what, out);
      return Status::Ok();
    } catch (py::error_already_set& e) {
      error_ = std::current_exception();
      return Status::Error(std::string("evaluate raised ") + e.what());
    } catch (const std::exception& e) {
      error_ = std::current_exception();
      return Status::Error(e.what());
    }
  }

  /// The exception evaluate raised (or its result's fault), to re-raise
  /// once the engine has stopped.
  std::exception_ptr error() const { return error_; }

 private:
  void EvaluateWithGil(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) {
    const size_t n = pixels.size();
    py::array_t<int32_t> xy({py::ssize_t(n), py::ssize_t(2)});
    int32_t* p = xy.mutable_data();
    for (size_t i = 0; i < n; ++i) p[2 * i] = pixels[i].x, p[2 * i + 1] = pixels[i].y;
    const py::object result = evaluate_(xy);
    const std::vector<py::ssize_t> shape = {py::ssize_t(n), 3};

    std::vector<RGB> L, Li, Lc, var;
    if (py::isinstance<py::dict>(result)) {
      const py::dict d = result.cast<py::dict>();
      for (const auto& [k, v] : d) {
        const std::string key = py::str(k);
        const std::string name = "evaluate()['" + key + "']";
        if (key == "L") L = Triples<RGB>(v, shape, name);
        else if (key == "Li") Li = Triples<RGB>(v, shape, name);
        else if (key == "Lc") Lc = Triples<RGB>(v, shape, name);
        else if (key == "var") var = Triples<RGB>(v, shape, name);
        else throw py::value_error("evaluate returned a dict with key '" + key + "' (valid: L, Li, Lc, var)");
      }
    } else {
      L = Triples<RGB>(result, shape, "evaluate()");
    }
    if (Li.empty() != Lc.empty()) throw py::value_error("evaluate returned one of 'Li' and 'Lc' without the other");
    if (what.split && Li.empty())
      throw py::value_error("evaluate must return a dict with 'Li' and 'Lc' (split=True with a 'tau' guide)");
    if (what.variance && var.empty()) throw py::value_error("evaluate must return a dict with 'var' (variance=True)");
    if (L.empty()) {
      // L = L_i * tau + L_c (Scheel et al. 2001, 3.3).
      if (Li.empty() || texture_.empty())
        throw py::value_error("evaluate returned no 'L' (and no 'Li', 'Lc' with a 'tau' guide to make it)");
      L.resize(n);
      for (size_t i = 0; i < n; ++i) {
        const RGB& t = texture_[size_t(pixels[i].y) * size_t(width_) + size_t(pixels[i].x)];
        L[i] = {Li[i].r * t.r + Lc[i].r, Li[i].g * t.g + Lc[i].g, Li[i].b * t.b + Lc[i].b};
      }
    }
    for (size_t i = 0; i < n; ++i) {
      out[i].L = L[i];
      if (what.split) out[i].Li = Li[i], out[i].Lc = Lc[i];
      if (what.variance) out[i].variance = var[i];
    }
  }

  int width_, height_;
  py::object evaluate_;
  bool split_, variance_, hardShadowsGuided_;
  std::vector<uint32_t> objectIds_, shaderIds_;
  std::vector<RGB> texture_;
  std::vector<Vec3f> normals_;
  std::exception_ptr error_;
};

/// dcm.reconstruct: the engine on a PythonProvider.
Result ReconstructPython(int width, int height, py::object guides, py::object evaluate, bool split, bool variance,
                         bool hardShadowsGuided, py::object targetPsnr, py::object budget, bool warn,
                         py::kwargs kwargs) {
  Settings s = ParseOptions(kwargs);
  const Goal g = ParseGoal(targetPsnr, budget, kwargs);
  QualityGoal goal;
  if (g.targetPsnr && *g.targetPsnr == cli::kTargetRender) goal.targetRender = true;
  else if (g.targetPsnr) goal.targetPsnr = *g.targetPsnr;
  goal.budget = g.budget.value_or(0);
  if (!s.batchSizeSet) s.options.batchSize = INT_MAX;  // one call per round: Python's overhead is per call
  constexpr int kMaxSide = 1 << 17;
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide)
    throw py::value_error("unusable size " + std::to_string(width) + "x" + std::to_string(height));
  if (evaluate.is_none() || !PyCallable_Check(evaluate.ptr()))
    throw py::type_error("evaluate: expected a function of an (N, 2) int32 array of pixels (x, y)");
  PythonProvider provider(width, height, evaluate, split, variance, hardShadowsGuided);
  if (!guides.is_none()) {
    if (!py::isinstance<py::dict>(guides)) throw py::type_error("guides: expected a dict, got " + TypeName(guides));
    provider.SetGuides(guides.cast<py::dict>());
  }
  Reconstruction r;
  QualityReport report;
  Status st;
  double wall = 0;
  {
    py::gil_scoped_release release;
    const auto t0 = std::chrono::steady_clock::now();
    st = g.any() ? ReconstructToQuality(provider, s.options, goal, &r, &report) : Reconstruct(provider, s.options, &r);
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (provider.error()) std::rethrow_exception(provider.error());
  Check(st);
  nlohmann::json stats = toolkit::RunToJson(r, s.method, s.options, wall);
  stats["warnings"] = toolkit::SampleWarnings(r.stats);
  if (g.any()) {
    toolkit::AddQualityJson(report, g.targetPsnr.value_or(0), g.budget.value_or(0), &stats);
    if (const std::string w = GoalWarning(report, g); !w.empty()) stats["warnings"].push_back(w);
  }
  if (warn) Warn(stats["warnings"]);
  return MakeResult(r, stats);
}

}  // namespace
}  // namespace dcm::python

PYBIND11_MODULE(_dcm, m) {
  using namespace dcm::python;
  m.doc() = "dcm: reconstruct a render from a few percent of exact pixels (Directional Coherence Maps)";
  m.attr("__version__") = DCM_VERSION;
  py::register_exception<Error>(m, "Error", PyExc_RuntimeError);

  py::list reasons;
  for (int i = 0; i < dcm::kSampleReasonCount; ++i) reasons.append(std::string(dcm::ToString(dcm::SampleReason(i))));
  m.attr("REASON_NAMES") = py::tuple(reasons);

  py::class_<Result>(m, "Result", "The outcome of a reconstruction.")
      .def_readonly("image", &Result::image, "(H, W, 3) float32 numpy array: linear RGB at the output resolution")
      .def_readonly("sample_map", &Result::sampleMap,
                    "(H, W) uint8 numpy array at the working resolution: why each pixel was exact, an index into "
                    "dcm.REASON_NAMES (0: interpolated)")
      .def_readonly("stats", &Result::stats, "dict: the statistics, as the command's --stats JSON")
      .def("__repr__", [](const Result& r) {
        const py::tuple shape = r.image.attr("shape");
        return "<dcm.Result " + std::string(py::str(shape[1])) + "x" + std::string(py::str(shape[0])) +
               ", exact fraction " + std::string(py::str(r.stats["exact_fraction"])) + ">";
      });

  m.def("reconstruct_exr", &ReconstructExr, py::arg("inputs"), py::arg("preset") = "blender", py::kw_only(),
        py::arg("map") = py::none(), py::arg("texture") = py::none(), py::arg("layer") = "",
        py::arg("samples") = py::none(), py::arg("second_render") = py::none(),
        py::arg("estimate_variance") = false, py::arg("highlight_level") = py::none(),
        py::arg("reference") = py::none(), py::arg("target_psnr") = py::none(), py::arg("budget") = py::none(),
        py::arg("warn") = true,
        R"(What `dcm reconstruct` does, in-process: reconstructs the image of EXR AOVs.

inputs: an EXR file name, or a list of them (one multilayer EXR or several of one size).
preset: "blender" (Cycles passes) or "generic" (id, shader, tau.R, ..., R, G, B).
map: {"ROLE": "EXPR"} or ["ROLE=EXPR", ...] (--map); texture: {"SHADER": "FILE"},
["SHADER=FILE"] or "MAP.json" (--texture); layer (--layer); samples (--samples, the
sparse round trip); second_render (--second-render); estimate_variance
(--estimate-variance); highlight_level (--highlight-level); reference (--reference).
target_psnr: a PSNR in dB, or "render" (--target-psnr); budget: the largest share of
exact pixels (--budget); with either, stats["estimated_psnr"] and stats["quality"].
warn: the provider's warnings and a target not reached (also in stats["warnings"]) as
RuntimeWarning.
**options: engine options by their C API names (method="paper", contrast_threshold=0.1,
elementary_block=8, texture_split=False, ...).

Returns a Result: .image (H, W, 3) float32, the pixels `dcm reconstruct` writes;
.sample_map; .stats (the --stats JSON as a dict). Raises dcm.Error (files, channels,
the engine), ValueError (option names and values), TypeError.)");

  m.def("reconstruct", &ReconstructPython, py::arg("width"), py::arg("height"), py::kw_only(),
        py::arg("guides") = py::none(), py::arg("evaluate"), py::arg("split") = false,
        py::arg("variance") = false, py::arg("hard_shadows_guided") = false, py::arg("target_psnr") = py::none(),
        py::arg("budget") = py::none(), py::arg("warn") = true,
        R"(Reconstructs a width x height image whose exact pixels come from a Python function.

guides: {"id": (H, W) ints, "shader": (H, W) ints, "tau": (H, W, 3) floats,
"normal": (H, W, 3) floats}, each optional: the cheap passes (object and material
IDs, texture value, surface normal).
evaluate(xy): xy is an (N, 2) int32 array of pixels (x, y); returns (N, 3) float32
radiance, or a dict {"L": ..., "Li": ..., "Lc": ..., "var": ...} of (N, 3) arrays.
Called once per round with the whole batch, from one thread; exceptions it raises
stop the reconstruction and are re-raised.
split: evaluate returns "Li" and "Lc" (L = Li * tau + Lc; "L" may be left out),
used with a "tau" guide. variance: evaluate returns "var", the variance of its
estimate of L (a noisy renderer). hard_shadows_guided: every hard shadow shows in
the guides (DCM_SAMPLE_HARD_SHADOWS_GUIDED).
target_psnr: refine until the estimated PSNR (display-referred, against the full
render; with variance=True against the converged image) reaches it, or "render";
budget: at most this share of exact pixels (validation pixels included); with both,
whichever binds first. evaluate is then called for each pixel at most once across the
search; stats["estimated_psnr"] and stats["quality"] report it. A target not reached
is a RuntimeWarning (warn=False: only in stats["warnings"]).
**options: engine options by their C API names; batch_size defaults to one call per round.

Returns a Result (.image, .sample_map, .stats).)");
}

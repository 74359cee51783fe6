// PipeProvider: the dcm-pipe protocol (PROTOCOL.md) over a child's stdin/stdout.
#include "dcm/pipe/pipe_provider.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "child_process.h"

namespace dcm::pipe {

static_assert(std::endian::native == std::endian::little, "the dcm-pipe payloads are little-endian");

namespace {

using Clock = ChildProcess::Clock;

/// Longest line of the protocol.
constexpr size_t kMaxLine = 4096;
/// Largest side of the image a child may announce.
constexpr int kMaxSide = 1 << 17;
/// preview_samples= (a renderer's samples per pixel).
constexpr int64_t kMaxSamplesPerPixel = int64_t(1) << 30;

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      if (!cur.empty()) out.push_back(std::move(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(std::move(cur));
  return out;
}

bool ParseInt(const std::string& s, int64_t* v) {
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, *v);
  return ec == std::errc() && p == end;
}

/// A duration in seconds: finite, from 0 to a day (a round costs less).
bool ParseSeconds(const std::string& s, double* v) {
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, *v);
  return ec == std::errc() && p == end && std::isfinite(*v) && *v >= 0 && *v <= 86400;
}

/// A line of the child quoted for a message: printable ASCII, at most 60 characters.
std::string Quote(const std::string& line) {
  std::string q;
  for (unsigned char c : line) {
    if (q.size() >= 60) {
      q += "...";
      break;
    }
    if (c >= 32 && c < 127) {
      q += char(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      q += buf;
    }
  }
  return "'" + q + "'";
}

std::string Seconds(double s) {
  std::ostringstream o;
  o << s << " s";
  return o.str();
}

}  // namespace

PipeProvider::PipeProvider(PipeOptions options, std::unique_ptr<ChildProcess> child)
    : options_(std::move(options)), child_(std::move(child)) {}

PipeProvider::~PipeProvider() {
  if (finished_ || !broken_.ok()) return;  // the child is gone (reaped, or killed by Fail)
  // Not finished: ask the child to quit, but do not wait long for it.
  const std::string quit = "quit\n";
  (void)child_->Write(quit.data(), quit.size(), Clock::now() + std::chrono::seconds(1));
  child_->CloseInput();
  if (!child_->WaitExit(Clock::now() + std::chrono::seconds(2))) child_->Kill();
}

Status PipeProvider::Start(const PipeOptions& options, std::unique_ptr<PipeProvider>* out) {
  if (options.command.empty()) return Status::Error("provider command is empty");
  // Above 1e6 s the deadline (now + timeout in nanoseconds) could overflow.
  const auto valid = [](double s) { return s > 0 && s <= 1e6; };
  if (!valid(options.timeoutSeconds) || !valid(options.startupTimeoutSeconds))
    return Status::Error("provider timeouts must be > 0 and at most 1e6 seconds");
  std::unique_ptr<ChildProcess> child;
  if (Status st = ChildProcess::Spawn(options.command, &child); !st.ok())
    return Status::Error("provider '" + options.command + "': " + st.message());
  std::unique_ptr<PipeProvider> p(new PipeProvider(options, std::move(child)));
  DCM_RETURN_IF_ERROR(p->Handshake());
  *out = std::move(p);
  return Status::Ok();
}

std::string PipeProvider::Prefix() const {
  return "provider '" + options_.command + "'";
}

Status PipeProvider::Fail(const std::string& what) {
  if (!broken_.ok()) return broken_;
  child_->Kill();
  broken_ = Status::Error(Prefix() + ": " + what);
  return broken_;
}

/// Reads the header line of an answer to `request` that must start with
/// `keyword`; handles "error MESSAGE", end of file, timeouts and garbage.
static Status ReadAnswer(ChildProcess& child, const std::string& request, const std::string& keyword,
                         double timeoutS, std::vector<std::string>* tokens, std::string* failure) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeoutS));
  std::string line;
  Status st = child.ReadLine(&line, kMaxLine, deadline);
  if (!st.ok()) {
    if (st.message() == "end of file") {
      child.WaitExit(Clock::now() + std::chrono::seconds(2));
      *failure = "closed its output instead of answering '" + request + "' (it " + child.ExitDescription() + ")";
    } else if (st.message() == "timeout") {
      *failure = "did not answer '" + request + "' within " + Seconds(timeoutS) + " (killed)";
    } else if (st.message() == "line too long") {
      *failure = "sent a line longer than " + std::to_string(kMaxLine) + " bytes in answer to '" + request +
                 "' (not a dcm-pipe provider?)";
    } else {
      *failure = "reading its answer to '" + request + "': " + st.message();
    }
    return Status::Error(*failure);
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.rfind("error", 0) == 0 && (line.size() == 5 || line[5] == ' ')) {
    *failure = "reported an error: " + (line.size() > 6 ? line.substr(6) : std::string("(no message)"));
    return Status::Error(*failure);
  }
  *tokens = Split(line, ' ');
  if (tokens->empty() || (*tokens)[0] != keyword) {
    *failure = "sent " + Quote(line) + " in answer to '" + request + "' (expected '" + keyword + " ...')";
    return Status::Error(*failure);
  }
  return Status::Ok();
}

/// Reads `size` payload bytes of the answer to `request`.
static Status ReadPayload(ChildProcess& child, void* data, size_t size, const std::string& request, double timeoutS,
                          std::string* failure) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeoutS));
  Status st = child.Read(data, size, deadline);
  if (st.ok()) return st;
  if (st.message() == "end of file") {
    child.WaitExit(Clock::now() + std::chrono::seconds(2));
    *failure = "closed its output in the middle of its answer to '" + request + "' (" + std::to_string(size) +
               " bytes expected; it " + child.ExitDescription() + ")";
  } else if (st.message() == "timeout") {
    *failure = "did not send all of its answer to '" + request + "' within " + Seconds(timeoutS) + " (killed)";
  } else {
    *failure = "reading its answer to '" + request + "': " + st.message();
  }
  return Status::Error(*failure);
}

Status PipeProvider::Handshake() {
  const std::string hello = "dcm-pipe " + std::to_string(kProtocolVersion) + "\n";
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options_.startupTimeoutSeconds));
  std::string failure;
  // A child that exits without reading its input fails the write; its answer
  // (or end of file) says more, so read it in any case.
  Status written = child_->Write(hello.data(), hello.size(), deadline);
  std::vector<std::string> t;
  if (!ReadAnswer(*child_, "dcm-pipe " + std::to_string(kProtocolVersion), "dcm-pipe", options_.startupTimeoutSeconds,
                  &t, &failure)
           .ok()) {
    return Fail(failure);
  }
  if (!written.ok()) return Fail("handshake: " + written.message());
  int64_t version = 0;
  if (t.size() < 2 || !ParseInt(t[1], &version)) return Fail("handshake without a protocol version");
  if (version != kProtocolVersion) {
    return Fail("speaks dcm-pipe protocol version " + std::to_string(version) + ", dcm speaks version " +
                std::to_string(kProtocolVersion));
  }
  childVersion_ = int(version);
  caps_ = ProviderCapabilities{};
  caps_.threadSafe = false;
  bool haveW = false, haveH = false;
  for (size_t i = 2; i < t.size(); ++i) {
    const size_t eq = t[i].find('=');
    if (eq == std::string::npos) return Fail("handshake: expected key=value, got " + Quote(t[i]));
    const std::string key = t[i].substr(0, eq), value = t[i].substr(eq + 1);
    keys_[key] = value;
    int64_t v = 0;
    if (key == "width" || key == "height") {
      if (!ParseInt(value, &v) || v < 1 || v > kMaxSide)
        return Fail("handshake: " + key + " must be from 1 to " + std::to_string(kMaxSide) + ", got " + Quote(value));
      (key == "width" ? caps_.width : caps_.height) = int(v);
      (key == "width" ? haveW : haveH) = true;
    } else if (key == "caps") {
      for (const std::string& c : Split(value, ',')) {
        if (c == "object_id") caps_.objectId = true;
        else if (c == "shader_id") caps_.shaderId = true;
        else if (c == "texture") caps_.texture = true;
        else if (c == "normal") caps_.normal = true;
        else if (c == "split") caps_.splitRadiance = true;
        else if (c == "variance") caps_.variance = true;
        else if (c == "hard_shadows_guided") caps_.hardShadowsGuided = true;
        else if (c == "preview") preview_ = true;
        else if (c == "texture_covariance") textureCovariance_ = true;
        else if (c == "extra") extra_ = true;
        else if (c == "exact_samples") exactSamples_ = true;
        // Unknown capabilities are ignored (newer providers).
      }
    } else if (key == "name") {
      caps_.name = value;
    } else if (key == "preview_samples") {
      if (!ParseInt(value, &v) || v < 0 || v > kMaxSamplesPerPixel)
        return Fail("handshake: preview_samples must be a whole number from 0 (unknown) to " +
                    std::to_string(kMaxSamplesPerPixel) + ", got " + Quote(value));
      previewSamples_ = double(v);
    } else if (key == "round_latency" || key == "sample_cost" || key == "preview_cost") {
      double seconds = 0;
      if (!ParseSeconds(value, &seconds))
        return Fail("handshake: " + key + " must be seconds from 0 to 86400, got " + Quote(value));
      (key == "round_latency" ? cost_.latencyS : key == "sample_cost" ? cost_.perSampleS : cost_.previewS) = seconds;
    }
    // Unknown keys are ignored (newer providers).
  }
  if (!haveW || !haveH) return Fail("handshake without width= and height=");
  if (previewSamples_ > 0 && !preview_) return Fail("handshake: preview_samples= without the capability 'preview'");
  if (caps_.name.empty()) caps_.name = "pipe";
  return Status::Ok();
}

ProviderCapabilities PipeProvider::Capabilities() const { return caps_; }

Status PipeProvider::Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!broken_.ok()) return broken_;
  if (finished_) return Status::Error(Prefix() + ": guides requested after Finish()");
  const Bounds2i all{{0, 0}, {caps_.width, caps_.height}};
  if (region.empty() || Intersect(region, all) != region)
    return Status::Error(Prefix() + ": guide region outside the image");
  const bool ids = what.objectId && caps_.objectId, shaders = what.shaderId && caps_.shaderId,
             tex = what.texture && caps_.texture, normal = what.normal && caps_.normal;
  std::string kinds;
  auto add = [&](bool on, const char* name) {
    if (!on) return;
    if (!kinds.empty()) kinds += ',';
    kinds += name;
  };
  add(ids, "object_id");
  add(shaders, "shader_id");
  add(tex, "texture");
  add(normal, "normal");
  out->region = region;
  out->objectId.clear();
  out->shaderId.clear();
  out->texture.clear();
  out->normal.clear();
  if (kinds.empty()) return Status::Ok();

  const std::string request = "guides " + std::to_string(region.min.x) + " " + std::to_string(region.min.y) + " " +
                              std::to_string(region.max.x) + " " + std::to_string(region.max.y) + " " + kinds;
  std::vector<std::string> t;
  DCM_RETURN_IF_ERROR(Ask(request, "guides", &t));
  std::string failure;
  const int64_t n = region.area();
  int64_t count = -1;
  if (t.size() != 2 || !ParseInt(t[1], &count))
    return Fail("sent a malformed answer to '" + request + "' (expected 'guides " + std::to_string(n) + "')");
  if (count != n) {
    return Fail("answered 'guides " + std::to_string(count) + "' to '" + request + "', which asks for " +
                std::to_string(n) + " pixels");
  }
  if (ids) {
    out->objectId.resize(size_t(n));
    if (!ReadPayload(*child_, out->objectId.data(), size_t(n) * 4, request, options_.timeoutSeconds, &failure).ok())
      return Fail(failure);
  }
  if (shaders) {
    out->shaderId.resize(size_t(n));
    if (!ReadPayload(*child_, out->shaderId.data(), size_t(n) * 4, request, options_.timeoutSeconds, &failure).ok())
      return Fail(failure);
  }
  if (tex) {
    std::vector<float> f(size_t(n) * 3);
    if (!ReadPayload(*child_, f.data(), f.size() * 4, request, options_.timeoutSeconds, &failure).ok())
      return Fail(failure);
    out->texture.resize(size_t(n));
    for (size_t i = 0; i < size_t(n); ++i) out->texture[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
  }
  if (normal) {
    std::vector<float> f(size_t(n) * 3);
    if (!ReadPayload(*child_, f.data(), f.size() * 4, request, options_.timeoutSeconds, &failure).ok())
      return Fail(failure);
    out->normal.resize(size_t(n));
    for (size_t i = 0; i < size_t(n); ++i) out->normal[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
  }
  return Status::Ok();
}

Status PipeProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                              std::span<ExactSample> out) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!broken_.ok()) return broken_;
  if (finished_) return Status::Error(Prefix() + ": samples requested after Finish()");
  if (out.size() != pixels.size()) return Status::Error(Prefix() + ": output span of the wrong size");
  if (pixels.empty()) return Status::Ok();
  if (pixels.size() > size_t(std::numeric_limits<int32_t>::max() / 2))
    return Status::Error(Prefix() + ": batch too large");
  const bool split = what.split && caps_.splitRadiance;
  const bool variance = what.variance && caps_.variance;
  const size_t n = pixels.size();
  const std::string request =
      "eval " + std::to_string(n) + " L" + (split ? ",split" : "") + (variance ? ",variance" : "");
  std::vector<char> message(request.size() + 1 + n * 8);
  std::memcpy(message.data(), request.data(), request.size());
  message[request.size()] = '\n';
  std::vector<int32_t> xy(2 * n);
  for (size_t i = 0; i < n; ++i) {
    xy[2 * i] = pixels[i].x;
    xy[2 * i + 1] = pixels[i].y;
  }
  std::memcpy(message.data() + request.size() + 1, xy.data(), n * 8);
  ++evalRequests_;
  extraPixels_.clear();
  extraSamples_.clear();
  DCM_RETURN_IF_ERROR(ReadSamples(request, message, n, split, variance, out.data()));
  return extra_ ? ReadExtra(request, split, variance) : Status::Ok();
}

Status PipeProvider::Ask(const std::string& request, const std::string& keyword, std::vector<std::string>* answer) {
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.timeoutSeconds));
  const std::string line = request + "\n";
  Status written = child_->Write(line.data(), line.size(), deadline);
  std::string failure;
  if (!ReadAnswer(*child_, request, keyword, options_.timeoutSeconds, answer, &failure).ok()) return Fail(failure);
  if (!written.ok()) return Fail("request '" + request + "': " + written.message());
  return Status::Ok();
}

Status PipeProvider::SetExactSamples(int64_t samples) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!broken_.ok()) return broken_;
  if (finished_) return Status::Error(Prefix() + ": exact_samples requested after Finish()");
  if (!exactSamples_) return Status::Error(Prefix() + ": the provider did not announce exact_samples");
  if (samples < 1) return Status::Error(Prefix() + ": exact_samples " + std::to_string(samples) + " is below 1");
  const std::string request = "exact_samples " + std::to_string(samples);
  std::vector<std::string> t;
  DCM_RETURN_IF_ERROR(Ask(request, "exact_samples", &t));
  if (t.size() != 2 || t[1] != std::to_string(samples))
    return Fail("sent a malformed answer to '" + request + "' (expected '" + request + "')");
  return Status::Ok();
}

Status PipeProvider::ReadExtra(const std::string& request, bool split, bool variance) {
  std::vector<std::string> t;
  std::string failure;
  if (!ReadAnswer(*child_, request, "extra", options_.timeoutSeconds, &t, &failure).ok()) return Fail(failure);
  int64_t m = -1;
  const int64_t most = int64_t(caps_.width) * int64_t(caps_.height);
  if (t.size() != 2 || !ParseInt(t[1], &m) || m < 0 || m > most)
    return Fail("sent a malformed 'extra' line after the samples of '" + request + "' (expected 'extra M', M from 0 to " +
                std::to_string(most) + ")");
  if (m == 0) return Status::Ok();
  std::vector<int32_t> xy(size_t(m) * 2);
  if (!ReadPayload(*child_, xy.data(), xy.size() * 4, request, options_.timeoutSeconds, &failure).ok())
    return Fail(failure);
  extraPixels_.resize(size_t(m));
  for (size_t i = 0; i < size_t(m); ++i) {
    const Point2i p{xy[2 * i], xy[2 * i + 1]};
    if (p.x < 0 || p.y < 0 || p.x >= caps_.width || p.y >= caps_.height)
      return Fail("sent an extra pixel (" + std::to_string(p.x) + ", " + std::to_string(p.y) + ") outside the " +
                  std::to_string(caps_.width) + "x" + std::to_string(caps_.height) + " image after '" + request + "'");
    extraPixels_[i] = p;
  }
  extraSamples_.resize(size_t(m));
  return ReadRecords(request, size_t(m), split, variance, extraSamples_.data());
}

void PipeProvider::TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) {
  std::lock_guard<std::mutex> lock(mutex_);
  *pixels = std::move(extraPixels_);
  *samples = std::move(extraSamples_);
  extraPixels_.clear();
  extraSamples_.clear();
}

Status PipeProvider::ReadSamples(const std::string& request, const std::vector<char>& message, size_t n, bool split,
                                 bool variance, ExactSample* out, RGB* textureCovariance) {
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.timeoutSeconds));
  Status written = child_->Write(message.data(), message.size(), deadline);
  std::vector<std::string> t;
  std::string failure;
  if (!ReadAnswer(*child_, request, "samples", options_.timeoutSeconds, &t, &failure).ok()) return Fail(failure);
  if (!written.ok()) return Fail("request '" + request + "': " + written.message());
  int64_t count = -1;
  if (t.size() != 2 || !ParseInt(t[1], &count))
    return Fail("sent a malformed answer to '" + request + "' (expected 'samples " + std::to_string(n) + "')");
  if (count != int64_t(n)) {
    return Fail("answered 'samples " + std::to_string(count) + "' to '" + request + "', which asks for " +
                std::to_string(n) + " pixels");
  }
  return ReadRecords(request, n, split, variance, out, textureCovariance);
}

Status PipeProvider::ReadRecords(const std::string& request, size_t n, bool split, bool variance, ExactSample* out,
                                 RGB* textureCovariance) {
  std::string failure;
  const size_t perPixel = 3 + (split ? 6 : 0) + (variance ? 3 : 0) + (textureCovariance ? 3 : 0);
  std::vector<float> f(n * perPixel);
  if (!ReadPayload(*child_, f.data(), f.size() * 4, request, options_.timeoutSeconds, &failure).ok())
    return Fail(failure);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &f[i * perPixel];
    out[i].L = {p[0], p[1], p[2]};
    if (split) {
      out[i].Li = {p[3], p[4], p[5]};
      out[i].Lc = {p[6], p[7], p[8]};
    }
    if (variance) {
      const float* v = p + (split ? 9 : 3);
      out[i].variance = {v[0], v[1], v[2]};
    }
    if (textureCovariance) {
      const float* c = p + perPixel - 3;
      textureCovariance[i] = {c[0], c[1], c[2]};
    }
  }
  return Status::Ok();
}

Status PipeProvider::Preview(const Bounds2i& region, const SampleRequest& what, std::vector<ExactSample>* out,
                             std::vector<RGB>* textureCovariance) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!broken_.ok()) return broken_;
  if (finished_) return Status::Error(Prefix() + ": preview requested after Finish()");
  if (!preview_) return Status::Error(Prefix() + ": the provider serves no preview (capability 'preview')");
  const Bounds2i all{{0, 0}, {caps_.width, caps_.height}};
  if (region.empty() || Intersect(region, all) != region)
    return Status::Error(Prefix() + ": preview region outside the image");
  const bool split = what.split && caps_.splitRadiance;
  const bool variance = what.variance && previewHasVariance();
  const bool texcov = textureCovariance && split && textureCovariance_;
  const std::string request = "preview " + std::to_string(region.min.x) + " " + std::to_string(region.min.y) + " " +
                              std::to_string(region.max.x) + " " + std::to_string(region.max.y) + " L" +
                              (split ? ",split" : "") + (variance ? ",variance" : "") + (texcov ? ",texcov" : "");
  const std::string line = request + "\n";
  const size_t n = size_t(region.area());
  out->assign(n, ExactSample{});
  if (textureCovariance) textureCovariance->assign(texcov ? n : 0, RGB{});
  return ReadSamples(request, std::vector<char>(line.begin(), line.end()), n, split, variance, out->data(),
                     texcov ? textureCovariance->data() : nullptr);
}

Status PipeProvider::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return finishStatus_;
  finished_ = true;
  if (!broken_.ok()) {
    finishStatus_ = broken_;
    return finishStatus_;
  }
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.timeoutSeconds));
  const std::string quit = "quit\n";
  (void)child_->Write(quit.data(), quit.size(), deadline);  // a child that already left is judged by its exit status
  child_->CloseInput();
  if (!child_->WaitExit(deadline)) {
    child_->Kill();
    finishStatus_ = Status::Error(Prefix() + ": did not exit within " + Seconds(options_.timeoutSeconds) +
                                  " after 'quit' (killed)");
  } else if (!child_->exitedCleanly()) {
    finishStatus_ = Status::Error(Prefix() + ": " + child_->ExitDescription() + " after 'quit'");
  } else {
    finishStatus_ = Status::Ok();
  }
  broken_ = finishStatus_;
  return finishStatus_;
}

}  // namespace dcm::pipe

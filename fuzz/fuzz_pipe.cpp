// libFuzzer target: the dcm-pipe protocol (plugins/pipe/src/pipe_provider.cpp,
// PROTOCOL.md) reading a child's replies. The child is fake_child_process.cpp:
// the fuzzer's bytes after the first are everything it writes to its stdout.
// The first byte picks what dcm asks: which guides (bits 0-3), split and
// variance in the samples (bits 4-5).
//
// The session: the handshake (Start), guides of the top-left 8x8 pixels or
// less, an exact sample of three pixels, Finish. The contract checked
// besides crashes and sanitizer reports: a handshake accepted announces a
// size of 1..2^17 per side; guides and samples accepted have the sizes asked
// for; every error names the provider's command; once a call fails, every
// later call fails with the same message.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

#include "dcm/pipe/pipe_provider.h"

namespace dcm::pipe {
void SetFakeChildOutput(std::string_view bytes);
}  // namespace dcm::pipe

namespace {

constexpr const char* kCommand = "fuzz-child";

[[noreturn]] void Violation(const std::string& what) {
  std::fprintf(stderr, "fuzz_pipe: %s\n", what.c_str());
  std::abort();
}

void CheckNamesCommand(const dcm::Status& st, const char* call) {
  if (!st.ok() && st.message().rfind(std::string("provider '") + kCommand + "'", 0) != 0)
    Violation(std::string(call) + ": error does not name the command: " + st.message());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > (1u << 20)) return 0;
  const uint8_t mode = data[0];
  dcm::pipe::SetFakeChildOutput(std::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
  dcm::pipe::PipeOptions options;
  options.command = kCommand;
  std::unique_ptr<dcm::pipe::PipeProvider> provider;
  const dcm::Status started = dcm::pipe::PipeProvider::Start(options, &provider);
  CheckNamesCommand(started, "Start");
  if (!started.ok()) return 0;

  const dcm::ProviderCapabilities caps = provider->Capabilities();
  if (caps.width < 1 || caps.height < 1 || caps.width > (1 << 17) || caps.height > (1 << 17) || caps.threadSafe)
    Violation("handshake accepted with size " + std::to_string(caps.width) + "x" + std::to_string(caps.height));

  const dcm::Bounds2i region{{0, 0}, {std::min(caps.width, 8), std::min(caps.height, 8)}};
  const dcm::GuideRequest what{(mode & 1) != 0, (mode & 2) != 0, (mode & 4) != 0, (mode & 8) != 0};
  dcm::GuideImage guides;
  const dcm::Status g = provider->Guides(region, what, &guides);
  CheckNamesCommand(g, "Guides");
  if (g.ok()) {
    const size_t n = size_t(region.area());
    auto expect = [&](bool asked, bool offered, size_t got, const char* kind) {
      if (got != (asked && offered ? n : 0)) Violation(std::string("Guides: ") + kind + " of the wrong size");
    };
    expect(what.objectId, caps.objectId, guides.objectId.size(), "object IDs");
    expect(what.shaderId, caps.shaderId, guides.shaderId.size(), "shader IDs");
    expect(what.texture, caps.texture, guides.texture.size(), "texture");
    expect(what.normal, caps.normal, guides.normal.size(), "normals");
  }

  const dcm::Point2i pixels[3] = {{0, 0}, {caps.width - 1, caps.height - 1}, {caps.width / 2, 0}};
  dcm::ExactSample samples[3];
  const dcm::Status e =
      provider->Evaluate(pixels, dcm::SampleRequest{(mode & 16) != 0, (mode & 32) != 0}, samples);
  CheckNamesCommand(e, "Evaluate");
  if (!g.ok() && (e.ok() || e.message() != g.message())) Violation("Evaluate after a failed Guides: " + e.message());

  const dcm::Status f = provider->Finish();
  CheckNamesCommand(f, "Finish");
  if (!e.ok() && f.message() != e.message()) Violation("Finish after a failed Evaluate: " + f.message());
  return 0;
}

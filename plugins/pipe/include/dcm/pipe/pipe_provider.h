// A SampleProvider served by a child process (an out-of-process renderer) over
// its stdin/stdout with the dcm-pipe protocol (plugins/pipe/PROTOCOL.md).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "dcm/round_schedule.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm::pipe {

/// The version of the dcm-pipe protocol this library speaks.
inline constexpr int kProtocolVersion = 1;

/// How to start and talk to the child.
struct PipeOptions {
  /// Shell command line of the provider, run as `/bin/sh -c COMMAND` in its own
  /// process group; its stderr goes to ours.
  std::string command;
  /// Longest wait for the handshake, in seconds: the child starts up and may
  /// load its scene first.
  double startupTimeoutSeconds = 600.0;
  /// Longest wait for any later answer (guides, a batch of samples) and for
  /// the child to exit after "quit", in seconds.
  double timeoutSeconds = 600.0;
};

class ChildProcess;

/// Kills the process group of every child still running (SIGKILL). Async-
/// signal-safe: for a signal handler of the program (dcm's SIGINT, SIGTERM,
/// SIGHUP cleanup), so that no child outlives it.
void KillAllChildren();

/// Starts the child, performs the handshake and serves its guides and samples
/// to the engine. Every failure of the child (it crashes, exits early, sends
/// garbage or wrong counts, or does not answer in time) becomes an error
/// Status that names the command and what went wrong; after the first failure
/// the child is killed and every later call returns the same error.
/// Not thread safe for the engine (Capabilities().threadSafe is false); calls
/// are serialised by a mutex in any case.
class PipeProvider final : public SampleProvider {
 public:
  /// Starts `options.command` and reads its handshake. On error `*out` is
  /// untouched and the child is gone.
  static Status Start(const PipeOptions& options, std::unique_ptr<PipeProvider>* out);

  /// Ends the child if Finish() was not called: sends "quit" and kills the
  /// child when it has not exited 2 s later.
  ~PipeProvider() override;

  PipeProvider(const PipeProvider&) = delete;
  PipeProvider& operator=(const PipeProvider&) = delete;

  /// What the child announced in its handshake; threadSafe is always false.
  ProviderCapabilities Capabilities() const override;

  /// Asks the child for the guides of `region` ("guides" request).
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;

  /// Asks the child to evaluate `pixels` ("eval" request): one request
  /// whatever their number (a round of RoundSchedule::kPreview is one call).
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

  /// The pixels the child computed exactly besides those of the last "eval"
  /// (capability `extra`: the line 'extra M' and M records after its samples).
  void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) override;

  /// What a round costs, as the child announced it (round_latency=,
  /// sample_cost=; zero when it did not).
  const RoundCost& roundCost() const { return cost_; }

  /// Whether the child serves cheap preview samples (capability `preview`).
  bool hasPreview() const { return preview_; }

  /// The samples per pixel of the child's preview where it announced it
  /// (`preview_samples=`: the same image as its exact pixels, an unbiased
  /// estimate with noise, whose variance it serves); 0: not announced (a
  /// preview of some other kind, e.g. a lower resolution).
  double previewSamples() const { return previewSamples_; }

  /// Whether the child serves the preview's variance: it announced
  /// `variance` or `preview_samples=`.
  bool previewHasVariance() const { return caps_.variance || previewSamples_ > 0; }

  /// Asks the child for the preview samples of every pixel of `region`
  /// ("preview" request), row-major, with the preview's variance where
  /// `what.variance` and the child announced `variance` or
  /// `preview_samples=`. Only when hasPreview().
  /// `textureCovariance`, when given and the child announced
  /// `texture_covariance`: each pixel's covariance of the preview's estimates
  /// of the texture guide and of L (empty otherwise).
  Status Preview(const Bounds2i& region, const SampleRequest& what, std::vector<ExactSample>* out,
                 std::vector<RGB>* textureCovariance = nullptr);

  /// The child's preview of the whole image, fetched in one request, as a
  /// provider of stand-in samples for ReconstructWithPreview(); with
  /// `what.variance`, the preview's variance, pooled over the pixels of the
  /// same surface (object and shader IDs) within `varianceRadius` pixels
  /// (dcm::SurfaceWindowMean; 0: each pixel's own). `ownVariance`, when
  /// given: each pixel's own variance before the pooling (empty without).
  /// `textureCovariance`, when given: as Preview() with `what.split`
  /// (PreviewScheduleOptions::previewTextureCovariance).
  Status FetchPreview(const SampleRequest& what, std::unique_ptr<SampleProvider>* out, int varianceRadius = 0,
                      std::vector<RGB>* ownVariance = nullptr, std::vector<RGB>* textureCovariance = nullptr);

  /// Whether the child can render later exact samples at fewer samples per
  /// pixel (capability `exact_samples`).
  bool hasExactSamples() const { return exactSamples_; }

  /// Asks the child to render every later "eval" at `samples` per pixel
  /// ("exact_samples N" request; only when hasExactSamples()): fewer than
  /// the handshake's `samples=` where a goal does not need them all.
  Status SetExactSamples(int64_t samples);

  /// Sends "quit", closes the child's stdin and waits for it to exit. An exit
  /// status other than 0 (or a signal) is an error. Idempotent: returns the
  /// first outcome again.
  Status Finish();

  /// Every key=value of the child's handshake, the ones dcm does not use too
  /// (what a particular provider adds for its own command).
  const std::map<std::string, std::string>& handshakeKeys() const { return keys_; }

  /// "eval" requests sent so far (rounds of exact samples).
  int64_t evalRequests() const { return evalRequests_; }

  /// The protocol version the child announced.
  int childProtocolVersion() const { return childVersion_; }

 private:
  PipeProvider(PipeOptions options, std::unique_ptr<ChildProcess> child);
  Status Handshake();
  /// Records the first failure, kills the child and returns the failure.
  Status Fail(const std::string& what);
  /// Sends the one-line `request` and reads the answer line, which must begin
  /// with `keyword`, split into `answer`; a failure kills the child.
  Status Ask(const std::string& request, const std::string& keyword, std::vector<std::string>* answer);
  /// Prefixes messages with the provider's command.
  std::string Prefix() const;

  PipeOptions options_;
  std::unique_ptr<ChildProcess> child_;
  /// Sends `request` with `payload`, reads the answer 'samples N' and its
  /// records of the parts of `split`/`variance` into `out` (n of them), and
  /// with `textureCovariance` the part `texcov` into it.
  Status ReadSamples(const std::string& request, const std::vector<char>& message, size_t n, bool split,
                     bool variance, ExactSample* out, RGB* textureCovariance = nullptr);
  /// Reads n records of the parts of `split`/`variance` (and `texcov` with
  /// `textureCovariance`) that follow an answer to `request` into `out`.
  Status ReadRecords(const std::string& request, size_t n, bool split, bool variance, ExactSample* out,
                     RGB* textureCovariance = nullptr);
  /// Reads the answer 'extra M' to `request`, M pixels and their records, into extraPixels_/extraSamples_.
  Status ReadExtra(const std::string& request, bool split, bool variance);

  ProviderCapabilities caps_;
  RoundCost cost_;
  std::map<std::string, std::string> keys_;
  bool preview_ = false;
  bool textureCovariance_ = false;  ///< capability `texture_covariance`
  bool extra_ = false;              ///< capability `extra`
  bool exactSamples_ = false;       ///< capability `exact_samples`
  double previewSamples_ = 0;       ///< preview_samples=, 0: none
  std::vector<Point2i> extraPixels_;      ///< the last eval's extra pixels
  std::vector<ExactSample> extraSamples_;
  int64_t evalRequests_ = 0;
  int childVersion_ = 0;
  std::mutex mutex_;
  Status broken_;  ///< the first failure; OK while healthy
  bool finished_ = false;
  Status finishStatus_;
};

}  // namespace dcm::pipe

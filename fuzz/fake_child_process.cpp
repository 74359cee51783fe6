// A ChildProcess (plugins/pipe/src/child_process.h) that runs nothing: what
// the "child" sends is the bytes the fuzz target hands to SetFakeChildOutput,
// and what it is sent is discarded. Linked into fuzz_pipe in place of
// child_process.cpp, so the protocol code of pipe_provider.cpp runs in
// process on the fuzzer's bytes, unchanged.
#include <cstring>
#include <string>
#include <string_view>

#include "child_process.h"

namespace dcm::pipe {
namespace {
std::string_view g_output;
}  // namespace

/// The bytes the next spawned child writes to its stdout, then end of file.
void SetFakeChildOutput(std::string_view bytes) { g_output = bytes; }

Status ChildProcess::Spawn(const std::string&, std::unique_ptr<ChildProcess>* out) {
  std::unique_ptr<ChildProcess> c(new ChildProcess());
  c->buffer_.assign(g_output.begin(), g_output.end());
  c->begin_ = 0;
  c->end_ = c->buffer_.size();
  *out = std::move(c);
  return Status::Ok();
}

ChildProcess::~ChildProcess() = default;

Status ChildProcess::Write(const void*, size_t, Clock::time_point) {
  if (reaped_) return Status::Error("it closed its input (stdin)");
  return Status::Ok();
}

Status ChildProcess::ReadLine(std::string* line, size_t maxLength, Clock::time_point) {
  const char* start = buffer_.data() + begin_;
  const void* nl = end_ > begin_ ? std::memchr(start, '\n', end_ - begin_) : nullptr;
  if (!nl) return Status::Error(end_ - begin_ > maxLength ? "line too long" : "end of file");
  const size_t len = size_t(static_cast<const char*>(nl) - start);
  if (len > maxLength) return Status::Error("line too long");
  line->assign(start, len);
  begin_ += len + 1;
  return Status::Ok();
}

Status ChildProcess::Read(void* data, size_t size, Clock::time_point) {
  if (end_ - begin_ < size) {
    begin_ = end_;
    return Status::Error("end of file");
  }
  if (size > 0) std::memcpy(data, buffer_.data() + begin_, size);
  begin_ += size;
  return Status::Ok();
}

void ChildProcess::CloseInput() {}

bool ChildProcess::WaitExit(Clock::time_point) {
  reaped_ = true;  // exits with status 0 when asked
  return true;
}

void ChildProcess::Kill() {
  if (!reaped_) waitStatus_ = 9;  // as if killed by SIGKILL
  reaped_ = true;
}

std::string ChildProcess::ExitDescription() const {
  if (!reaped_) return "is still running";
  return waitStatus_ == 0 ? "exited with status 0" : "was killed by signal 9";
}

bool ChildProcess::exitedCleanly() const { return reaped_ && waitStatus_ == 0; }

}  // namespace dcm::pipe

// Running POV-Ray: one process per pass, through plugins/pipe's ChildProcess
// (a supervisor in its own process group that takes POV-Ray with it when dcm
// dies, even by SIGKILL).
#include "povray_process.h"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <thread>

#include "child_process.h"
#include "dcm/pipe/run_command.h"
#include "scratch_dir.h"

namespace dcm::povray {

namespace {

using pipe::ShellQuote;

std::string Dirname(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

/// The shell command of `job`. -D: no display (Debian's povray.ini turns it
/// on); -A: no antialiasing (the split L = tau*L_i + L_c holds per ray); +FE:
/// OpenEXR (half float, linear under assumed_gamma 1.0). The scene and its
/// folder come from ScratchIni() (WriteSceneIni): POV-Ray splits its command
/// line at spaces, also within a quoted +I or +L option.
std::string CommandLine(const PovrayEnv& env, const PovrayJob& job) {
  // append(), not operator+ on literals: GCC 12 warns (-Wrestrict) on those.
  std::string c = "cd ";
  for (const std::string& word :
       {ShellQuote(JobFolder(env, job)), std::string("&& exec"), ShellQuote(env.executable), std::string("-D -A +FE"),
        "+W" + std::to_string(job.width), "+H" + std::to_string(job.height),
        "Declare=Pass=" + std::to_string(job.pass)})
    c.append(word).append(" ");
  for (const auto& a : job.args) c.append(ShellQuote(a)).append(" ");
  c.append(ScratchIni()).append(" +O").append(ScratchRender(job.pass));
  c.append(" </dev/null >").append(ScratchLog(job.pass)).append(" 2>&1");
  return c;
}

/// What POV-Ray's log says went wrong: its error lines, else its last lines.
std::string LogExcerpt(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines, errors;
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    lines.push_back(line);
    if (line.find("Error") != std::string::npos || line.find("error:") != std::string::npos ||
        line.find("Fatal") != std::string::npos || line.find("not found") != std::string::npos)
      errors.push_back(line);
  }
  const auto& pick = errors.empty() ? lines : errors;
  std::string s;
  for (size_t i = pick.size() > 3 ? pick.size() - 3 : 0; i < pick.size(); ++i) s += (s.empty() ? "" : " | ") + pick[i];
  return s.empty() ? "(no output)" : s;
}

std::string Failed(const PovrayEnv& env, const PovrayJob& job) {
  return "rendering " + job.what + " of " + env.sceneName + " failed";
}

}  // namespace

Status WriteSceneIni(const std::string& folder, const std::string& scene) {
  if (scene.find('"') != std::string::npos)
    return Status::Error("the scene's path " + scene + " holds a '\"', which POV-Ray's INI files cannot quote");
  const std::string path = folder + "/" + ScratchIni();
  std::ofstream ini(path);
  ini << "Input_File_Name=\"" << scene << "\"\nLibrary_Path=\"" << Dirname(scene) << "\"\n";
  ini.close();
  if (!ini) return Status::Error("cannot write " + path);
  return Status::Ok();
}

std::string JobFolder(const PovrayEnv& env, const PovrayJob& job) {
  return job.folder.empty() ? env.scratch : env.scratch + "/" + job.folder;
}

Status FindExecutable(const std::string& name, std::string* path) {
  if (name.empty()) return Status::Error("--povray: empty");
  if (name.find('/') != std::string::npos) {
    if (::access(name.c_str(), X_OK) != 0)
      return Status::Error("POV-Ray '" + name + "' is not an executable file");
    *path = name;
    return Status::Ok();
  }
  const char* env = std::getenv("PATH");
  std::string dirs = env ? env : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
    const std::string candidate = dir + "/" + name;
    if (::access(candidate.c_str(), X_OK) == 0) {
      *path = candidate;
      return Status::Ok();
    }
    start = end + 1;
  }
  return Status::Error("POV-Ray ('" + name +
                       "') is not on PATH (Debian: apt-get install povray; or give --povray PATH)");
}

Status RunJobs(const PovrayEnv& env, std::span<const PovrayJob> jobs) {
  struct Running {
    const PovrayJob* job;
    std::unique_ptr<pipe::ChildProcess> child;
  };
  std::vector<Running> running;  // destroyed on any return: kills what still runs
  size_t next = 0;
  const int concurrency = std::max(1, env.concurrency);
  while (next < jobs.size() || !running.empty()) {
    while (next < jobs.size() && int(running.size()) < concurrency) {
      const PovrayJob& job = jobs[next++];
      std::unique_ptr<pipe::ChildProcess> child;
      if (Status st = pipe::ChildProcess::Spawn(CommandLine(env, job), &child); !st.ok())
        return Status::Error(Failed(env, job) + ": " + st.message());
      child->CloseInput();
      running.push_back({&job, std::move(child)});
    }
    bool progressed = false;
    for (size_t i = 0; i < running.size();) {
      if (!running[i].child->WaitExit(pipe::ChildProcess::Clock::now())) {
        ++i;
        continue;
      }
      progressed = true;
      if (!running[i].child->exitedCleanly())
        return Status::Error(Failed(env, *running[i].job) + ": POV-Ray (" + env.executable + ") " +
                             running[i].child->ExitDescription() +
                             ": " + LogExcerpt(JobFolder(env, *running[i].job) + "/" + ScratchLog(running[i].job->pass)));
      running.erase(running.begin() + std::ptrdiff_t(i));
    }
    // POV-Ray polls its own renderer in 50-100 ms steps; 5 ms here costs nothing.
    if (!progressed) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return Status::Ok();
}

Status ReadRender(const PovrayEnv& env, const PovrayJob& job, std::vector<RGB>* rgb) {
  const std::string path = JobFolder(env, job) + "/" + ScratchRender(job.pass);
  auto fail = [&](const std::string& why) {
    return Status::Error(Failed(env, job) + ": " + why + " (POV-Ray's log: " +
                         LogExcerpt(JobFolder(env, job) + "/" + ScratchLog(job.pass)) + ")");
  };
  auto in = OIIO::ImageInput::open(path);
  if (!in) return fail("it wrote no readable image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width != job.width || spec.height != job.height)
    return fail("the image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ", not " +
                std::to_string(job.width) + "x" + std::to_string(job.height));
  int r = -1, g = -1, b = -1;
  for (int c = 0; c < spec.nchannels; ++c) {
    const std::string& n = spec.channelnames[size_t(c)];
    if (n == "R") r = c;
    if (n == "G") g = c;
    if (n == "B") b = c;
  }
  if (r < 0 || g < 0 || b < 0) return fail("the image has no R, G, B channels");
  const size_t n = size_t(spec.width) * size_t(spec.height);
  std::vector<float> all(n * size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    return fail("cannot read the image: " + in->geterror());
  rgb->resize(n);
  const size_t nc = size_t(spec.nchannels);
  for (size_t i = 0; i < n; ++i)
    (*rgb)[i] = RGB{all[i * nc + size_t(r)], all[i * nc + size_t(g)], all[i * nc + size_t(b)]};
  return Status::Ok();
}

}  // namespace dcm::povray

// POV-Ray processes: the command line of one pass render, several run side by
// side, their EXRs read back.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "dcm/color.h"
#include "dcm/status.h"

namespace dcm::povray {

/// One POV-Ray process: pass `pass` at `width` x `height`, written to
/// ScratchRender(pass) with its log in ScratchLog(pass), in the scratch
/// folder or its subfolder `folder` (its own pixels.inc).
struct PovrayJob {
  int pass = 0;
  std::string folder;  ///< "" or ScratchSubfolder()
  int width = 0, height = 0;
  std::vector<std::string> args;  ///< more POV-Ray options (+SR2, Declare=Sparse=1, ...)
  std::string what;               ///< "pass 4 (illumination)", for messages
};

/// Where and how POV-Ray runs.
struct PovrayEnv {
  std::string executable;  ///< the POV-Ray found
  std::string scene;       ///< absolute path of the .pov file
  std::string sceneName;   ///< as the user named it, for messages
  std::string scratch;     ///< the working folder of the processes
  int concurrency = 2;
};

/// The executable `name` names: itself when it contains a '/', else the first
/// match on PATH. Fails when there is none or it is not executable.
Status FindExecutable(const std::string& name, std::string* path);

/// Runs `jobs`, `env.concurrency` at a time (each in its own process group,
/// killed with dcm; see plugins/pipe's ChildProcess), in `env.scratch` as the
/// working folder: POV-Ray's I/O restrictions allow the current folder.
/// Fails at the first process that fails ("rendering pass 4 (illumination)
/// of scene.pov failed: POV-Ray exited with status 1: Parse Error: ..."),
/// the others killed.
Status RunJobs(const PovrayEnv& env, std::span<const PovrayJob> jobs);

/// Writes ScratchIni() into `folder`: the scene (an absolute path) and its
/// folder for its include files, since POV-Ray runs in the scratch folder.
Status WriteSceneIni(const std::string& folder, const std::string& scene);

/// The folder `job` runs in.
std::string JobFolder(const PovrayEnv& env, const PovrayJob& job);

/// Reads R, G, B of the render of `job` (half-float EXR) and checks its size.
Status ReadRender(const PovrayEnv& env, const PovrayJob& job, std::vector<RGB>* rgb);

}  // namespace dcm::povray

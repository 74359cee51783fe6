// The private scratch folder of a POV-Ray run: the pixel lists POV-Ray reads
// and the passes it writes. Only files of fixed names live in it, so that a
// signal handler can remove them without listing the folder.
#pragma once

#include <string>

#include "dcm/status.h"

namespace dcm::povray {

/// The file names a scratch folder may hold: the pixel list, the INI file, and per pass
/// (0 to 5) a render, a log and POV-Ray's state file while it renders
/// (passN.pov-state).
std::string ScratchPixelList();                 ///< "pixels.inc" (the name scene files include)
std::string ScratchIni();                       ///< "scene.ini": the scene and its folder, for POV-Ray
/// "li": the folder of the illumination pass's own pixel list, when it
/// renders fewer pixels than the beauty pass (the same file names inside).
std::string ScratchSubfolder();
std::string ScratchRender(int pass);            ///< "pass4.exr"
std::string ScratchLog(int pass);               ///< "pass4.log"

/// Makes a folder only this user may enter, under $TMPDIR or /tmp, and
/// registers it for RemoveScratchOnSignal(). One at a time.
Status MakeScratch(std::string* path);

/// Removes the folder and everything in it, and unregisters it.
void RemoveScratch(const std::string& path);

/// Removes the registered folder's files and the folder (async-signal-safe).
void RemoveScratchOnSignal();

}  // namespace dcm::povray

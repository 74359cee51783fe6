// The file names in the private scratch folder of a POV-Ray run
// (pipe::ScratchFolder): the pixel lists POV-Ray reads and the passes it writes.
#pragma once

#include <string>

namespace dcm::povray {

std::string ScratchPixelList();                 ///< "pixels.inc" (the name scene files include)
std::string ScratchIni();                       ///< "scene.ini": the scene and its folder, for POV-Ray
/// "li": the folder of the illumination pass's own pixel list, when it
/// renders fewer pixels than the beauty pass (the same file names inside).
std::string ScratchSubfolder();
std::string ScratchRender(int pass);            ///< "pass4.exr"
std::string ScratchLog(int pass);               ///< "pass4.log"

}  // namespace dcm::povray

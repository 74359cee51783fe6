// The file names in a POV-Ray run's scratch folder.
#include "scratch_dir.h"

namespace dcm::povray {

std::string ScratchPixelList() { return "pixels.inc"; }
std::string ScratchSubfolder() { return "li"; }
std::string ScratchIni() { return "scene.ini"; }
std::string ScratchRender(int pass) { return "pass" + std::to_string(pass) + ".exr"; }
std::string ScratchLog(int pass) { return "pass" + std::to_string(pass) + ".log"; }

}  // namespace dcm::povray

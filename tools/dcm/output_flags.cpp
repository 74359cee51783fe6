#include "output_flags.h"

namespace dcm::cli {

void AddExrFormatFlags(CLI::App* app, toolkit::ExrFormat* format) {
  app->add_option("-d", format->dataType,
                  "output EXR type: half or float (integer IDs and Cryptomatte keep theirs; default: the "
                  "beauty float, copied passes their input's type)");
  app->add_option("--compression", format->compression,
                  "output EXR compression: none, zip, zips, piz, rle, pxr24, b44, b44a, dwaa, dwab")
      ->capture_default_str();
  app->add_option("--ch", format->channels, "output EXR channels to write (names as in the output, comma-separated)")
      ->delimiter(',');
}

void AddDisplayFlags(CLI::App* app, toolkit::DisplayTransform* transform) {
  app->add_option("--colorconfig", transform->config, "OpenColorIO config of the previews (default: $OCIO)");
  app->add_option("--display", transform->display, "preview display (default: the config's)");
  app->add_option("--view", transform->view, "preview view (default: the display's)");
  app->add_option("--look", transform->look, "preview looks, comma-separated (default: the view's)");
}

}  // namespace dcm::cli

// `present: picture | egl`, one rule for the outputs that can show the surround view as OpenGL
// drew it (window, display).
#include <fmt/format.h>

#include "daemon/built_in_outputs.hpp"

namespace surroundd::daemon {

ConfigKey<OutputConfig> presentKey(std::string_view doc) {
  return ConfigKey<OutputConfig>::choice(
      "present", &OutputConfig::present,
      {{"picture", ViewPresent::kPicture}, {"egl", ViewPresent::kEgl}}, doc);
}

void checkPresent(YamlObject& item, const OutputConfig& output, std::string_view type) {
  if (output.present == ViewPresent::kEgl && output.stream != OutputStream::kSurround) {
    item.error("present", fmt::format("egl shows the surround view as OpenGL draws it: the {}'s "
                                      "stream must be surround",
                                      type));
  }
}

}  // namespace surroundd::daemon

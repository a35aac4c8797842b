// The `display` output: a screen driven through DRM/KMS (render::DrmDisplaySink), whose page flips
// wait for vblank on a thread of their own behind a queue.
#include "daemon/built_in_outputs.hpp"
#include "render/outputs/drm_display_sink.hpp"

namespace surroundd::daemon {
namespace {

// A screen shows the newest picture: one may wait for the next vblank.
constexpr std::size_t kDisplayQueue = 1;

std::unique_ptr<render::FrameSink> openDisplay(const OutputConfig& output,
                                               const OutputContext& context) {
  return queuedSink(std::make_unique<render::DrmDisplaySink>(
                        render::DrmDisplaySettings{output.device, output.connector}),
                    context, kDisplayQueue);
}

}  // namespace

OutputType displayOutputType() {
  OutputType type;
  type.name = "display";
  using Key = ConfigKey<OutputConfig>;
  // Both default to the first connected screen: their values in the reference are examples.
  type.keys = {
      Key::text("device", &OutputConfig::device, "the DRM card", Shown::kExample),
      Key::text("connector", &OutputConfig::connector, "the screen's connector", Shown::kExample),
  };
  type.openPictureSink = openDisplay;
  return type;
}

}  // namespace surroundd::daemon

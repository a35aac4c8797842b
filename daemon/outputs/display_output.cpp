// The `display` output: a screen driven through DRM/KMS. With `present: picture`
// (render::DrmDisplaySink) it is handed each picture read back, and its page flips wait for
// vblank on a thread of their own behind a queue; with `present: egl` (render::EglDisplaySink) it
// shows the surround view as OpenGL drew it, on the renderer's thread, through EGL: the renderer's
// context is then made on the card's GBM device, and the card is opened (as its master) for it.
#include <fmt/format.h>

#include "daemon/outputs/built_in_outputs.hpp"
#include "render/outputs/drm_display_sink.hpp"
#include "render/outputs/egl_display_sink.hpp"

namespace surroundd::daemon {
namespace {

// A screen shows the newest picture: one may wait for the next vblank.
constexpr std::size_t kDisplayQueue = 1;

std::string cardName(const OutputConfig& output) {
  return output.device.empty() ? std::string("the first card with a screen")
                               : output.device.string();
}

std::unique_ptr<render::FrameSink> openDisplay(const OutputConfig& output,
                                               const OutputContext& context) {
  if (output.present == ViewPresent::kPicture) {
    return queuedSink(std::make_unique<render::DrmDisplaySink>(
                          render::DrmDisplaySettings{output.device, output.connector}),
                      context, kDisplayQueue);
  }
  render::EglContext& gl = presentingRenderer(
      context, render::EglPlatform::kGbm, fmt::format("display on {}", cardName(output)), "card");
  return std::make_unique<render::EglDisplaySink>(gl, output.connector);
}

// The renderer's context on the GBM device of the card of a display that shows the views through
// EGL; the context keeps the card open, as its DRM master, for as long as it lives.
std::unique_ptr<render::EglContext> openRendererOnCard(const OutputConfig& output) {
  if (output.present != ViewPresent::kEgl) return nullptr;
  auto card = std::make_shared<render::DrmCard>(
      render::DrmDisplaySettings{output.device, output.connector});
  void* device = card->gbm();
  return std::make_unique<render::EglContext>(render::EglPlatform::kGbm, device, std::move(card));
}

void checkDisplay(YamlObject& item, OutputConfig& output) { checkPresent(item, output, "display"); }

// The renderer draws on one card: every egl display is on it.
std::optional<OutputConflict> otherCard(const OutputConfig& earlier, const OutputConfig& output) {
  if (earlier.present != ViewPresent::kEgl || output.present != ViewPresent::kEgl ||
      earlier.device == output.device) {
    return std::nullopt;
  }
  return OutputConflict{"device",
                        fmt::format("an egl display must be on the card of the renderer, which an "
                                    "earlier egl display puts on {}",
                                    cardName(earlier))};
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
      presentKey("how it shows the view: picture (read back, copied to the screen) or egl "
                 "(drawn into the screen's buffers on the GPU; the renderer then runs on that "
                 "card)"),
  };
  type.readSettings = checkDisplay;
  type.conflict = otherCard;
  type.openPictureSink = openDisplay;
  type.openRenderer = openRendererOnCard;
  return type;
}

}  // namespace surroundd::daemon

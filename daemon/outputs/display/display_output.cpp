#include "daemon/outputs/display/display_output.hpp"

#include <fmt/format.h>

#include "render/outputs/drm_display_sink.hpp"
#include "render/outputs/egl_display_sink.hpp"

namespace surroundd::daemon {
namespace {

// A screen shows the newest picture: one may wait for the next vblank.
constexpr std::size_t kDisplayQueue = 1;

std::string cardName(const DisplayOutputSettings& settings) {
  return settings.device.empty() ? std::string("the first card with a screen")
                                 : settings.device.string();
}

std::unique_ptr<render::FrameSink> openDisplay(const OutputConfig& output,
                                               const OutputContext& context) {
  const auto& own = settingsOf<DisplayOutputSettings>(output);
  if (own.present == ViewPresent::kPicture) {
    return queuedSink(std::make_unique<render::DrmDisplaySink>(
                          render::DrmDisplaySettings{own.device, own.connector}),
                      context, kDisplayQueue);
  }
  render::EglContext& gl = presentingRenderer(context, render::EglPlatform::kGbm,
                                              fmt::format("display on {}", cardName(own)), "card");
  return std::make_unique<render::EglDisplaySink>(gl, own.connector);
}

// The renderer's context on the GBM device of the card of a display that shows the views through
// EGL; the context keeps the card open, as its DRM master, for as long as it lives.
std::unique_ptr<render::EglContext> openRendererOnCard(const OutputConfig& output) {
  const auto& own = settingsOf<DisplayOutputSettings>(output);
  if (own.present != ViewPresent::kEgl) return nullptr;
  auto card =
      std::make_shared<render::DrmCard>(render::DrmDisplaySettings{own.device, own.connector});
  void* device = card->gbm();
  return std::make_unique<render::EglContext>(render::EglPlatform::kGbm, device, std::move(card));
}

}  // namespace

OutputType displayOutputType() {
  OutputType type;
  type.name = "display";
  using Key = ConfigKey<DisplayOutputSettings>;
  // Both default to the first connected screen: their values in the reference are examples.
  readsSettings<DisplayOutputSettings>(
      type,
      {
          Key::text("device", &DisplayOutputSettings::device, "the DRM card", Shown::kExample),
          Key::text("connector", &DisplayOutputSettings::connector, "the screen's connector",
                    Shown::kExample),
          presentKey<DisplayOutputSettings>(
              "how it shows the view: picture (read back, copied to the screen) or egl (drawn "
              "into the screen's buffers on the GPU; the renderer then runs on that card)"),
      },
      presentCheck<DisplayOutputSettings>("display"));
  type.conflict = onePlaceForEgl<DisplayOutputSettings>("display", "card", "device", cardName);
  type.openPictureSink = openDisplay;
  type.openRenderer = openRendererOnCard;
  return type;
}

}  // namespace surroundd::daemon

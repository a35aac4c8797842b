#include "daemon/outputs/h264_settings.hpp"

namespace surroundd::daemon {

void checkEncoder(YamlObject& item, const H264Settings& h264) {
  if (const auto problem = render::h264EncoderProblem(h264.encoder)) {
    item.error("encoder", *problem);
  }
}

render::VideoEncoderSettings encoderSettings(const H264Settings& h264,
                                             const OutputContext& context) {
  render::VideoEncoderSettings settings;
  settings.size = context.pictureSize;
  settings.nominalFps = context.nominalFps;
  settings.crf = h264.crf;
  settings.preset = h264.preset;
  settings.pixelFormat = h264.pixelFormat;
  settings.encoder = h264.encoder;
  return settings;
}

}  // namespace surroundd::daemon

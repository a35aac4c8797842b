#include "capture/v4l2_formats.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace surroundd::capture {

bool V4l2Offer::has(cv::Size size) const {
  if (anySize) {
    return size.width >= smallest.width && size.width <= largest.width &&
           size.height >= smallest.height && size.height <= largest.height;
  }
  return std::ranges::find(sizes, size) != sizes.end();
}

std::string fourccText(std::uint32_t code) {
  std::string text(4, ' ');
  for (int i = 0; i < 4; ++i)
    text[static_cast<std::size_t>(i)] = static_cast<char>((code >> (8 * i)) & 0xff);
  return text;
}

std::vector<V4l2Offer> offersOf(V4l2Device& device, std::uint32_t bufferType) {
  std::vector<V4l2Offer> offers;
  for (std::uint32_t i = 0;; ++i) {
    v4l2_fmtdesc description{};
    description.index = i;
    description.type = bufferType;
    if (device.ioctl(VIDIOC_ENUM_FMT, &description) != 0) break;
    V4l2Offer offer;
    offer.fourcc = description.pixelformat;
    for (std::uint32_t k = 0;; ++k) {
      v4l2_frmsizeenum size{};
      size.index = k;
      size.pixel_format = offer.fourcc;
      if (device.ioctl(VIDIOC_ENUM_FRAMESIZES, &size) != 0) break;
      if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        offer.sizes.emplace_back(static_cast<int>(size.discrete.width),
                                 static_cast<int>(size.discrete.height));
      } else {
        offer.anySize = true;
        offer.smallest = {static_cast<int>(size.stepwise.min_width),
                          static_cast<int>(size.stepwise.min_height)};
        offer.largest = {static_cast<int>(size.stepwise.max_width),
                         static_cast<int>(size.stepwise.max_height)};
        break;
      }
    }
    offers.push_back(std::move(offer));
  }
  return offers;
}

std::string describe(const std::vector<V4l2Offer>& offers) {
  std::string text;
  for (const auto& offer : offers) {
    text += fmt::format("{}{}", text.empty() ? "" : "; ", fourccText(offer.fourcc));
    if (offer.anySize) {
      text += fmt::format(" {}x{} to {}x{}", offer.smallest.width, offer.smallest.height,
                          offer.largest.width, offer.largest.height);
    }
    for (std::size_t k = 0; k < offer.sizes.size(); ++k) {
      text +=
          fmt::format("{}{}x{}", k == 0 ? " " : ", ", offer.sizes[k].width, offer.sizes[k].height);
    }
  }
  return text.empty() ? "nothing" : text;
}

}  // namespace surroundd::capture

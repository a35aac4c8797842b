#include "capture/v4l2_formats.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace surroundd::capture {

bool V4l2Offer::has(cv::Size size) const {
  if (anySize) {
    return size.width >= smallest.width && size.width <= largest.width &&
           size.height >= smallest.height && size.height <= largest.height;
  }
  return std::ranges::find(sizes, size) != sizes.end();
}

std::string fourccText(std::uint32_t code) {
  // Bit 31 marks the big-endian variant of a format (V4L2_PIX_FMT_FLAG_BE); short names are
  // padded with spaces ("Y10 ").
  constexpr std::uint32_t kBigEndian = 1U << 31;
  std::string text(4, ' ');
  for (int i = 0; i < 4; ++i) {
    text[static_cast<std::size_t>(i)] = static_cast<char>(((code & ~kBigEndian) >> (8 * i)) & 0xff);
  }
  text.erase(text.find_last_not_of(' ') + 1);
  return (code & kBigEndian) != 0 ? text + "-BE" : text;
}

namespace {

std::vector<double> ratesOf(V4l2Device& device, std::uint32_t fourcc,
                            const v4l2_frmsize_discrete& size) {
  std::vector<double> rates;
  for (std::uint32_t k = 0;; ++k) {
    v4l2_frmivalenum interval{};
    interval.index = k;
    interval.pixel_format = fourcc;
    interval.width = size.width;
    interval.height = size.height;
    if (device.ioctl(VIDIOC_ENUM_FRAMEINTERVALS, &interval) != 0 ||
        interval.type != V4L2_FRMIVAL_TYPE_DISCRETE) {
      break;
    }
    if (interval.discrete.numerator != 0) {
      rates.push_back(static_cast<double>(interval.discrete.denominator) /
                      interval.discrete.numerator);
    }
  }
  return rates;
}

}  // namespace

std::vector<V4l2Offer> offersOf(V4l2Device& device, std::uint32_t bufferType, FrameRates rates) {
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
        if (rates == FrameRates::kListed) {
          offer.rates.push_back(ratesOf(device, offer.fourcc, size.discrete));
        }
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

std::string describe(const std::vector<V4l2Offer>& offers, FrameRates rates) {
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
      if (rates == FrameRates::kListed && k < offer.rates.size() && !offer.rates[k].empty()) {
        text += fmt::format(" ({:g} fps)", fmt::join(offer.rates[k], ", "));
      }
    }
  }
  return text.empty() ? "nothing" : text;
}

}  // namespace surroundd::capture

#pragma once
// The page surround-calibrate guide serves at "/": one self-contained HTML file (no external
// resources) that draws what /state.json says. Elements tests rely on: #live (the camera,
// /stream.mjpg), #phase (data-phase collecting / passed / ended), #views (one li per kept view),
// #coverage (a canvas; data-covered is the covered share in percent), #hints (one li each),
// #verdict (data-state none / pass / fail), #written, #error.

#include <string>
#include <string_view>

namespace surroundd::calibrate {

std::string_view guidePage();

// A guide page: `style` (CSS rules), `body` (HTML) and `script` (JavaScript defining show(state),
// which the page calls with each /state.json) in the frame both guide pages share.
std::string guidePageFrom(std::string_view title, std::string_view style, std::string_view body,
                          std::string_view script);

}  // namespace surroundd::calibrate

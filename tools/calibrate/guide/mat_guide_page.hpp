#pragma once
// The guided mat calibration's page (surround-calibrate guide --mat): the cameras and the
// stitched top view (/stream.mjpg), a table per camera, the seams in centimetres against the
// stated limit, the verdict and the rig written, all read from /state.json every 300 ms. One
// self-contained HTML file. Elements tests rely on: #live, #phase (data-phase waiting / failed /
// passed / ended), #verdict (data-state none / pass / fail), #seam-limit ("(limit C cm RMS)"),
// #seams and #cameras (a tbody row each, data-passed true / false / null; a seam's cells:
// cameras, board, RMS cm, max cm, verdict), #hints, #written, #error.

#include <string_view>

namespace surroundd::calibrate {

std::string_view matGuidePage();

}  // namespace surroundd::calibrate

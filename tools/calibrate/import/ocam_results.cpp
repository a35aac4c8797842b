#include "tools/calibrate/import/ocam_results.hpp"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "common/regular_file.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

constexpr std::size_t kMaxOcamFileBytes = std::size_t{1} << 20;

// The data lines in order; comment lines start with '#'.
constexpr std::array<std::string_view, 5> kSections{
    "pol (count, then the coefficients of the direct mapping)",
    "invpol (count, then the coefficients of the inverse mapping)",
    "the centre: xc (row) and yc (column)", "the affine parameters c, d, e",
    "the image size: height and width"};

}  // namespace

processing::Intrinsics fromOcamNative(const OcamNative& native) {
  processing::Intrinsics lens;
  lens.model = processing::LensModel::kOcam;
  lens.imageSize = native.imageSize;
  lens.cx = native.ycColumn;
  lens.cy = native.xcRow;
  const double c = native.c;
  lens.ocam.c = 1 / c;
  lens.ocam.d = native.e / c;
  lens.ocam.e = native.d / c;
  // rho' = c rho: invpol scales by c; pol(rho) becomes c pol(rho' / c), coefficient i by c^(1-i).
  for (const double p : native.invpol) lens.ocam.worldToImage.push_back(c * p);
  double power = c;
  for (const double a : native.pol) {
    lens.ocam.imageToWorld.push_back(a * power);
    power /= c;
  }
  return lens;
}

OcamNative toOcamNative(const processing::Intrinsics& lens) {
  OcamNative native;
  const double c = 1 / lens.ocam.c;
  native.c = c;
  native.d = lens.ocam.e * c;
  native.e = lens.ocam.d * c;
  native.xcRow = lens.cy;
  native.ycColumn = lens.cx;
  native.imageSize = lens.imageSize;
  for (const double p : lens.ocam.worldToImage) native.invpol.push_back(p / c);
  double power = c;
  for (const double a : lens.ocam.imageToWorld) {
    native.pol.push_back(a / power);
    power /= c;
  }
  return native;
}

processing::Intrinsics readOcamResults(const std::filesystem::path& file) {
  // A results file is a few hundred bytes: a FIFO, a device or a file past 1 MiB is refused
  // (one linked to /dev/zero grew by 400 MB/s, read as one endless line).
  std::istringstream stream;
  try {
    stream.str(readRegularFile(file, kMaxOcamFileBytes));
  } catch (const FileReadError& error) {
    throw UsageError(error.what());
  }
  std::vector<std::pair<int, std::vector<double>>> lines;  // line number, numbers
  int number = 0;
  for (std::string line; std::getline(stream, line) && lines.size() < kSections.size();) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream words(line);
    std::vector<double> values;
    for (std::string word; words >> word;) {
      try {
        std::size_t used = 0;
        values.push_back(std::stod(word, &used));
        if (used != word.size()) throw std::invalid_argument(word);
      } catch (const std::exception&) {
        throw UsageError(fmt::format("{}:{}: {}: expected numbers, got '{}'", file.string(), number,
                                     kSections[lines.size()], word));
      }
    }
    lines.emplace_back(number, std::move(values));
  }
  if (lines.size() < kSections.size()) {
    throw UsageError(fmt::format("{}: ends before {} (is it OCamCalib's calib_results.txt?)",
                                 file.string(), kSections[lines.size()]));
  }
  const auto fail = [&](std::size_t section, std::string_view what) {
    return UsageError(fmt::format("{}:{}: {}: expected {}", file.string(), lines[section].first,
                                  kSections[section], what));
  };
  OcamNative native;
  for (std::size_t section = 0; section < 2; ++section) {
    const auto& values = lines[section].second;
    if (values.empty() || values[0] < 1 || values[0] != std::floor(values[0]) ||
        values.size() != static_cast<std::size_t>(values[0]) + 1) {
      throw fail(section, "a count followed by that many coefficients");
    }
    (section == 0 ? native.pol : native.invpol).assign(values.begin() + 1, values.end());
  }
  const auto& centre = lines[2].second;
  const auto& affine = lines[3].second;
  const auto& size = lines[4].second;
  if (centre.size() != 2) throw fail(2, "two numbers");
  if (affine.size() != 3 || std::abs(affine[0]) < 1e-6) throw fail(3, "three numbers, c not 0");
  if (size.size() != 2 || size[0] < 16 || size[1] < 16 || size[0] > 16384 || size[1] > 16384) {
    throw fail(4, "two whole numbers from 16 to 16384");
  }
  native.xcRow = centre[0];
  native.ycColumn = centre[1];
  native.c = affine[0];
  native.d = affine[1];
  native.e = affine[2];
  native.imageSize = {static_cast<int>(size[1]), static_cast<int>(size[0])};
  return fromOcamNative(native);
}

}  // namespace surroundd::calibrate

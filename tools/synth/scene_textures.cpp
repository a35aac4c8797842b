#include "tools/synth/scene_textures.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "tools/synth/hash.hpp"

namespace surroundd::synth {
namespace {

// Per-texel uniform noise in [0, 1) from the counter hash.
cv::Mat whiteNoise(cv::Size size, std::uint64_t seed, std::uint64_t stream) {
  cv::Mat out(size, CV_32F);
  for (int r = 0; r < size.height; ++r) {
    float* row = out.ptr<float>(r);
    for (int c = 0; c < size.width; ++c) {
      row[c] = static_cast<float>(unitFromHash(
          hash64(seed, stream, static_cast<std::uint64_t>(r), static_cast<std::uint64_t>(c))));
    }
  }
  return out;
}

// Value noise with `cells` random values across each side, interpolated cubically, seamless: the
// lattice is padded by wrapping before it is resized, then cropped.
cv::Mat valueNoise(cv::Size size, int cells, std::uint64_t seed, std::uint64_t stream) {
  const cv::Mat lattice = whiteNoise({cells, cells}, seed, stream);
  constexpr int kPad = 2;
  cv::Mat padded;
  cv::copyMakeBorder(lattice, padded, kPad, kPad, kPad, kPad, cv::BORDER_WRAP);
  const int scaleX = size.width / cells;
  const int scaleY = size.height / cells;
  cv::Mat big;
  cv::resize(padded, big, {padded.cols * scaleX, padded.rows * scaleY}, 0, 0,
             scaleX > 4 ? cv::INTER_CUBIC : cv::INTER_LINEAR);
  return big(cv::Rect(kPad * scaleX, kPad * scaleY, size.width, size.height)).clone();
}

// World rectangle (metres) to texel rectangle of the ground texture.
struct GroundPainter {
  cv::Mat& mask;
  int size;
  float texel;

  void rect(double x0, double y0, double x1, double y1, int value = 255) const {
    const auto col = [&](double x) { return static_cast<int>(std::lround(x / texel)) + size / 2; };
    cv::rectangle(mask, cv::Point(col(x0), col(y0)), cv::Point(col(x1) - 1, col(y1) - 1),
                  cv::Scalar(value), cv::FILLED);
  }
};

void paintMarkings(cv::Mat& white, cv::Mat& yellow, int size, float texel) {
  const double half =
      static_cast<double>(size) * texel / 2;  // the texture spans [-half, half) in x and y
  const GroundPainter w{white, size, texel};
  const GroundPainter y{yellow, size, texel};
  // Double yellow centre line just right of the start position, along the whole texture.
  y.rect(-half, -2.25, half, -2.10);
  y.rect(-half, -2.00, half, -1.85);
  // Dashed lane line on the left: 3 m dashes every 8 m (the texture is 81.92 m: 10 dashes + seam).
  for (double x = -half; x < half - 3; x += 8.0) w.rect(x, 1.70, x + 3.0, 1.85);
  // Solid edge lines.
  w.rect(-half, 5.40, half, 5.55);
  w.rect(-half, -7.95, half, -7.80);
  // Parking bays on the right: separators every 2.6 m, perpendicular to the road.
  for (double x = -30.0; x <= 40.0; x += 2.6) w.rect(x, -7.80, x + 0.12, -2.9);
  // Angled bays on the left beyond the edge line.
  for (double x = -24.0; x <= 36.0; x += 3.0) {
    std::vector<cv::Point> poly;
    for (const auto& [px, py] :
         {std::pair{x, 5.55}, {x + 0.14, 5.55}, {x + 2.64, 10.5}, {x + 2.5, 10.5}}) {
      poly.emplace_back(static_cast<int>(std::lround(px / texel)) + size / 2,
                        static_cast<int>(std::lround(py / texel)) + size / 2);
    }
    cv::fillConvexPoly(white, poly, cv::Scalar(255), cv::LINE_8);
  }
  // Two zebra crossings, one ahead and one behind the start: bars along the road.
  for (const double x0 : {11.0, -13.0}) {
    for (double yy = -1.6; yy < 5.2; yy += 1.0) w.rect(x0, yy, x0 + 3.0, yy + 0.5);
    w.rect(x0 - 0.8, -1.7, x0 - 0.5, 5.3);  // stop bar
  }
}

cv::Vec3b toBgr(double b, double g, double r) {
  return {cv::saturate_cast<uchar>(b), cv::saturate_cast<uchar>(g), cv::saturate_cast<uchar>(r)};
}

}  // namespace

cv::Mat makeGroundTexture(std::uint64_t seed, int size, float texelM) {
  const cv::Size dims(size, size);
  // Octaves from ~5 m blotches down to the 2 cm grain: what makes asphalt readable at every range.
  const cv::Mat low = valueNoise(dims, 16, seed, 101);
  const cv::Mat mid = valueNoise(dims, 128, seed, 102);
  const cv::Mat fine = valueNoise(dims, 1024, seed, 103);
  const cv::Mat grain = whiteNoise(dims, seed, 104);
  const cv::Mat tint = valueNoise(dims, 32, seed, 105);

  cv::Mat white(dims, CV_8U, cv::Scalar(0));
  cv::Mat yellow(dims, CV_8U, cv::Scalar(0));
  paintMarkings(white, yellow, size, texelM);
  const cv::Mat wear = valueNoise(dims, 512, seed, 106);

  cv::Mat out(dims, CV_8UC3);
  cv::parallel_for_(cv::Range(0, size), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      const float* l = low.ptr<float>(r);
      const float* m = mid.ptr<float>(r);
      const float* f = fine.ptr<float>(r);
      const float* g = grain.ptr<float>(r);
      const float* t = tint.ptr<float>(r);
      const float* we = wear.ptr<float>(r);
      const uchar* wm = white.ptr<uchar>(r);
      const uchar* ym = yellow.ptr<uchar>(r);
      auto* px = out.ptr<cv::Vec3b>(r);
      for (int c = 0; c < size; ++c) {
        double grey =
            92 + 40 * (l[c] - 0.5) + 22 * (m[c] - 0.5) + 18 * (f[c] - 0.5) + 26 * (g[c] - 0.5);
        if (g[c] > 0.985f) grey += 45;   // light pebbles in the mix
        if (l[c] < 0.22f) grey *= 0.75;  // old patches / oil stains
        const double warm = 6 * (t[c] - 0.5);
        double b = grey - warm, gg = grey, rr = grey + warm;
        const double paint = std::clamp((we[c] - 0.15) * 1.6, 0.55, 1.0);  // worn paint
        if (wm[c] != 0) {
          const double p = 215 * paint + 12 * (g[c] - 0.5);
          b = std::max(b, p);
          gg = std::max(gg, p);
          rr = std::max(rr, p);
        } else if (ym[c] != 0) {
          b = std::max(b * 0.5, 30.0 * paint);
          gg = std::max(gg, 175 * paint + 10 * (g[c] - 0.5));
          rr = std::max(rr, 220 * paint + 10 * (g[c] - 0.5));
        }
        px[c] = toBgr(b, gg, rr);
      }
    }
  });
  return out;
}

cv::Mat makeFacadeTexture(std::uint64_t seed, cv::Size size, float texelM) {
  cv::Mat out(size, CV_8UC3);
  const auto texels = [&](double metres) { return static_cast<int>(std::lround(metres / texelM)); };
  // Bricks 24 x 7 cm with 1 cm mortar, every other course shifted by half a brick.
  const int brickW = texels(0.25), brickH = texels(0.08), mortar = std::max(1, texels(0.01));
  out.setTo(cv::Scalar(168, 172, 176));
  for (int course = 0; course * brickH < size.height; ++course) {
    const int shift = (course % 2) * brickW / 2;
    for (int col = -1; col * brickW < size.width; ++col) {
      const double v =
          0.8 + 0.4 * unitFromHash(hash64(seed, 201, static_cast<std::uint64_t>(course),
                                          static_cast<std::uint64_t>(col + 1)));
      const int x0 = col * brickW + shift;
      cv::rectangle(out, cv::Point(x0, course * brickH),
                    cv::Point(x0 + brickW - mortar - 1, (course + 1) * brickH - mortar - 1),
                    cv::Scalar(58 * v, 74 * v, 148 * v), cv::FILLED);
    }
  }
  // Concrete plinth, then three floors of windows (8 per texture width so they tile).
  cv::rectangle(out, cv::Rect(0, 0, size.width, texels(0.45)), cv::Scalar(150, 150, 145),
                cv::FILLED);
  const int period = size.width / 8;
  for (int floor = 0; floor < 3; ++floor) {
    const int y0 = texels(1.1 + 3.0 * floor);
    const int height = texels(1.5);
    if (y0 + height >= size.height) break;
    for (int i = 0; i < 8; ++i) {
      const int x0 = i * period + (period - texels(1.2)) / 2;
      cv::rectangle(
          out, cv::Rect(x0 - texels(0.08), y0 - texels(0.1), texels(1.36), height + texels(0.18)),
          cv::Scalar(215, 215, 210), cv::FILLED);
      const double lit = unitFromHash(hash64(seed, 202, static_cast<std::uint64_t>(floor * 8 + i)));
      for (int r = 0; r < height; ++r) {
        const double s = 0.7 + 0.5 * r / height;  // sky reflected brighter towards the top
        cv::line(
            out, cv::Point(x0, y0 + r), cv::Point(x0 + texels(1.2) - 1, y0 + r),
            lit > 0.8 ? cv::Scalar(90 * s, 170 * s, 210 * s) : cv::Scalar(105 * s, 80 * s, 55 * s));
      }
      cv::rectangle(out, cv::Rect(x0 + texels(0.58), y0, texels(0.04), height),
                    cv::Scalar(215, 215, 210), cv::FILLED);  // mullion
    }
  }
  // Grime: low-frequency darkening plus per-texel grain.
  const cv::Mat grime = valueNoise(size, 16, seed, 203);
  const cv::Mat grain = whiteNoise(size, seed, 204);
  for (int r = 0; r < size.height; ++r) {
    auto* px = out.ptr<cv::Vec3b>(r);
    const float* gm = grime.ptr<float>(r);
    const float* gr = grain.ptr<float>(r);
    for (int c = 0; c < size.width; ++c) {
      const double k = 0.85 + 0.3 * gm[c] + 0.12 * (gr[c] - 0.5);
      px[c] = toBgr(px[c][0] * k, px[c][1] * k, px[c][2] * k);
    }
  }
  return out;
}

cv::Mat makeCloudTexture(std::uint64_t seed, int size) {
  const cv::Size dims(size, size);
  cv::Mat density = valueNoise(dims, 8, seed, 301) * 0.55 + valueNoise(dims, 32, seed, 302) * 0.3 +
                    valueNoise(dims, 64, seed, 303) * 0.15;
  cv::Mat grey;
  density.convertTo(grey, CV_8U, 255.0);
  cv::Mat out;
  cv::cvtColor(grey, out, cv::COLOR_GRAY2BGR);
  return out;
}

}  // namespace surroundd::synth

#include "processing/column_dct.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace surroundd::processing {
namespace {

// The FFT's stages: radix 4 while it divides, then 2, then the odd prime factors, smallest first
// (3 and 5 have their own butterflies; larger primes take p * p products per output group).
std::vector<int> radicesOf(int n) {
  std::vector<int> radices;
  for (; n % 4 == 0; n /= 4) radices.push_back(4);
  if (n % 2 == 0) {
    radices.push_back(2);
    n /= 2;
  }
  for (int p = 3; n > 1; p += 2) {
    for (; n % p == 0; n /= p) radices.push_back(p);
    if (p * p > n && n > 1) {  // what is left is prime
      radices.push_back(n);
      n = 1;
    }
  }
  return radices;
}

// Four complex values: lanes of real parts and of imaginary parts. A row of the FFT's buffers
// holds its real parts in its first half and its imaginary parts in its second.
struct Complex4 {
  FloatLanes re;
  FloatLanes im;
};

inline Complex4 loadComplex(const float* row, int half, int column) {
  return {loadLanes(row + column), loadLanes(row + half + column)};
}
inline void storeComplex(float* row, int half, int column, Complex4 v) {
  storeLanes(row + column, v.re);
  storeLanes(row + half + column, v.im);
}
inline Complex4 operator+(Complex4 a, Complex4 b) { return {a.re + b.re, a.im + b.im}; }
inline Complex4 operator-(Complex4 a, Complex4 b) { return {a.re - b.re, a.im - b.im}; }
inline Complex4 rotate(Complex4 a, float cos, float sin) {
  return {a.re * cos - a.im * sin, a.re * sin + a.im * cos};
}

}  // namespace

ColumnDct::ColumnDct(int length, int width) : length_(length), width_(width), half_(width / 2) {
  if (length < 1 || width < 8 || width % 8 != 0) {
    throw std::invalid_argument(
        fmt::format("ColumnDct: length {} and width {} (want length >= 1, width a multiple of 8)",
                    length, width));
  }
  const double pi = std::numbers::pi;
  int span = 1;
  int largestRadix = 1;
  for (const int radix : radicesOf(length)) {
    stages_.push_back({radix, span, twiddles_.size()});
    for (int k = 0; k < span; ++k) {
      for (int r = 1; r < radix; ++r) {
        const double angle = -2 * pi * r * k / (span * radix);
        twiddles_.push_back(static_cast<float>(std::cos(angle)));
        twiddles_.push_back(static_cast<float>(std::sin(angle)));
      }
    }
    firstRoot_.push_back(rootCos_.size());
    if (radix > 5) {
      for (int m = 0; m < radix; ++m) {
        rootCos_.push_back(static_cast<float>(std::cos(-2 * pi * m / radix)));
        rootSin_.push_back(static_cast<float>(std::sin(-2 * pi * m / radix)));
      }
    }
    span *= radix;
    largestRadix = std::max(largestRadix, radix);
  }
  radixScratch_.resize(2 * static_cast<std::size_t>(largestRadix));

  // Makhoul: v = (x0, x2, x4, ..., x5, x3, x1); then DCT-II(x)_k = Re(exp(-i pi k / 2N) FFT(v)_k).
  evenOdd_.resize(static_cast<std::size_t>(length));
  for (int m = 0; 2 * m < length; ++m) evenOdd_[static_cast<std::size_t>(m)] = 2 * m;
  for (int m = 0; 2 * m + 1 < length; ++m) {
    evenOdd_[static_cast<std::size_t>(length - 1 - m)] = 2 * m + 1;
  }
  for (int k = 0; k < length; ++k) {
    const double angle = pi * k / (2.0 * length);
    const double scale = std::sqrt((k == 0 ? 1.0 : 2.0) / length);  // orthonormal
    // forward(): the halves of the two packed columns' spectra are taken with a factor 1/2.
    postCos_.push_back(static_cast<float>(std::cos(angle) * scale / 2));
    postSin_.push_back(static_cast<float>(std::sin(angle) * scale / 2));
    preCos_.push_back(static_cast<float>(std::cos(angle) / length));  // 1/N: inverse FFT
    preSin_.push_back(static_cast<float>(std::sin(angle) / length));
    inverseScale_.push_back(static_cast<float>(1 / scale));
  }
  for (auto& buffer : buffers_) buffer.assign(static_cast<std::size_t>(length) * width, 0.0f);
}

void ColumnDct::forward(float* data) {
  const auto row = [this](float* base, int r) {
    return base + static_cast<std::size_t>(r) * width_;
  };
  float* packed = buffers_[0].data();
  for (int n = 0; n < length_; ++n) {
    std::copy_n(row(data, evenOdd_[static_cast<std::size_t>(n)]), width_, row(packed, n));
  }
  float* spectrum = fft(false);
  // Columns a (first half of a row) and b (second half) were the real and imaginary parts:
  // V_a[k] = (Z[k] + conj Z[N-k]) / 2, V_b[k] = (Z[k] - conj Z[N-k]) / 2i, and the DCT is
  // Re(exp(-i pi k / 2N) V[k]).
  for (int k = 0; k < length_; ++k) {
    const float* z = row(spectrum, k);
    const float* mirror = row(spectrum, (length_ - k) % length_);
    float* out = row(data, k);
    const float cos = postCos_[static_cast<std::size_t>(k)];
    const float sin = postSin_[static_cast<std::size_t>(k)];
    for (int column = 0; column < half_; column += kFloatLanes) {
      const Complex4 a = loadComplex(z, half_, column);
      const Complex4 b = loadComplex(mirror, half_, column);
      storeLanes(out + column, cos * (a.re + b.re) + sin * (a.im - b.im));
      storeLanes(out + half_ + column, cos * (a.im + b.im) + sin * (b.re - a.re));
    }
  }
}

void ColumnDct::inverse(float* data) {
  const auto row = [this](float* base, int r) {
    return base + static_cast<std::size_t>(r) * width_;
  };
  // V[k] = exp(i pi k / 2N) (X[k] - i X[N-k]) for each packed column (X[N] = 0), unscaled to
  // the plain DCT-II's coefficients; then Z = V_a + i V_b.
  float* packed = buffers_[0].data();
  for (int k = 0; k < length_; ++k) {
    const float* x = row(data, k);
    const float* mirror = row(data, k == 0 ? 0 : length_ - k);
    const float own = inverseScale_[static_cast<std::size_t>(k)];
    const float other = k == 0 ? 0.0f : inverseScale_[static_cast<std::size_t>(length_ - k)];
    const float cos = preCos_[static_cast<std::size_t>(k)];
    const float sin = preSin_[static_cast<std::size_t>(k)];
    float* out = row(packed, k);
    for (int column = 0; column < half_; column += kFloatLanes) {
      const FloatLanes p = own * loadLanes(x + column);
      const FloatLanes pb = own * loadLanes(x + half_ + column);
      const FloatLanes q = other * loadLanes(mirror + column);
      const FloatLanes qb = other * loadLanes(mirror + half_ + column);
      storeLanes(out + column, (cos * p + sin * q) - (sin * pb - cos * qb));
      storeLanes(out + half_ + column, (sin * p - cos * q) + (cos * pb + sin * qb));
    }
  }
  const float* signal = fft(true);
  for (int n = 0; n < length_; ++n) {
    std::copy_n(signal + static_cast<std::size_t>(n) * width_, width_,
                row(data, evenOdd_[static_cast<std::size_t>(n)]));
  }
}

float* ColumnDct::fft(bool inverse) {
  float* in = buffers_[0].data();
  float* out = buffers_[1].data();
  for (const Stage& stage : stages_) {
    radixStage(stage, inverse, in, out);
    std::swap(in, out);
  }
  return in;
}

// One Stockham stage: butterfly j takes rows j + r * N/p (r < p), turns them by the twiddles of
// its position k = j mod span, and writes its p outputs to rows (j / span) * span * p + k +
// q * span, so the result comes out in natural order without a bit-reversal pass.
void ColumnDct::radixStage(const Stage& stage, bool inverse, const float* in, float* out) {
  const int p = stage.radix;
  const int groups = length_ / p;
  const int half = half_;
  const float sign = inverse ? -1.0f : 1.0f;  // the inverse turns the other way
  const auto rowIn = [&](int r) { return in + static_cast<std::size_t>(r) * width_; };
  const auto rowOut = [&](int r) { return out + static_cast<std::size_t>(r) * width_; };
  const std::size_t stageIndex = static_cast<std::size_t>(&stage - stages_.data());
  const float* rootCos = rootCos_.data() + firstRoot_[stageIndex];
  const float* rootSin = rootSin_.data() + firstRoot_[stageIndex];
  for (int j = 0; j < groups; ++j) {
    const int k = j % stage.span;
    const float* twiddle =
        twiddles_.data() + stage.firstTwiddle + 2 * static_cast<std::size_t>(k) * (p - 1);
    const auto turned = [&](int r, int column) {
      const Complex4 a = loadComplex(rowIn(j + r * groups), half, column);
      const auto at = 2 * static_cast<std::size_t>(r - 1);
      return r == 0 ? a : rotate(a, twiddle[at], sign * twiddle[at + 1]);
    };
    const int first = (j / stage.span) * stage.span * p + k;
    const auto target = [&](int q) { return rowOut(first + q * stage.span); };
    if (p == 2) {
      for (int column = 0; column < half; column += kFloatLanes) {
        const Complex4 a0 = turned(0, column);
        const Complex4 a1 = turned(1, column);
        storeComplex(target(0), half, column, a0 + a1);
        storeComplex(target(1), half, column, a0 - a1);
      }
    } else if (p == 4) {
      for (int column = 0; column < half; column += kFloatLanes) {
        const Complex4 a0 = turned(0, column);
        const Complex4 a1 = turned(1, column);
        const Complex4 a2 = turned(2, column);
        const Complex4 a3 = turned(3, column);
        const Complex4 sum02 = a0 + a2;
        const Complex4 difference02 = a0 - a2;
        const Complex4 sum13 = a1 + a3;
        const Complex4 d = a1 - a3;
        // d times the fourth root of unity: -i forward, +i inverse.
        const Complex4 turned13 = {sign * d.im, -sign * d.re};
        storeComplex(target(0), half, column, sum02 + sum13);
        storeComplex(target(1), half, column, difference02 + turned13);
        storeComplex(target(2), half, column, sum02 - sum13);
        storeComplex(target(3), half, column, difference02 - turned13);
      }
    } else if (p == 3) {
      const float sin3 = sign * 0.866025403784f;  // sin(2 pi / 3)
      for (int column = 0; column < half; column += kFloatLanes) {
        const Complex4 a0 = turned(0, column);
        const Complex4 a1 = turned(1, column);
        const Complex4 a2 = turned(2, column);
        const Complex4 sum = a1 + a2;
        const Complex4 middle = {a0.re - 0.5f * sum.re, a0.im - 0.5f * sum.im};
        const Complex4 d = a1 - a2;
        const Complex4 turnedD = {sin3 * d.im, -sin3 * d.re};  // -i sin(2 pi / 3) d, forward
        storeComplex(target(0), half, column, a0 + sum);
        storeComplex(target(1), half, column, middle + turnedD);
        storeComplex(target(2), half, column, middle - turnedD);
      }
    } else if (p == 5) {
      const float cos1 = 0.309016994375f;   // cos(2 pi / 5)
      const float cos2 = -0.809016994375f;  // cos(4 pi / 5)
      const float sin1 = sign * 0.951056516295f;
      const float sin2 = sign * 0.587785252292f;
      for (int column = 0; column < half; column += kFloatLanes) {
        const Complex4 a0 = turned(0, column);
        const Complex4 a1 = turned(1, column);
        const Complex4 a2 = turned(2, column);
        const Complex4 a3 = turned(3, column);
        const Complex4 a4 = turned(4, column);
        const Complex4 b1 = a1 + a4;
        const Complex4 b2 = a2 + a3;
        const Complex4 d1 = a1 - a4;
        const Complex4 d2 = a2 - a3;
        const Complex4 m1 = {a0.re + cos1 * b1.re + cos2 * b2.re,
                             a0.im + cos1 * b1.im + cos2 * b2.im};
        const Complex4 m2 = {a0.re + cos2 * b1.re + cos1 * b2.re,
                             a0.im + cos2 * b1.im + cos1 * b2.im};
        // -i (sin1 d1 + sin2 d2) and -i (sin2 d1 - sin1 d2), forward.
        const Complex4 t1 = {sin1 * d1.im + sin2 * d2.im, -(sin1 * d1.re + sin2 * d2.re)};
        const Complex4 t2 = {sin2 * d1.im - sin1 * d2.im, -(sin2 * d1.re - sin1 * d2.re)};
        storeComplex(target(0), half, column, a0 + b1 + b2);
        storeComplex(target(1), half, column, m1 + t1);
        storeComplex(target(2), half, column, m2 + t2);
        storeComplex(target(3), half, column, m2 - t2);
        storeComplex(target(4), half, column, m1 - t1);
      }
    } else {
      // Any other odd radix: the plain p-point DFT of the turned inputs, p * p complex products.
      FloatLanes* scratch = radixScratch_.data();
      for (int column = 0; column < half; column += kFloatLanes) {
        for (int r = 0; r < p; ++r) {
          const Complex4 a = turned(r, column);
          const auto slot = 2 * static_cast<std::size_t>(r);
          scratch[slot] = a.re;
          scratch[slot + 1] = a.im;
        }
        for (int q = 0; q < p; ++q) {
          Complex4 sum = {scratch[0], scratch[1]};
          for (int r = 1, m = q; r < p; ++r, m = m + q < p ? m + q : m + q - p) {
            const auto slot = 2 * static_cast<std::size_t>(r);
            sum = sum + rotate({scratch[slot], scratch[slot + 1]}, rootCos[m], sign * rootSin[m]);
          }
          storeComplex(target(q), half, column, sum);
        }
      }
    }
  }
}

}  // namespace surroundd::processing

#include "tools/synth/mip_texture.hpp"

#include <cstdlib>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <sys/mman.h>

namespace surroundd::synth {
namespace {

bool isPowerOfTwo(int n) { return n > 0 && (n & (n - 1)) == 0; }

constexpr std::size_t kHugePage = 2 << 20;
constexpr int kBlock = 8;

}  // namespace

void MipTexture::Free::operator()(std::uint32_t* p) const { std::free(p); }

MipTexture::MipTexture(const cv::Mat& level0) {
  if (level0.type() != CV_8UC3 || !isPowerOfTwo(level0.cols) || !isPowerOfTwo(level0.rows) ||
      level0.cols < kBlock || level0.rows < kBlock) {
    throw std::invalid_argument(
        "MipTexture: expected 8-bit BGR with power-of-two sides of at least 8");
  }
  std::vector<cv::Mat> mats;
  cv::Mat current;
  cv::cvtColor(level0, current, cv::COLOR_BGR2BGRA);
  std::size_t total = 0;
  for (;;) {
    mats.push_back(current);
    total += current.total();
    if (current.cols <= kBlock || current.rows <= kBlock) break;
    cv::Mat next;
    cv::pyrDown(current, next);  // Gaussian 5x5 then decimate: the anti-aliasing filter we want
    current = next;
  }
  const std::size_t bytes = (total * 4 + kHugePage - 1) / kHugePage * kHugePage;
  storage_.reset(static_cast<std::uint32_t*>(std::aligned_alloc(kHugePage, bytes)));
  if (!storage_) throw std::bad_alloc();
  ::madvise(storage_.get(), bytes, MADV_HUGEPAGE);  // a hint: fine if the kernel says no
  std::uint32_t* texels = storage_.get();
  for (const auto& mat : mats) {
    Level level;
    level.texels = texels;
    level.blocksPerRow = mat.cols / kBlock;
    level.widthMask = mat.cols - 1;
    level.heightMask = mat.rows - 1;
    for (int y = 0; y < mat.rows; ++y) {
      const auto* row = mat.ptr<std::uint32_t>(y);
      for (int x = 0; x < mat.cols; ++x) texels[blockRow(level, y) + blockColumn(x)] = row[x];
    }
    levels_.push_back(level);
    sizes_.push_back(mat.size());
    texels += mat.total();
  }
}

}  // namespace surroundd::synth

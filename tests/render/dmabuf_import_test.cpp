// Camera frames taken into textures from the DMABUFs their V4L2 driver lent them
// (render/dmabuf_import.hpp, CameraTexture::import): what the display says it cannot do, and, on
// vivid's cameras (ctest runs these on scripts/device-vm.sh's virtual machine:
// DmabufImport.OnVividCameras), the imported texture is texel for texel the uploaded one, or the
// refusal says why the driver would not import it. Skipped, with a message, where there is no
// vivid device or no driver that imports.

#include "render/dmabuf_import.hpp"

#include <array>
#include <memory>
#include <vector>

#include <GLES3/gl32.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "capture/frame.hpp"
#include "capture/v4l2_source.hpp"
#include "common/pixel_format.hpp"
#include "render/camera_texture.hpp"
#include "render/egl_context.hpp"
#include "tests/support/vivid_cameras.hpp"

namespace surroundd::render {
namespace {

using ::testing::AnyOf;
using ::testing::HasSubstr;

// A texture's texels, copied into one of this context's own (imported ones need not be
// attachable) and read back.
cv::Mat texels(GLuint texture, cv::Size size, GLenum internalFormat, int type) {
  gl::Texture copy;
  glBindTexture(GL_TEXTURE_2D, copy.name());
  glTexStorage2D(GL_TEXTURE_2D, 1, internalFormat, size.width, size.height);
  glCopyImageSubData(texture, GL_TEXTURE_2D, 0, 0, 0, 0, copy.name(), GL_TEXTURE_2D, 0, 0, 0, 0,
                     size.width, size.height, 1);
  gl::Framebuffer framebuffer;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.name());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, copy.name(), 0);
  cv::Mat read(size, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, size.width, size.height, GL_RGBA, GL_UNSIGNED_BYTE, read.data);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  // GL reads any colour format as RGBA: keep the channels the texture has.
  cv::Mat texels(size, type);
  const int channels = CV_MAT_CN(type);
  const std::array<int, 8> pairs{0, 0, 1, 1, 2, 2, 3, 3};
  cv::mixChannels(&read, 1, &texels, 1, pairs.data(), static_cast<std::size_t>(channels));
  return texels;
}

TEST(DmabufImport, SaysWhyItImportsNothing) {
  const EglContext context;
  EXPECT_EQ(DmabufImport(PixelFormat::kBgr, {64, 32}).refusal(), "BGR frames are not imported");
  DmabufImport yuyv(PixelFormat::kYuyv, {64, 32});
  DmabufPlanes planes;
  EXPECT_FALSE(yuyv.texturesOf(planes)) << "a picture in no DMABUF";
  planes.planes = 2;  // YUYV comes in one
  planes.session = 1;
  EXPECT_FALSE(yuyv.texturesOf(planes));
  EXPECT_THAT(yuyv.refusal(), AnyOf(HasSubstr("a YUYV picture in 2 planes"),
                                    HasSubstr("no EGL_EXT_image_dma_buf_import")));
}

class VividImport : public ::testing::Test {
 protected:
  void SetUp() override {
    cameras_ = testing::vividCameras();
    if (cameras_.empty()) {
      GTEST_SKIP() << "no vivid device here (ctest runs these on a virtual machine's: "
                      "DmabufImport.OnVividCameras)";
    }
  }
  std::vector<std::filesystem::path> cameras_;
};

TEST_F(VividImport, AnImportedFrameIsTheUploadedOne) {
  const EglContext context;
  for (const auto format : {capture::V4l2Format::kYuyv, capture::V4l2Format::kNv12}) {
    SCOPED_TRACE(capture::toString(format));
    capture::V4l2Source source("vivid", testing::vividSettings(cameras_.front(), format));
    ASSERT_EQ(source.lendBuffers(), nullptr);
    capture::FramePool pool(2, source.frameSize(), source.pixelFormat());
    const capture::FrameRef frame = pool.acquire(std::chrono::milliseconds(0));
    ASSERT_EQ(source.read(*frame), capture::ReadStatus::kFrame) << source.lastError();
    ASSERT_GT(frame->dmabuf.planes, 0u);

    CameraTexture imported(source.pixelFormat(), source.frameSize());
    if (!imported.import(frame->dmabuf)) {
      // Mesa's llvmpipe, which the virtual machine has, answers EGL_BAD_ALLOC (0x3003).
      EXPECT_THAT(imported.importRefusal(),
                  AnyOf(HasSubstr("the driver refused to import a DMABUF (EGL error 0x"),
                        HasSubstr("no EGL_EXT_image_dma_buf_import")));
      GTEST_SKIP() << "this machine's EGL (" << context.description()
                   << ") does not import vivid's DMABUFs: " << imported.importRefusal();
    }
    CameraTexture uploaded(source.pixelFormat(), source.frameSize());
    uploaded.upload(frame->image);
    const cv::Size size = source.frameSize();
    if (source.pixelFormat() == PixelFormat::kYuyv) {
      const cv::Size half(size.width / 2, size.height);
      EXPECT_EQ(cv::norm(texels(imported.pixels(), half, GL_RGBA8, CV_8UC4),
                         texels(uploaded.pixels(), half, GL_RGBA8, CV_8UC4), cv::NORM_INF),
                0.0);
    } else {
      EXPECT_EQ(cv::norm(texels(imported.pixels(), size, GL_R8, CV_8UC1),
                         texels(uploaded.pixels(), size, GL_R8, CV_8UC1), cv::NORM_INF),
                0.0);
      const cv::Size chroma(size.width / 2, size.height / 2);
      EXPECT_EQ(cv::norm(texels(imported.chroma(), chroma, GL_RG8, CV_8UC2),
                         texels(uploaded.chroma(), chroma, GL_RG8, CV_8UC2), cv::NORM_INF),
                0.0);
    }
  }
}

// An import holds its buffer's memory: once a camera is opened again, the imports of its earlier
// buffers are let go, though a frame still holds one.
TEST_F(VividImport, TheImportsOfAReopenedCamerasEarlierBuffersAreLetGo) {
  const EglContext context;
  const auto settings = testing::vividSettings(cameras_.front(), capture::V4l2Format::kYuyv);
  auto first = std::make_unique<capture::V4l2Source>("vivid", settings);
  ASSERT_EQ(first->lendBuffers(), nullptr);
  capture::FramePool pool(2, first->frameSize(), first->pixelFormat());
  const capture::FrameRef early = pool.acquire(std::chrono::milliseconds(0));
  ASSERT_EQ(first->read(*early), capture::ReadStatus::kFrame) << first->lastError();
  DmabufImport import(first->pixelFormat(), first->frameSize());
  if (!import.texturesOf(early->dmabuf)) {
    GTEST_SKIP() << "this machine's EGL (" << context.description()
                 << ") does not import vivid's DMABUFs: " << import.refusal();
  }
  EXPECT_EQ(import.imports(), 1u);
  first.reset();  // closed, a frame still holding one of its buffers
  capture::V4l2Source second("vivid", settings);
  ASSERT_EQ(second.lendBuffers(), nullptr);
  const capture::FrameRef late = pool.acquire(std::chrono::milliseconds(0));
  ASSERT_EQ(second.read(*late), capture::ReadStatus::kFrame) << second.lastError();
  ASSERT_TRUE(import.texturesOf(late->dmabuf)) << import.refusal();
  EXPECT_EQ(import.imports(), 1u) << "the closed camera's buffer is still imported";
}

}  // namespace
}  // namespace surroundd::render

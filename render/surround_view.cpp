#include "render/surround_view.hpp"

#include <limits>
#include <stdexcept>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "render/egl_context.hpp"
#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

// The largest rectangle of `picture`'s aspect that fits `area`, centred in it.
cv::Rect letterbox(cv::Size picture, const cv::Rect& area) {
  const double scale = std::min(static_cast<double>(area.width) / picture.width,
                                static_cast<double>(area.height) / picture.height);
  const int w = static_cast<int>(picture.width * scale);
  const int h = static_cast<int>(picture.height * scale);
  return {area.x + (area.width - w) / 2, area.y + (area.height - h) / 2, w, h};
}

// The grey behind the scene, where no mesh is.
constexpr float kBackground = 0.08F;

}  // namespace

SurroundView::SurroundView(const SurroundScene& scene, cv::Size size, ViewKind view,
                           ViewSettings settings, GpuTimer* timer)
    : scene_(scene),
      size_(size),
      view_(view),
      settings_(settings),
      timer_(timer),
      readAtCollect_(softwareRenderer()),
      from_(view),
      picture_(size, CV_8UC3) {
  if (size.width <= 0 || size.height <= 0 || size.width % 2 != 0 || size.height % 2 != 0) {
    throw std::invalid_argument(fmt::format(
        "surround view: size must be even and positive, got {}x{}", size.width, size.height));
  }
  glBindRenderbuffer(GL_RENDERBUFFER, colour_.name());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, size.width, size.height);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_.name());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, size.width, size.height);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_.name());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.name());
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw RenderError(fmt::format("surround view {}x{}: framebuffer incomplete (0x{:04x})",
                                  size.width, size.height, status));
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, readBuffer_.name());
  glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(size.area()) * 4, nullptr,
               GL_STREAM_READ);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  gl::check("creating a surround view");
}

void SurroundView::setView(ViewKind view) {
  if (view == view_) return;
  from_ = view_;
  view_ = view;
  transitioning_ = settings_.transitionS > 0;
  transitionStartS_.reset();
}

bool SurroundView::settlesStill() const {
  return (view_ != ViewKind::kOrbit && view_ != ViewKind::kSplit) || !orbitMoves(settings_);
}

double SurroundView::transitionProgress(double timeS) {
  if (!transitioning_) return 1;
  if (!transitionStartS_) transitionStartS_ = timeS;
  const double t = (timeS - *transitionStartS_) / settings_.transitionS;
  // Before its start: stream time went back (a replay that loops); the switch ends there. The
  // margin: 2.4 - 2.0 is 0.39999... in doubles.
  if (t >= 1 - 1e-9 || t < 0) {
    transitioning_ = false;
    return 1;
  }
  return t;
}

std::optional<cv::Rect> SurroundView::cameraArea() const {
  if (view_ != ViewKind::kSplit) return std::nullopt;
  const int half = size_.width / 2;
  return letterbox(scene_.cameraSize(), {half, 0, half, size_.height});
}

void SurroundView::drawScene(ViewKind view, double timeS, SurroundScene::Pass pass) const {
  glViewport(0, 0, size_.width, size_.height);
  switch (view) {
    case ViewKind::kTop:
    case ViewKind::kOrbit:
    case ViewKind::kRear:
      scene_.drawSurround(viewProjection(*perspectivePose(view, settings_, size_, timeS), size_),
                          pass);
      break;
    case ViewKind::kPanorama360:
      scene_.drawStrips(stripTangents(settings_, size_), pass);
      break;
    case ViewKind::kSplit: {
      // Framebuffer row 0 is the picture's top, so viewport rectangles read top-down too.
      const cv::Size half(size_.width / 2, size_.height);
      glViewport(0, 0, half.width, half.height);
      scene_.drawSurround(orbitViewProjection(settings_, half, timeS), pass);
      if (pass == SurroundScene::Pass::kPicture) {
        const cv::Rect camera =
            letterbox(scene_.cameraSize(), {half.width, 0, half.width, half.height});
        glViewport(camera.x, camera.y, camera.width, camera.height);
        scene_.drawCamera();
      }
      break;
    }
  }
}

void SurroundView::draw(double timeS, ReadBack readBack) {
  const bool reading = readBack == ReadBack::kYes;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
  drawPicture(timeS);
  readStarted_ = false;
  if (reading && !readAtCollect_) startReadBack();
  drawnFence_.place();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  gl::check("drawing a surround view");
  pending_ = reading;
}

void SurroundView::drawPicture(double timeS) {
  const GpuTimer::Scope timed(timer_, GpuStep::kDraw);
  glClearColor(kBackground, kBackground, kBackground, 1.0F);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  constexpr auto kPicture = SurroundScene::Pass::kPicture;
  const double progress = transitionProgress(timeS);
  drawn_ = {std::chrono::steady_clock::now(), progress >= 1};
  const auto fromPose = perspectivePose(from_, settings_, size_, timeS);
  const auto toPose = perspectivePose(view_, settings_, size_, timeS);
  if (progress >= 1) {
    drawScene(view_, timeS, kPicture);
  } else if (fromPose && toPose) {
    glViewport(0, 0, size_.width, size_.height);
    scene_.drawSurround(viewProjection(poseBetween(*fromPose, *toPose, progress), size_), kPicture);
  } else {
    // The new view over the old, more of it as the switch goes on.
    drawScene(from_, timeS, kPicture);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendColor(0, 0, 0, static_cast<float>(transitionWeight(progress)));
    glBlendFunc(GL_CONSTANT_ALPHA, GL_ONE_MINUS_CONSTANT_ALPHA);
    drawScene(view_, timeS, kPicture);
    glDisable(GL_BLEND);
  }
}

void SurroundView::startReadBack() {
  const GpuTimer::Scope timed(timer_, GpuStep::kReadBack);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, readBuffer_.name());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  readStarted_ = true;
}

const cv::Mat& SurroundView::collect() {
  if (!pending_) return picture_;
  if (!readStarted_) {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
    startReadBack();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, readBuffer_.name());
  const void* mapped = glMapBufferRange(GL_PIXEL_PACK_BUFFER, 0,
                                        static_cast<GLsizeiptr>(size_.area()) * 4, GL_MAP_READ_BIT);
  if (mapped == nullptr) {
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    gl::check("mapping the read-back buffer");
    throw RenderError("mapping the read-back buffer failed");
  }
  // The mapped pixels are read once, straight into the output's BGR picture.
  const cv::Mat rgba(size_, CV_8UC4, const_cast<void*>(mapped));
  cv::cvtColor(rgba, picture_, cv::COLOR_RGBA2BGR);
  glUnmapBuffer(GL_PIXEL_PACK_BUFFER);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  pending_ = false;
  return picture_;
}

cv::Mat SurroundView::drawAlone(SurroundScene::Pass pass, double timeS) const {
  gl::Renderbuffer colour;
  glBindRenderbuffer(GL_RENDERBUFFER, colour.name());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, size_.width, size_.height);
  gl::Renderbuffer depth;
  glBindRenderbuffer(GL_RENDERBUFFER, depth.name());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, size_.width, size_.height);
  gl::Framebuffer framebuffer;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.name());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour.name());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth.name());
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    throw RenderError(fmt::format("the {} view {}x{} alone: framebuffer incomplete (0x{:04x})",
                                  toString(view_), size_.width, size_.height, status));
  }
  if (pass == SurroundScene::Pass::kPicture) {
    glClearColor(kBackground, kBackground, kBackground, 1.0F);
  } else {
    glClearColor(0, 0, 0, 0);  // no panorama shown
  }
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  drawScene(view_, timeS, pass);
  cv::Mat rgba(size_, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  gl::check("drawing a view alone");
  return rgba;
}

cv::Mat SurroundView::stillPicture(double timeS) const {
  cv::Mat picture;
  cv::cvtColor(drawAlone(SurroundScene::Pass::kPicture, timeS), picture, cv::COLOR_RGBA2BGR);
  return picture;
}

cv::Mat SurroundView::panoramaPositions(double timeS) const {
  const cv::Mat packed = drawAlone(SurroundScene::Pass::kPanoramaPositions, timeS);
  // Unpacked as the positions pass packs them (render/surround_scene.cpp, panoramaPosition()).
  // A plain loop, not cv::Mat::forEach: OpenCV's TBB threads hand the picture back through
  // synchronisation that ThreadSanitizer cannot see, and the view LUT reads it on the work pool.
  // Once per view switch, so the single thread costs nothing that matters.
  constexpr float kNone = std::numeric_limits<float>::quiet_NaN();
  const cv::Size panorama = scene_.panoramaSize();
  const float uScale = static_cast<float>(panorama.width) / 65536.0F;
  const float vScale = static_cast<float>(panorama.height) / 32767.0F;
  cv::Mat result(size_, CV_32FC2);
  for (int y = 0; y < size_.height; ++y) {
    const auto* texel = packed.ptr<cv::Vec4b>(y);
    auto* position = result.ptr<cv::Vec2f>(y);
    for (int x = 0; x < size_.width; ++x) {
      const cv::Vec4b t = texel[x];
      if ((t[2] & 0x80U) == 0) {
        position[x] = cv::Vec2f(kNone, kNone);
        continue;
      }
      const auto u = static_cast<float>((t[0] << 8U) | t[1]);
      const auto v = static_cast<float>(((t[2] & 0x7FU) << 8U) | t[3]);
      position[x] = cv::Vec2f(u * uScale - 0.5F, v * vScale - 0.5F);
    }
  }
  return result;
}

const cv::Mat& SurroundView::guidelineLayer(double timeS) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
  // The pending picture leaves the framebuffer before the guidelines are drawn into it.
  if (pending_ && !readStarted_) startReadBack();
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  // The 3D part of the view: all of it, or the split view's left half.
  const bool split = view_ == ViewKind::kSplit;
  const cv::Size area = split ? cv::Size(size_.width / 2, size_.height) : size_;
  if (const auto pose = perspectivePose(split ? ViewKind::kOrbit : view_, settings_, area, timeS)) {
    glViewport(0, 0, area.width, area.height);
    scene_.drawGuidelines(viewProjection(*pose, area));
  }
  guidelineRgba_.create(size_, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, guidelineRgba_.data);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  gl::check("drawing a view's guidelines");
  cv::cvtColor(guidelineRgba_, guidelineLayer_, cv::COLOR_RGBA2BGR);
  return guidelineLayer_;
}

cv::Mat SurroundView::panoramaShown(const cv::Mat& panoramaPositions) {
  cv::Mat column;
  cv::extractChannel(panoramaPositions, column, 0);
  cv::Mat shown;
  cv::compare(column, column, shown, cv::CMP_EQ);  // false for NaN alone
  return shown;
}

}  // namespace surroundd::render

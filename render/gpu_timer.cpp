#include "render/gpu_timer.hpp"

#include <algorithm>

#include <EGL/egl.h>

#include "render/gl_objects.hpp"

namespace surroundd::render {
namespace {

constexpr auto kLongestReading = std::chrono::seconds(10);

}  // namespace

const char* toString(GpuStep step) {
  switch (step) {
    case GpuStep::kUpload:
      return "upload";
    case GpuStep::kStitch:
      return "stitch";
    case GpuStep::kDraw:
      return "draw";
    case GpuStep::kReadBack:
      return "read-back";
    case GpuStep::kCount:
      break;
  }
  return "?";
}

GpuTimer::GpuTimer()
    : readResult_(reinterpret_cast<PFNGLGETQUERYOBJECTUI64VEXTPROC>(
          eglGetProcAddress("glGetQueryObjectui64vEXT"))) {
  // ES 3's own read of a result is 32 bits: 4.29 s at most, where llvmpipe's misreading saturates.
  available_ = gl::hasExtension("GL_EXT_disjoint_timer_query") && readResult_ != nullptr;
  if (!available_) return;
  for (auto& step : steps_) glGenQueries(static_cast<GLsizei>(kQueriesPerStep), step.names.data());
  // Reading the flag clears it: what was disjoint before the first run does not count.
  GLint disjoint = 0;
  glGetIntegerv(GL_GPU_DISJOINT_EXT, &disjoint);
}

GpuTimer::~GpuTimer() {
  if (!available_) return;
  for (auto& step : steps_)
    glDeleteQueries(static_cast<GLsizei>(kQueriesPerStep), step.names.data());
}

bool GpuTimer::begin(GpuStep step) {
  StepQueries& queries = steps_[static_cast<std::size_t>(step)];
  if (queries.unread == kQueriesPerStep) {
    ++untimed_;
    return false;
  }
  glBeginQuery(GL_TIME_ELAPSED_EXT,
               queries.names[(queries.oldest + queries.unread) % kQueriesPerStep]);
  ++queries.unread;
  return true;
}

void GpuTimer::end() { glEndQuery(GL_TIME_ELAPSED_EXT); }

GpuTimer::Scope::Scope(GpuTimer* timer, GpuStep step)
    : timer_(timer != nullptr && timer->available_ && timer->begin(step) ? timer : nullptr) {}

GpuTimer::Scope::~Scope() {
  if (timer_ != nullptr) end();
}

std::span<const GpuTimer::Reading> GpuTimer::collect() {
  if (!available_) return {};
  // Queries finish in the order they were issued, so each step's oldest is read first.
  std::size_t read = 0;
  for (std::size_t s = 0; s < kGpuSteps; ++s) {
    StepQueries& queries = steps_[s];
    while (queries.unread > 0) {
      const GLuint query = queries.names[queries.oldest];
      GLuint ready = GL_FALSE;
      glGetQueryObjectuiv(query, GL_QUERY_RESULT_AVAILABLE, &ready);
      if (ready == GL_FALSE) break;
      GLuint64 nanoseconds = 0;
      readResult_(query, GL_QUERY_RESULT, &nanoseconds);
      queries.oldest = (queries.oldest + 1) % kQueriesPerStep;
      --queries.unread;
      const auto time = std::chrono::nanoseconds(static_cast<std::int64_t>(
          std::min<GLuint64>(nanoseconds, std::chrono::nanoseconds::max().count())));
      if (time < kLongestReading) readings_[read++] = {static_cast<GpuStep>(s), time};
    }
  }
  GLint disjoint = 0;
  glGetIntegerv(GL_GPU_DISJOINT_EXT, &disjoint);
  return std::span(readings_).first(disjoint != 0 ? 0 : read);
}

}  // namespace surroundd::render

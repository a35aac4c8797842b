#pragma once
// The GPU's own time of the pipeline's OpenGL steps (the camera frames' or panorama's upload, the
// stitch pass, a view's draw, its read-back), through GL_EXT_disjoint_timer_query: what the
// pipeline thread's clock cannot see, as the GPU runs them after the calls return.
//
// Never waits: each step has a ring of queries; collect() reads the results that are ready (a set
// or two later) and a step whose ring is full of unread queries goes untimed that once. Results
// from a disjoint period (the GPU's clock reset, its frequency changed) are dropped, as the
// extension asks; so are readings no GPU step takes (over 10 s: llvmpipe reads the first query of
// a context from a start of zero, hours before).
//
// Where the driver lacks the extension, available() is false and timing does nothing.
// Threads: the GL thread only, with the context current; one step is timed at a time (GL allows
// one time query at once).

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>

#include <GLES3/gl3.h>
// After gl3.h, which it needs.
#include <GLES2/gl2ext.h>

namespace surroundd::render {

enum class GpuStep { kUpload, kStitch, kDraw, kReadBack, kCount };
inline constexpr std::size_t kGpuSteps = static_cast<std::size_t>(GpuStep::kCount);
const char* toString(GpuStep step);  // "upload", "stitch", "draw", "read-back"

class GpuTimer {
 public:
  static constexpr std::size_t kQueriesPerStep = 8;

  GpuTimer();
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  bool available() const { return available_; }

  // Times the GL commands issued while it lives as one run of `step`. `timer` may be null.
  class Scope {
   public:
    Scope(GpuTimer* timer, GpuStep step);
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    GpuTimer* timer_;  // null: not timed
  };

  struct Reading {
    GpuStep step = GpuStep::kUpload;
    std::chrono::nanoseconds time{0};
  };
  // The GPU times of the runs that have finished since the last call (none waited for), oldest
  // first per step; valid until the next call.
  std::span<const Reading> collect();
  // Runs not timed because their step's queries were all still unread.
  std::uint64_t untimed() const { return untimed_; }

 private:
  struct StepQueries {
    std::array<GLuint, kQueriesPerStep> names{};
    std::size_t oldest = 0;  // the oldest unread, if any
    std::size_t unread = 0;
  };
  // Starts a run of `step`; false when its queries are all unread (not timed).
  bool begin(GpuStep step);
  static void end();

  PFNGLGETQUERYOBJECTUI64VEXTPROC readResult_;
  bool available_ = false;
  std::array<StepQueries, kGpuSteps> steps_{};
  std::array<Reading, kGpuSteps * kQueriesPerStep> readings_{};
  std::uint64_t untimed_ = 0;
};

}  // namespace surroundd::render

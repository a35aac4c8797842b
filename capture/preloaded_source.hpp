#pragma once
// A recording played from memory as a live camera delivers it: decoded once at start (through
// FileSource: any video, image sequence or picture) into frames of a camera's pixel format — YUYV
// or NV12, BT.601 limited range as V4L2 cameras deliver them — and then each read() hands one of
// them over with the function a V4L2 camera's frames go through (holdFrame: a copy into the
// caller's frame, which holds it in the same format). A replay then costs per frame what a live
// camera costs instead of a video decode: what a benchmark of a live rig measures
// (surround-bench pipeline --input raw).
//
// Timestamps, looping and pacing are the file's, as FileSource replays it: the file's own
// timestamps, moved on by whole periods at each loop; real time or as fast as possible. Frames that
// do not decode are left out (said in the log once); frames decoded with concealed errors are
// shown and reported as FileSource reports them, at each showing.
//
// Memory: every frame is held, allocated at start: frames x the format's frame size (YUYV
// 2 bytes per pixel, NV12 1.5). More than `maxBytes` is a CaptureError naming the camera, the
// file, the bytes needed and the bytes allowed, raised before the decode where the file states its
// length. Nothing is allocated per frame.

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "capture/file_source.hpp"
#include "capture/pixel_conversion.hpp"

namespace surroundd::capture {

struct PreloadSettings {
  FileSourceSettings file;                  // what to decode, and how to play it (loop, pacing)
  PixelLayout format = PixelLayout::kYuyv;  // as held in memory: kYuyv, kUyvy or kNv12 only
  std::uint64_t maxBytes = std::uint64_t{1} << 30;  // the most all its frames may take
  // Where `maxBytes` comes from, added to the message when it is exceeded (e.g. the config key).
  std::string maxBytesOrigin;

  bool operator==(const PreloadSettings&) const = default;
};

// Bytes of one frame of `size` in `format` (kYuyv, kUyvy or kNv12), tightly packed.
std::size_t preloadedFrameBytes(PixelLayout format, cv::Size size);

class PreloadedSource final : public FrameSource {
 public:
  // Decodes the whole file. Throws CaptureError naming the camera and the file: as FileSource's
  // constructor does, for a format other than YUYV, UYVY or NV12, for a size the format cannot
  // hold (YUYV, UYVY: even width; NV12: even width and height), when the frames would take more
  // than maxBytes, or when no frame decodes. `start`: as FileSource's.
  PreloadedSource(std::string cameraName, PreloadSettings settings,
                  std::shared_ptr<ReplayStart> start = nullptr);
  ~PreloadedSource() override;

  cv::Size frameSize() const override;
  PixelFormat pixelFormat() const override;
  Timestamp nominalPeriod() const override;
  ReadStatus read(Frame& out) override;
  const std::string& lastError() const override;
  bool repeatsOnePicture() const override;  // one frame, looped

  std::size_t frameCount() const;  // one pass
  std::uint64_t bytes() const;     // held by the frames
  // Frame `index` of one pass as held: YUYV rows of width x 2 bytes; NV12 the luma rows, then the
  // interleaved chroma rows (CbCr), width bytes each.
  std::span<const std::uint8_t> frameData(std::size_t index) const;

 private:
  struct Impl;  // the frames and their clock stay out of the header
  std::unique_ptr<Impl> impl_;
};

}  // namespace surroundd::capture

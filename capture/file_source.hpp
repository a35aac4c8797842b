#pragma once
// A file-backed virtual camera: plays a video file (any container/codec FFmpeg decodes), an image
// sequence (printf pattern such as "front_%06d.png", FFmpeg's image2) or a still picture (one PNG,
// JPEG, ...) as if it were a camera.
//
// Pictures (a sequence or a still) have no frame rate of their own: they are played at
// `sequenceFps`. A still picture, or a sequence of one picture, is decoded once; looped, it is
// delivered again every period with a timestamp one period on (repeatsOnePicture()).
//
// Frames carry the file's own presentation timestamps in nanoseconds (not rebased, so that the four
// files of one recording stay aligned with each other); when looping, timestamps keep increasing
// across the loop so the stream stays monotonic. Real-time pacing sleeps until each frame is due on
// the steady clock; kAsFastAsPossible returns frames as fast as decoding allows (benchmarks, tests,
// lossless replay).

#include <filesystem>
#include <memory>
#include <string>

#include "capture/frame_source.hpp"
#include "capture/replay_clock.hpp"

namespace surroundd::capture {

struct FileSourceSettings {
  std::filesystem::path path;  // video file, picture, or image-sequence pattern with a printf %d
  double sequenceFps = 30.0;   // frame rate of pictures (a sequence, a still); videos carry theirs
  bool loop = false;           // restart at the end instead of reporting kEndOfStream
  Pacing pacing = Pacing::kRealtime;

  bool operator==(const FileSourceSettings&) const = default;
};

// Whether `path` names one picture file (by its extension: png, jpg, jpeg, bmp, tif, tiff, webp,
// ppm, pgm) rather than a video or an image-sequence pattern. For a config's defaults; FileSource
// itself goes by what FFmpeg finds in the file.
bool isStillPicturePath(const std::filesystem::path& path);

// The (first) picture in `path` as a FileSource decodes it (PNG, JPEG, ...: what FFmpeg reads),
// 8-bit BGR: for a picture a config names besides its cameras (a body mask). Throws CaptureError
// naming the file.
cv::Mat readPicture(const std::filesystem::path& path);

class FileSource final : public FrameSource {
 public:
  // Opens the file and decodes its first frame, so that a file that cannot deliver one fails here.
  // Throws CaptureError naming the camera and the file when it is missing, unreadable, not a video,
  // or has no decodable video stream. `start`: where its real-time pacing counts from, shared with
  // the rig's other replayed cameras (ReplayStart); none: its own first frame.
  FileSource(std::string cameraName, FileSourceSettings settings,
             std::shared_ptr<ReplayStart> start = nullptr);
  ~FileSource() override;

  cv::Size frameSize() const override;
  Timestamp nominalPeriod() const override;
  ReadStatus read(Frame& out) override;
  const std::string& lastError() const override;
  // A still picture or a one-picture sequence that loops.
  bool repeatsOnePicture() const override;
  // How many frames one pass holds as the file states it (a picture: 1; a video: its stream's frame
  // count, else its duration over the frame period); 0 when it does not say. For sizing only: the
  // frames that decode may be a few more or fewer.
  std::uint64_t frameCountHint() const;

 private:
  struct Impl;  // FFmpeg state stays out of the header
  std::unique_ptr<Impl> impl_;
};

}  // namespace surroundd::capture

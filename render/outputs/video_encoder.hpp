#pragma once
// H.264 (libx264, or a hardware encoder, through FFmpeg's libavcodec) into MP4 or MKV (chosen by
// the file extension), as MPEG-TS to a network address (`url`, e.g. udp://239.0.0.1:5600), or as
// encoded pictures handed to the caller (Annex B, for a server that sends them on: RTSP). The two
// streams are tuned for latency: no B-frames, a keyframe with its parameter sets every second so
// that a receiver can join any time, sooner on request (requestKeyframe()), and, with
// stampCaptureTime, each picture's capture time in it (capture_time_sei.hpp).
//
// The file is written as "<path>.part" and renamed to <path> when it has been finalized (trailer
// written). close() finalizes; the destructor finalizes too if close() was not called (an
// exception or a signal on the way out still leaves a playable file). A failure once frames have
// reached the file (a full disk, a failed encode) ends the file where it stands and renames it
// too, saying so in the error: Matroska, and MP4 written in fragments of at most a second, play
// up to where they were cut, so nothing written is lost. Only a file with no frame is removed. A
// file is not begun on a disk with less than 8 MiB free.
//
// A ".part" left by an earlier crash is overwritten. If construction fails, nothing is left behind.
//
// Timestamps are written as given (not moved to start at zero), so files of several cameras keep
// their relative start offsets. MP4 keeps them to the microsecond; Matroska to the millisecond (its
// muxer forces a 1/1000 time base), so frames there must be at least 1 ms apart.
//
// The encoder: libx264, any H.264 encoder of this FFmpeg by name (h264_nvenc, h264_vaapi through
// a VA-API device's frames, h264_v4l2m2m, ...), or "auto": the first hardware one of
// kHardwareH264Encoders that opens here, else libx264, with one log line that says which and why.
// x264's crf and preset apply to libx264; a hardware encoder gets the crf as its constant quality
// where it has one (nvenc cq, vaapi qp) and a bit rate of 0.1 bit per pixel otherwise. bgr24 and
// bit-exact output are libx264's only.
//
// Error policy: the constructor, write() and close() throw EncoderError with a message naming the
// file; the caller decides whether to stop or drop the output. close() after zero frames throws
// ("no frames written") and leaves no file: an empty video is not a useful output.

#include <array>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

namespace surroundd::render {

class EncoderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct VideoEncoderSettings {
  std::filesystem::path path;  // .mp4 or .mkv; unused when `url` is set
  cv::Size size;               // frame size in pixels (even width and height)
  double nominalFps = 30.0;    // rate hint for the container; timestamps decide the real timing
  int crf = 20;                // x264 constant rate factor; 0 = lossless
  std::string preset = "veryfast";  // x264 preset
  // yuv420p (plays everywhere), yuv444p (camera-master quality) or bgr24 (libx264rgb; with crf 0
  // the pictures come back bit for bit)
  std::string pixelFormat = "yuv420p";
  int threads = 0;        // encoder threads; 0 = codec's choice. Fix it for identical bytes.
  bool bitExact = false;  // leave out version strings so the same input gives the same bytes
  std::string url;        // udp://HOST:PORT: MPEG-TS over UDP instead of a file; for messages
                          // only when the pictures are handed over (the server's address)
  std::string encoder = "libx264";  // libx264 | auto | an FFmpeg H.264 encoder's name
  // Streams: each picture given a capture time carries it in an SEI message (libx264, nvenc).
  bool stampCaptureTime = false;

  bool operator==(const VideoEncoderSettings&) const = default;
};

// The hardware H.264 encoders "auto" tries, in this order.
inline constexpr std::array<const char*, 3> kHardwareH264Encoders{"h264_nvenc", "h264_vaapi",
                                                                  "h264_v4l2m2m"};
// Why `name` cannot be a VideoEncoderSettings::encoder here (not an H.264 encoder this FFmpeg
// has); none if it can.
std::optional<std::string> h264EncoderProblem(std::string_view name);

// One encoded picture: H.264 Annex B, a keyframe's parameter sets in front of it.
struct EncodedPicture {
  std::span<const std::uint8_t> bytes;  // valid during the call it is handed to
  std::chrono::nanoseconds timestamp;
  bool keyframe = false;
};
using EncodedPictureHandler = std::function<void(const EncodedPicture&)>;

class VideoEncoder {
 public:
  // Into settings.path or settings.url.
  explicit VideoEncoder(VideoEncoderSettings settings);
  // Each encoded picture to `handler`, on the thread that writes (no file; settings.url names it).
  VideoEncoder(VideoEncoderSettings settings, EncodedPictureHandler handler);
  ~VideoEncoder();
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  // `picture` is 8-bit BGR of settings.size, or I420 where takesI420() (frame_sink.hpp).
  // Timestamps must increase at the file's precision (see above); converted as BT.601 limited
  // range, and tagged so, so that decoders convert back alike. `captured` goes into the stream
  // with settings.stampCaptureTime.
  void write(const cv::Mat& picture, std::chrono::nanoseconds timestamp,
             std::optional<std::chrono::system_clock::time_point> captured = std::nullopt);
  // Whether write() takes I420 pictures: the stream is 4:2:0 (pixel format yuv420p).
  bool takesI420() const;
  // The next picture written is a keyframe (a viewer has joined). Safe from any thread.
  void requestKeyframe();
  // Flushes, finalizes and renames the file. Idempotent; the destructor calls it and logs errors.
  void close();

  const std::filesystem::path& path() const;
  // The file's path or the URL, for messages.
  std::string target() const;
  std::uint64_t framesWritten() const;
  // The FFmpeg encoder that writes it: "auto" resolved.
  std::string encoderName() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surroundd::render

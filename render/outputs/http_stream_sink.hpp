#pragma once
// The surround view as MJPEG over HTTP (libmicrohttpd), with a small live page.
//
//   GET  /              the live page: the picture, camera health and frame rate, view buttons
//   GET  /stream.mjpg   multipart/x-mixed-replace JPEGs; each client gets the newest picture each
//                       time one is made: a slow client skips pictures, it never queues them
//   GET  /snapshot.jpg  the newest picture (503 before the first one)
//   GET  /status.json   the text last given to setStatus() ("{}" before); the path and the page
//                       are settings, for other programs' pages on this stream
//   GET  /views.json    {"views": [...], "active": "top" or null}, for the page's buttons
//   POST /view?name=X   202 and X is handed once to takeViewRequest(); 400 if X is not a view
//
// Other paths are 404, other methods 405; a URL over 4 KiB is 414, a body over 1 KiB 413. At most
// 16 connections at a time (one thread each), idle ones closed after 15 s.
//
// Threads: requests are served on libmicrohttpd's threads. consume() is called from one thread at
// a time (the pipeline's, or an output queue's), which encodes the JPEGs, and only while someone
// looks (see wantsFrame()); the other calls are safe from any thread.
//
// Error policy: the constructor throws std::invalid_argument for bad settings and
// std::runtime_error if it cannot listen ("HTTP stream: cannot listen on 127.0.0.1:8080: Address
// already in use"); consume() throws RenderError if libjpeg-turbo fails. Nothing is thrown on the
// server's threads: a request that cannot be served gets an error status.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/outputs/frame_sink.hpp"
#include "render/outputs/http_server.hpp"

namespace surroundd::render {

struct HttpStreamSettings {
  std::string address = "127.0.0.1";  // IPv4 address to listen on; 0.0.0.0: every interface
  int port = 8080;                    // TCP port, 0..65535; 0: any free port (see port())
  int jpegQuality = 80;               // 1..100
  // Names the page offers as buttons (e.g. top, 360, orbit, split): letters, digits, '-' and '_'
  // (they become element ids and URL arguments). Empty: no switcher, every POST /view is 400.
  std::vector<std::string> views;
  std::string initialView;  // the view shown first, marked on the page; empty or one of `views`
  // Host names (besides IP addresses and localhost) the server answers to; see HttpServer.
  std::vector<std::string> allowedHosts;
  // Who may watch (HTTP basic authentication); none: anyone who reaches the address.
  std::optional<Credentials> credentials;
  std::chrono::milliseconds headerTimeout = kHeaderTimeout;  // for a whole request head
  // Another program's page on the same stream (surround-calibrate guide): the HTML served at "/"
  // (static, self-contained; empty: livePage()) and the path of setStatus()'s JSON.
  std::string_view page;
  std::string statusPath = "/status.json";

  // Throws std::invalid_argument naming the field.
  void validate() const;
  bool operator==(const HttpStreamSettings&) const = default;
};

class HttpStreamSink final : public FrameSink, public ViewPage {
 public:
  explicit HttpStreamSink(HttpStreamSettings settings);  // listens at once
  ~HttpStreamSink() override;                            // stops the server if finish() did not

  // Encodes `bgr` (8-bit BGR) to JPEG when wantsFrame(); otherwise does nothing.
  void consume(const cv::Mat& bgr, const PictureTime& time) override;
  // True while a stream client is connected, before the first JPEG, and after a snapshot request
  // until the next picture.
  bool wantsFrame(std::chrono::nanoseconds streamTime) const override;
  // Ends the streams and stops the server; requests after it are refused. Idempotent.
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  // "HTTP stream on http://127.0.0.1:8080/ (412 frames encoded, 380 sent to 2 clients)"
  std::string describe() const override;

  int port() const;  // the bound port (the chosen one when settings.port is 0)
  // The JSON object served as /status.json; the page shows `fps` (number), `frames` (number),
  // `cameras` ({"front": "ok", ...}) and any other key as text.
  void setStatus(std::string json) override;
  // The view last asked for by POST /view, once; nullopt if none since the last call.
  std::optional<std::string> takeViewRequest() override;
  // The view shown now, when it was switched another way (surroundctl): the page marks it.
  void setActiveView(std::string name) override;
  ViewPage* page() override { return this; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surroundd::render

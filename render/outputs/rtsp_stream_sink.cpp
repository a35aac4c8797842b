#include "render/outputs/rtsp_stream_sink.hpp"

#include <atomic>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gst/app/gstappsrc.h>
#include <gst/gst.h>
#include <gst/rtsp-server/rtsp-server.h>

namespace surroundd::render {
namespace {

// How long the last picture gets to reach the viewers before the end of the stream is sent: a
// viewer that reads the end (an RTCP BYE, on a socket of its own) first would drop what is still
// unread on the RTP socket (FFmpeg does).
constexpr auto kLastPictureLeaves = std::chrono::milliseconds(50);
// After the end of the stream has gone out, how long the viewers get to leave on their own (they
// leave when its RTCP BYE arrives) before the server closes their connections.
constexpr auto kViewersLeave = std::chrono::seconds(2);
// Threads the server serves its clients on: one each up to this many (see listen()).
constexpr gint kClientThreads = 8;

// The shared pipeline. Each picture is timed by its own stream time from the pipeline's first
// (RTP timestamps spaced as the cameras took them), and sent as soon as it comes: the server's
// sinks are told not to wait for the pipeline clock (see onMediaPrepared). Pictures wait for a
// slow connection up to a second's worth; past that the oldest give way, and the viewer recovers
// at the next keyframe. The encoder puts the parameter sets in front of every keyframe itself, so
// a viewer needs nothing from the SDP to start; rtph264pay must not add its own (config-interval
// 0): it would put them after the capture time's SEI, which splits the picture in two.
constexpr const char* kLaunch =
    "( appsrc name=pictures is-live=true format=time max-buffers=30 "
    "leaky-type=downstream caps=video/x-h264,stream-format=byte-stream,alignment=au "
    "! rtph264pay name=pay0 pt=96 config-interval=0 )";

// The GStreamer elements it needs, with the Debian package that has each.
struct NeededElement {
  const char* name;
  const char* package;
};
constexpr NeededElement kNeededElements[] = {{"appsrc", "gstreamer1.0-plugins-base"},
                                             {"rtph264pay", "gstreamer1.0-plugins-good"}};

struct GObjectUnref {
  void operator()(gpointer object) const noexcept { g_object_unref(object); }
};
template <typename T>
using GObjectPtr = std::unique_ptr<T, GObjectUnref>;

struct MainContextUnref {
  void operator()(GMainContext* context) const noexcept { g_main_context_unref(context); }
};
struct MainLoopUnref {
  void operator()(GMainLoop* loop) const noexcept { g_main_loop_unref(loop); }
};
struct SourceUnref {
  void operator()(GSource* source) const noexcept {
    g_source_destroy(source);
    g_source_unref(source);
  }
};

// GStreamer, started once per process; why it cannot be, if so.
std::string gstreamerProblem() {
  static const std::string kProblem = [] {
    GError* error = nullptr;
    if (gst_init_check(nullptr, nullptr, &error) == FALSE) {
      std::string why = fmt::format("cannot start GStreamer: {}",
                                    error != nullptr ? error->message : "no reason given");
      g_clear_error(&error);
      return why;
    }
    for (const auto& element : kNeededElements) {
      GstElementFactory* factory = gst_element_factory_find(element.name);
      if (factory == nullptr) {
        return fmt::format("GStreamer has no '{}' element (install {})", element.name,
                           element.package);
      }
      gst_object_unref(factory);
    }
    return std::string();
  }();
  return kProblem;
}

}  // namespace

struct RtspStreamSink::Impl {
  RtspStreamSettings settings;
  std::optional<VideoEncoder> encoder;
  std::unique_ptr<GMainContext, MainContextUnref> context{g_main_context_new()};
  std::unique_ptr<GMainLoop, MainLoopUnref> loop{g_main_loop_new(context.get(), FALSE)};
  GObjectPtr<GstRTSPServer> server;  // made once GStreamer is started
  std::unique_ptr<GSource, SourceUnref> listening;
  std::thread thread;  // runs `loop`: every callback below but consume()'s
  int port = 0;

  // Guards `pictures` and `connected`: the server's threads (its loop, and the media's own for
  // "unprepared") set them, the caller's pushes into `pictures`.
  std::mutex mutex;
  GstAppSrc* pictures = nullptr;  // the shared pipeline's way in (a reference), while it exists
  GstRTSPMedia* media = nullptr;  // whose pipeline that is (no reference: `connected` holds one)
  std::optional<std::chrono::nanoseconds> firstTimestamp;  // of the pictures pushed into it
  // The media and clients that call us back, while they do (a reference each, dropped when the
  // client leaves or the media ends), so that stop() can tell them to stop.
  std::vector<GObjectPtr<GObject>> connected;
  std::atomic<bool> watched{false};
  std::atomic<int> viewers{0};
  std::atomic<std::uint64_t> viewersServed{0};
  std::uint64_t frames = 0;  // the caller's thread only
  bool stopped = false;

  void listen();
  void serve();
  void send(const EncodedPicture& picture);
  void stop();
  void follow(gpointer object) { connected.emplace_back(G_OBJECT(g_object_ref(object))); }
  void unfollow(gpointer object) {
    std::erase_if(connected, [this, object](const GObjectPtr<GObject>& followed) {
      if (followed.get() != object) return false;
      g_signal_handlers_disconnect_by_data(object, this);
      return true;
    });
  }

  static void onMediaConfigure(GstRTSPMediaFactory* factory, GstRTSPMedia* media, gpointer self);
  static void onMediaPrepared(GstRTSPMedia* media, gpointer self);
  static void onMediaUnprepared(GstRTSPMedia* media, gpointer self);
  static void onClientConnected(GstRTSPServer* server, GstRTSPClient* client, gpointer self);
  static void onClientClosed(GstRTSPClient* client, gpointer self);
  static void onPlay(GstRTSPClient* client, GstRTSPContext* request, gpointer self);
};

void RtspStreamSink::Impl::listen() {
  const std::string where = fmt::format("{}:{}", settings.address, settings.port);
  if (settings.name.empty() || settings.name.find_first_of("/?# ") != std::string::npos) {
    throw std::runtime_error(fmt::format(
        "RTSP stream on {}: the name must be one path segment, got '{}'", where, settings.name));
  }
  if (const std::string problem = gstreamerProblem(); !problem.empty()) {
    throw std::runtime_error(fmt::format("RTSP stream on {}: {}", where, problem));
  }
  server.reset(gst_rtsp_server_new());
  GstRTSPServer* s = server.get();
  gst_rtsp_server_set_address(s, settings.address.c_str());
  gst_rtsp_server_set_service(s, std::to_string(settings.port).c_str());
  GstRTSPMediaFactory* factory = gst_rtsp_media_factory_new();
  gst_rtsp_media_factory_set_launch(factory, kLaunch);
  gst_rtsp_media_factory_set_shared(factory, TRUE);
  g_signal_connect(factory, "media-configure", G_CALLBACK(onMediaConfigure), this);
  if (settings.credentials) {
    // gst-rtsp-server's basic authentication: a client that does not send the user and password
    // gets 401 and sees nothing of the stream; the user's token gives it the factory's role.
    const GObjectPtr<GstRTSPAuth> auth(gst_rtsp_auth_new());
    gchar* basic = gst_rtsp_auth_make_basic(settings.credentials->user.c_str(),
                                            settings.credentials->password.c_str());
    GstRTSPToken* token =
        gst_rtsp_token_new(GST_RTSP_TOKEN_MEDIA_FACTORY_ROLE, G_TYPE_STRING, "viewer", nullptr);
    gst_rtsp_auth_add_basic(auth.get(), basic, token);
    g_free(basic);
    gst_rtsp_token_unref(token);
    gst_rtsp_media_factory_add_role(factory, "viewer", GST_RTSP_PERM_MEDIA_FACTORY_ACCESS,
                                    G_TYPE_BOOLEAN, TRUE, GST_RTSP_PERM_MEDIA_FACTORY_CONSTRUCT,
                                    G_TYPE_BOOLEAN, TRUE, nullptr);
    gst_rtsp_server_set_auth(s, auth.get());
  }
  const GObjectPtr<GstRTSPMountPoints> mounts(gst_rtsp_server_get_mount_points(s));
  gst_rtsp_mount_points_add_factory(mounts.get(), ("/" + settings.name).c_str(), factory);
  g_signal_connect(s, "client-connected", G_CALLBACK(onClientConnected), this);
  // Each client on a thread of its own (up to kClientThreads, then shared): with all of them on
  // one, a client sending a request line of a megabyte held every other one up while it was read.
  const GObjectPtr<GstRTSPThreadPool> threads(gst_rtsp_server_get_thread_pool(s));
  gst_rtsp_thread_pool_set_max_threads(threads.get(), kClientThreads);

  GError* error = nullptr;
  listening.reset(gst_rtsp_server_create_source(s, nullptr, &error));
  if (!listening) {
    const std::string why = error != nullptr ? error->message : "no reason given";
    g_clear_error(&error);
    throw std::runtime_error(fmt::format("RTSP stream: cannot listen on {}: {}", where, why));
  }
  g_source_attach(listening.get(), context.get());
  port = gst_rtsp_server_get_bound_port(s);
}

void RtspStreamSink::Impl::serve() {
  thread = std::thread([this] {
    g_main_context_push_thread_default(context.get());
    g_main_loop_run(loop.get());
    // What closing the connections left to do (their sources' last calls).
    while (g_main_context_iteration(context.get(), FALSE) == TRUE) {
    }
    g_main_context_pop_thread_default(context.get());
  });
}

void RtspStreamSink::Impl::onMediaConfigure(GstRTSPMediaFactory* /*factory*/, GstRTSPMedia* media,
                                            gpointer self) {
  auto& s = *static_cast<Impl*>(self);
  const GObjectPtr<GstElement> bin(gst_rtsp_media_get_element(media));
  GstElement* source = gst_bin_get_by_name_recurse_up(GST_BIN(bin.get()), "pictures");
  {
    const std::lock_guard lock(s.mutex);
    if (s.pictures != nullptr) gst_object_unref(s.pictures);
    s.pictures = GST_APP_SRC(source);
    s.media = media;
    s.firstTimestamp.reset();
    s.follow(media);
    g_signal_connect(media, "prepared", G_CALLBACK(onMediaPrepared), self);
    g_signal_connect(media, "unprepared", G_CALLBACK(onMediaUnprepared), self);
  }
  // The first picture of a new pipeline starts a stream: a keyframe, with its parameter sets.
  s.encoder->requestKeyframe();
  s.watched = true;
}

void RtspStreamSink::Impl::onMediaPrepared(GstRTSPMedia* media, gpointer /*self*/) {
  // The server's sinks (one per transport, made while preparing) would hold each picture until the
  // pipeline clock reaches its time, which a pause for a joining viewer's PLAY moves: a picture
  // of a live view goes out as soon as it is encoded.
  const GObjectPtr<GstElement> bin(gst_rtsp_media_get_element(media));
  const GObjectPtr<GstObject> pipeline(gst_object_get_parent(GST_OBJECT(bin.get())));
  if (!pipeline) return;
  GstIterator* sinks = gst_bin_iterate_sinks(GST_BIN(pipeline.get()));
  gst_iterator_foreach(
      sinks,
      [](const GValue* item, gpointer) {
        g_object_set(g_value_get_object(item), "sync", FALSE, nullptr);
      },
      nullptr);
  gst_iterator_free(sinks);
}

void RtspStreamSink::Impl::onMediaUnprepared(GstRTSPMedia* media, gpointer self) {
  auto& s = *static_cast<Impl*>(self);
  const std::lock_guard lock(s.mutex);
  s.unfollow(media);
  if (media != s.media) return;  // one that a newer pipeline has replaced already
  s.watched = false;
  s.media = nullptr;
  if (s.pictures != nullptr) gst_object_unref(s.pictures);
  s.pictures = nullptr;
}

void RtspStreamSink::Impl::onClientConnected(GstRTSPServer* /*server*/, GstRTSPClient* client,
                                             gpointer self) {
  auto& s = *static_cast<Impl*>(self);
  ++s.viewers;
  const std::lock_guard lock(s.mutex);
  s.follow(client);
  g_signal_connect(client, "closed", G_CALLBACK(onClientClosed), self);
  g_signal_connect(client, "play-request", G_CALLBACK(onPlay), self);
}

void RtspStreamSink::Impl::onClientClosed(GstRTSPClient* client, gpointer self) {
  auto& s = *static_cast<Impl*>(self);
  --s.viewers;
  const std::lock_guard lock(s.mutex);
  s.unfollow(client);
}

void RtspStreamSink::Impl::onPlay(GstRTSPClient* /*client*/, GstRTSPContext* /*request*/,
                                  gpointer self) {
  // A viewer joining a running stream starts at the next picture instead of the next keyframe.
  auto& s = *static_cast<Impl*>(self);
  s.encoder->requestKeyframe();
  ++s.viewersServed;
}

void RtspStreamSink::Impl::send(const EncodedPicture& picture) {
  const std::lock_guard lock(mutex);
  if (pictures == nullptr) return;  // the last viewer has just left
  if (!firstTimestamp) firstTimestamp = picture.timestamp;
  GstBuffer* buffer = gst_buffer_new_memdup(picture.bytes.data(), picture.bytes.size());
  GST_BUFFER_PTS(buffer) = static_cast<GstClockTime>((picture.timestamp - *firstTimestamp).count());
  // appsrc takes the buffer; while its pipeline starts or stops it drops it.
  gst_app_src_push_buffer(pictures, buffer);
}

void RtspStreamSink::Impl::stop() {
  if (stopped) return;
  stopped = true;
  if (!thread.joinable()) return;
  // On the loop's own thread, where the connections are served: stop listening, close them, end.
  g_main_context_invoke(
      context.get(),
      [](gpointer self) -> gboolean {
        auto& s = *static_cast<Impl*>(self);
        g_source_destroy(s.listening.get());
        gst_rtsp_server_client_filter(
            s.server.get(),
            [](GstRTSPServer*, GstRTSPClient*, gpointer) { return GST_RTSP_FILTER_REMOVE; },
            nullptr);
        g_main_loop_quit(s.loop.get());
        return G_SOURCE_REMOVE;
      },
      this);
  thread.join();
  const std::lock_guard lock(mutex);
  for (const auto& object : connected) g_signal_handlers_disconnect_by_data(object.get(), this);
  connected.clear();
  if (pictures != nullptr) gst_object_unref(pictures);
  pictures = nullptr;
  media = nullptr;
  watched = false;
}

RtspStreamSink::RtspStreamSink(RtspStreamSettings settings) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.settings = std::move(settings);
  s.listen();
  s.settings.video.url = url();  // names the stream in the encoder's messages
  s.settings.video.stampCaptureTime = true;
  s.encoder.emplace(s.settings.video, [&s](const EncodedPicture& picture) { s.send(picture); });
  s.serve();
}

RtspStreamSink::~RtspStreamSink() {
  impl_->stop();
  // Now, while what it hands its last pictures to is still there (it finalizes unless finished).
  impl_->encoder.reset();
}

void RtspStreamSink::consume(const cv::Mat& picture, const PictureTime& time) {
  Impl& s = *impl_;
  if (!s.watched) return;
  s.encoder->write(picture, time.stream, time.captured);
  ++s.frames;
}

bool RtspStreamSink::takesI420() const { return impl_->encoder->takesI420(); }

bool RtspStreamSink::wantsFrame(std::chrono::nanoseconds /*streamTime*/) const {
  return impl_->watched;
}

void RtspStreamSink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  Impl& s = *impl_;
  s.encoder->close();  // what the encoder still holds goes out first
  if (s.frames > 0) std::this_thread::sleep_for(kLastPictureLeaves);
  {
    const std::lock_guard lock(s.mutex);
    if (s.pictures != nullptr) gst_app_src_end_of_stream(s.pictures);
  }
  const auto deadline = std::chrono::steady_clock::now() + kViewersLeave;
  while (s.viewers > 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  s.stop();
}

std::string RtspStreamSink::describe() const {
  return fmt::format("RTSP stream {} ({} frames, {} viewers)", url(), impl_->frames,
                     impl_->viewersServed.load());
}

int RtspStreamSink::port() const { return impl_->port; }

std::string RtspStreamSink::url() const {
  return fmt::format("rtsp://{}:{}/{}", impl_->settings.address, impl_->port, impl_->settings.name);
}

int RtspStreamSink::viewers() const { return impl_->viewers; }

}  // namespace surroundd::render

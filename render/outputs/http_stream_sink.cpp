#include "render/outputs/http_stream_sink.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string_view>

#include <arpa/inet.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <netinet/in.h>

#include "render/outputs/http_page.hpp"
#include "render/outputs/http_server.hpp"
#include "render/outputs/jpeg_encoder.hpp"

namespace surroundd::render {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kStreamBlockBytes = std::size_t{32} * 1024;
// A picture encoded less than kFreshFor ago is live. An older one (nobody looked, so the pipeline
// stopped encoding) is sent to a new stream client or a snapshot request only if no fresh one comes
// within kFreshWait. A stream with no new picture for kResendAfter gets the newest again: the
// client sees the stream is alive, and a client that has gone is noticed (the send fails).
constexpr auto kFreshFor = std::chrono::milliseconds(250);
constexpr auto kFreshWait = std::chrono::seconds(1);
constexpr auto kResendAfter = std::chrono::seconds(1);
constexpr std::string_view kBoundary = "surroundd-frame";
constexpr const char* kStreamContentType = "multipart/x-mixed-replace; boundary=surroundd-frame";

bool isViewNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
         c == '_';
}

HttpStreamSettings validated(HttpStreamSettings settings) {
  settings.validate();
  return settings;
}

}  // namespace

void HttpStreamSettings::validate() const {
  const auto invalid = [](const std::string& what) {
    return std::invalid_argument("HTTP stream: " + what);
  };
  in_addr parsed{};
  if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) {
    throw invalid(
        fmt::format("address: expected an IPv4 address such as 127.0.0.1, got '{}'", address));
  }
  if (port < 0 || port > 65535) throw invalid(fmt::format("port: expected 0..65535, got {}", port));
  if (jpegQuality < 1 || jpegQuality > 100) {
    throw invalid(fmt::format("jpeg quality: expected 1..100, got {}", jpegQuality));
  }
  for (const std::string& view : views) {
    if (view.empty() || !std::all_of(view.begin(), view.end(), isViewNameChar)) {
      throw invalid(
          fmt::format("views: expected names of letters, digits, '-' and '_', got '{}'", view));
    }
  }
  if (statusPath.size() < 2 || statusPath.front() != '/' || statusPath == "/stream.mjpg" ||
      statusPath == "/snapshot.jpg" || statusPath == "/views.json" || statusPath == "/view") {
    throw invalid(fmt::format("status path: expected a free path such as /status.json, got '{}'",
                              statusPath));
  }
  if (!initialView.empty() && std::find(views.begin(), views.end(), initialView) == views.end()) {
    throw invalid(fmt::format("initial view: '{}' is not one of the views [{}]", initialView,
                              fmt::join(views, ", ")));
  }
}

struct HttpStreamSink::Impl {
  // One picture as JPEG. `bytes` holds the worst case for the picture size, so that swapping
  // buffers allocates nothing once both have seen the largest picture.
  struct Jpeg {
    std::vector<unsigned char> bytes;
    std::size_t size = 0;
    std::uint64_t sequence = 0;  // 1 for the first picture; 0: none yet
    Clock::time_point encodedAt;
  };

  // What one connection to /stream.mjpg is sending. Owned by its libmicrohttpd response; only
  // that connection's thread touches it.
  struct StreamClient {
    explicit StreamClient(Impl& owner) : server(owner) { ++owner.streamClients; }
    ~StreamClient() { --server.streamClients; }
    StreamClient(const StreamClient&) = delete;
    StreamClient& operator=(const StreamClient&) = delete;

    Impl& server;
    // The part being sent: boundary, headers, JPEG. A copy, so that the pipeline can swap in the
    // next picture meanwhile; it grows to the largest part, then is reused.
    std::vector<char> part;
    std::size_t sent = 0;        // bytes of `part` handed to libmicrohttpd
    std::uint64_t sequence = 0;  // of the picture in `part`
    Clock::time_point sentAt = Clock::now();
  };

  explicit Impl(HttpStreamSettings s)
      : settings(validated(std::move(s))),
        encoder(settings.jpegQuality),
        activeView(settings.initialView),
        server("HTTP stream", settings.address, settings.port, settings.allowedHosts,
               settings.headerTimeout, settings.credentials,
               [this](MHD_Connection* connection, std::string_view path, std::string_view method) {
                 return route(connection, path, method);
               }) {}
  ~Impl() { stop(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  HttpStreamSettings settings;

  // Only the thread that calls consume() (the pipeline's, or an output queue's) touches these.
  JpegEncoder encoder;
  std::vector<unsigned char> spare;  // the next picture is encoded here, then swapped with latest
  std::atomic<std::uint64_t> framesEncoded{0};  // atomic: describe() may be called elsewhere

  // Guards `latest` and `stopping`. The pipeline thread swaps a new JPEG into `latest`; the
  // server's threads copy it out (stream parts, snapshots) and wait on `pictureMade` for the next.
  // Held for a swap or one copy of JPEG bytes, never while encoding or sending.
  std::mutex pictureMutex;
  std::condition_variable pictureMade;  // also signalled when stopping
  Jpeg latest;
  bool stopping = false;

  // Guards the status and the views: set by the pipeline thread (setStatus, takeViewRequest) and
  // the server's (POST /view), read by the other side. Apart from pictureMutex so that a status
  // request never waits for a JPEG copy.
  std::mutex controlMutex;
  std::string status = "{}";
  std::optional<std::string> requestedView;
  std::string activeView;

  // Read by wantsFrame() without taking a lock.
  std::atomic<int> streamClients{0};
  std::atomic<bool> havePicture{false};
  std::atomic<bool> snapshotWanted{false};
  // For describe().
  std::atomic<std::uint64_t> picturesSent{0};  // stream parts and snapshots
  std::atomic<std::uint64_t> clientsServed{0};

  // Last, so that it starts when everything it serves exists, and stops first.
  HttpServer server;

  void stop() {
    {
      std::lock_guard lock(pictureMutex);
      stopping = true;
    }
    pictureMade.notify_all();  // streams end, snapshots stop waiting
    server.stop();
  }

  MHD_Result route(MHD_Connection* connection, std::string_view path, std::string_view method) {
    if (path == "/view") {
      return method == "POST" ? requestView(connection) : replyNotAllowed(connection, "POST");
    }
    const bool known = path == "/" || path == "/stream.mjpg" || path == "/snapshot.jpg" ||
                       path == settings.statusPath || path == "/views.json";
    if (!known) return reply(connection, MHD_HTTP_NOT_FOUND, "not found\n");
    if (method != "GET" && method != "HEAD") return replyNotAllowed(connection, "GET, HEAD");
    if (path == "/stream.mjpg") return startStream(connection);
    if (path == "/snapshot.jpg") return serveSnapshot(connection);
    if (path == settings.statusPath) {
      std::unique_lock lock(controlMutex);
      MHD_Response* response =
          MHD_create_response_from_buffer(status.size(), status.data(), MHD_RESPMEM_MUST_COPY);
      lock.unlock();
      return queue(connection, MHD_HTTP_OK, response, "application/json");
    }
    if (path == "/views.json") {
      return reply(connection, MHD_HTTP_OK, viewsJson(), "application/json");
    }
    // PERSISTENT: the page is static and libmicrohttpd never writes through the pointer.
    const std::string_view page = settings.page.empty() ? livePage() : settings.page;
    return queue(connection, MHD_HTTP_OK,
                 MHD_create_response_from_buffer(page.size(), const_cast<char*>(page.data()),
                                                 MHD_RESPMEM_PERSISTENT),
                 "text/html; charset=utf-8");
  }

  std::string viewsJson() {
    // View names are letters, digits, '-' and '_' (validate()): nothing to escape. `settings`
    // does not change after construction: no lock.
    std::string json = R"({"views": [)";
    for (std::size_t i = 0; i < settings.views.size(); ++i) {
      json += fmt::format("{}\"{}\"", i == 0 ? "" : ", ", settings.views[i]);
    }
    std::lock_guard lock(controlMutex);
    json += activeView.empty() ? R"(], "active": null})"
                               : fmt::format(R"(], "active": "{}"}})", activeView);
    return json;
  }

  MHD_Result requestView(MHD_Connection* connection) {
    const char* name = MHD_lookup_connection_value(connection, MHD_GET_ARGUMENT_KIND, "name");
    if (name == nullptr) {
      return reply(connection, MHD_HTTP_BAD_REQUEST, "expected /view?name=VIEW\n");
    }
    const auto& views = settings.views;
    if (std::find(views.begin(), views.end(), name) == views.end()) {
      return reply(connection, MHD_HTTP_BAD_REQUEST,
                   fmt::format("unknown view '{}'; this stream offers: {}\n", name,
                               views.empty() ? "none" : fmt::format("{}", fmt::join(views, ", "))));
    }
    {
      std::lock_guard lock(controlMutex);
      requestedView = name;
      activeView = name;
    }
    return reply(connection, MHD_HTTP_ACCEPTED, fmt::format("view {} requested\n", name));
  }

  MHD_Result startStream(MHD_Connection* connection) {
    auto client = std::make_unique<StreamClient>(*this);
    {
      std::lock_guard lock(pictureMutex);
      if (stopping) return reply(connection, MHD_HTTP_SERVICE_UNAVAILABLE, "stopping\n");
      // A stale picture counts as sent: the client waits for a fresh one (see kFreshWait).
      const bool fresh = latest.sequence != 0 && Clock::now() - latest.encodedAt < kFreshFor;
      client->sequence = fresh ? 0 : latest.sequence;
    }
    MHD_Response* response = MHD_create_response_from_callback(
        MHD_SIZE_UNKNOWN, kStreamBlockBytes, &Impl::readStream, client.get(), &Impl::endStream);
    if (response == nullptr) return MHD_NO;
    static_cast<void>(client.release());  // the response owns it now: endStream deletes it
    ++clientsServed;
    return queue(connection, MHD_HTTP_OK, response, kStreamContentType);
  }

  static void endStream(void* cls) { delete static_cast<StreamClient*>(cls); }

  static ssize_t readStream(void* cls, std::uint64_t /*position*/, char* buffer, size_t max) {
    StreamClient& client = *static_cast<StreamClient*>(cls);
    if (client.sent == client.part.size() && !client.server.nextPart(client)) {
      return MHD_CONTENT_READER_END_OF_STREAM;
    }
    const std::size_t count = std::min(max, client.part.size() - client.sent);
    std::memcpy(buffer, client.part.data() + client.sent, count);
    client.sent += count;
    if (client.sent == client.part.size()) ++client.server.picturesSent;
    return static_cast<ssize_t>(count);
  }

  // Waits for a picture the client has not had (or kResendAfter), and makes it the next part.
  // False when the server stops.
  bool nextPart(StreamClient& client) {
    std::unique_lock lock(pictureMutex);
    for (;;) {
      if (stopping) return false;
      const auto now = Clock::now();
      const bool have = latest.sequence != 0;
      if (have && (latest.sequence != client.sequence || now - client.sentAt >= kResendAfter)) {
        break;
      }
      pictureMade.wait_until(lock, have ? client.sentAt + kResendAfter : now + kResendAfter);
    }
    std::array<char, 128> header{};
    const std::size_t headerSize =
        fmt::format_to_n(header.data(), header.size(),
                         "--{}\r\nContent-Type: image/jpeg\r\nContent-Length: {}\r\n\r\n",
                         kBoundary, latest.size)
            .size;
    client.part.resize(headerSize + latest.size + 2);
    std::memcpy(client.part.data(), header.data(), headerSize);
    std::memcpy(client.part.data() + headerSize, latest.bytes.data(), latest.size);
    std::memcpy(client.part.data() + headerSize + latest.size, "\r\n", 2);
    client.sent = 0;
    client.sequence = latest.sequence;
    client.sentAt = Clock::now();
    return true;
  }

  MHD_Result serveSnapshot(MHD_Connection* connection) {
    std::unique_lock lock(pictureMutex);
    if (latest.sequence == 0) {
      lock.unlock();
      return reply(connection, MHD_HTTP_SERVICE_UNAVAILABLE, "no picture yet\n");
    }
    if (Clock::now() - latest.encodedAt >= kFreshFor) {
      snapshotWanted = true;  // the pipeline encodes the next picture (wantsFrame())
      const std::uint64_t stale = latest.sequence;
      pictureMade.wait_for(lock, kFreshWait, [&] { return stopping || latest.sequence != stale; });
    }
    MHD_Response* response =
        MHD_create_response_from_buffer(latest.size, latest.bytes.data(), MHD_RESPMEM_MUST_COPY);
    lock.unlock();
    ++picturesSent;
    ++clientsServed;
    return queue(connection, MHD_HTTP_OK, response, "image/jpeg");
  }
};

HttpStreamSink::HttpStreamSink(HttpStreamSettings settings)
    : impl_(std::make_unique<Impl>(std::move(settings))) {}

HttpStreamSink::~HttpStreamSink() = default;

void HttpStreamSink::consume(const cv::Mat& bgr, const PictureTime& time) {
  if (!wantsFrame(time.stream)) return;
  Impl& s = *impl_;
  const std::size_t size = s.encoder.encode(bgr, s.spare);
  {
    std::lock_guard lock(s.pictureMutex);
    std::swap(s.spare, s.latest.bytes);
    s.latest.size = size;
    ++s.latest.sequence;
    s.latest.encodedAt = Clock::now();
  }
  s.havePicture = true;
  s.snapshotWanted = false;
  s.pictureMade.notify_all();
  ++s.framesEncoded;
}

bool HttpStreamSink::wantsFrame(std::chrono::nanoseconds /*streamTime*/) const {
  return impl_->streamClients > 0 || !impl_->havePicture || impl_->snapshotWanted;
}

void HttpStreamSink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  impl_->stop();
}

std::string HttpStreamSink::describe() const {
  return fmt::format("HTTP stream on http://{}:{}/ ({} frames encoded, {} sent to {} clients)",
                     impl_->settings.address, port(), impl_->framesEncoded.load(),
                     impl_->picturesSent.load(), impl_->clientsServed.load());
}

int HttpStreamSink::port() const { return impl_->server.port(); }

void HttpStreamSink::setStatus(std::string json) {
  std::lock_guard lock(impl_->controlMutex);
  impl_->status = std::move(json);
}

std::optional<std::string> HttpStreamSink::takeViewRequest() {
  std::lock_guard lock(impl_->controlMutex);
  return std::exchange(impl_->requestedView, std::nullopt);
}

void HttpStreamSink::setActiveView(std::string name) {
  std::lock_guard lock(impl_->controlMutex);
  impl_->activeView = std::move(name);
}

}  // namespace surroundd::render

// HttpStreamSink over a real loopback socket: the snapshot, the MJPEG stream, the status, view
// requests, the page, refusals of what is too large or unknown, and JPEGs made only while someone
// looks.

#include "render/outputs/http_stream_sink.hpp"

#include <future>
#include <memory>
#include <stop_token>
#include <thread>

#include <arpa/inet.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <opencv2/imgcodecs.hpp>
#include <sys/socket.h>
#include <unistd.h>

#include "tests/support/http_client.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::render {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;
using ::testing::HasSubstr;
using testing::HttpConnection;
using testing::httpExchange;
using testing::httpRequest;

cv::Mat testPicture(int index) { return testing::syntheticPicture({320, 240}, index); }

HttpStreamSettings testSettings() {
  HttpStreamSettings settings;
  settings.port = 0;
  settings.jpegQuality = 90;
  settings.views = {"top", "360", "orbit", "split"};
  settings.initialView = "orbit";
  return settings;
}

cv::Mat decodeJpeg(const std::string& bytes) {
  return cv::imdecode(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())),
      cv::IMREAD_COLOR);
}

// PSNR of a JPEG against the picture it should show; 0 if it does not decode to that size.
double psnrOf(const std::string& jpeg, const cv::Mat& expected) {
  const cv::Mat decoded = decodeJpeg(jpeg);
  if (decoded.size() != expected.size()) return 0.0;
  return cv::PSNR(decoded, expected);
}

// One part of a multipart/x-mixed-replace stream: its JPEG bytes (empty if the stream ended).
std::string readPart(HttpConnection& stream) {
  const std::optional<std::string> head = stream.readUntil("\r\n\r\n");
  if (!head) return {};
  EXPECT_THAT(*head, HasSubstr("--surroundd-frame\r\n"));
  EXPECT_THAT(*head, HasSubstr("Content-Type: image/jpeg\r\n"));
  const std::size_t at = head->find("Content-Length: ");
  if (at == std::string::npos) return {};
  const std::size_t length = std::stoul(head->substr(at + 16));
  std::optional<std::string> jpeg = stream.readExactly(length);
  const std::optional<std::string> end = stream.readExactly(2);
  EXPECT_EQ(end.value_or(""), "\r\n");
  return jpeg.value_or("");
}

// Waits up to 5 s for `condition`.
template <typename Condition>
bool eventually(Condition condition) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(milliseconds(10));
  }
  return true;
}

TEST(HttpStreamSink, SnapshotIsUnavailableBeforeTheFirstPictureThenShowsIt) {
  HttpStreamSink sink(testSettings());
  EXPECT_GT(sink.port(), 0);
  EXPECT_EQ(httpRequest(sink.port(), "GET", "/snapshot.jpg").status, 503);

  sink.consume(testPicture(3), nanoseconds(0));
  const testing::HttpResponse snapshot = httpRequest(sink.port(), "GET", "/snapshot.jpg");
  EXPECT_EQ(snapshot.status, 200);
  EXPECT_THAT(snapshot.headers, HasSubstr("Content-Type: image/jpeg"));
  EXPECT_GE(psnrOf(snapshot.body, testPicture(3)), 30.0);
}

TEST(HttpStreamSink, StreamSendsEachNewPictureAsAJpegPart) {
  HttpStreamSink sink(testSettings());
  HttpConnection stream(sink.port());
  stream.send("GET /stream.mjpg HTTP/1.0\r\n\r\n");
  sink.consume(testPicture(1), nanoseconds(0));
  const testing::HttpResponse head = stream.readHead();
  EXPECT_EQ(head.status, 200);
  EXPECT_THAT(head.headers,
              HasSubstr("Content-Type: multipart/x-mixed-replace; boundary=surroundd-frame"));

  const std::string first = readPart(stream);
  EXPECT_GE(psnrOf(first, testPicture(1)), 30.0);
  EXPECT_TRUE(sink.wantsFrame(milliseconds(33))) << "a stream client is watching";

  sink.consume(testPicture(2), milliseconds(33));
  std::string second = readPart(stream);
  while (second == first) second = readPart(stream);  // a resend after a quiet second
  EXPECT_GE(psnrOf(second, testPicture(2)), 30.0);
  EXPECT_LT(psnrOf(second, testPicture(1)), 30.0) << "the two pictures differ";
}

TEST(HttpStreamSink, StreamEndsWhenTheSinkFinishesAndAGoneClientIsNoticed) {
  HttpStreamSink sink(testSettings());
  sink.consume(testPicture(1), nanoseconds(0));
  {
    HttpConnection stream(sink.port());
    stream.send("GET /stream.mjpg HTTP/1.0\r\n\r\n");
    EXPECT_EQ(stream.readHead().status, 200);
    EXPECT_FALSE(readPart(stream).empty());
  }
  // Only the one client above, now gone: the next send to it fails and it no longer counts.
  EXPECT_TRUE(eventually([&] { return !sink.wantsFrame(nanoseconds(0)); }));

  HttpConnection stream(sink.port());
  stream.send("GET /stream.mjpg HTTP/1.0\r\n\r\n");
  EXPECT_EQ(stream.readHead().status, 200);
  const auto started = std::chrono::steady_clock::now();
  sink.finish(testPicture(1), nanoseconds(0));
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(2));
  stream.readToEnd();  // returns: the server closed the stream
  EXPECT_THAT(sink.describe(), HasSubstr("HTTP stream on http://127.0.0.1:"));
}

TEST(HttpStreamSink, MakesJpegsOnlyWhileSomeoneLooks) {
  HttpStreamSink sink(testSettings());
  EXPECT_TRUE(sink.wantsFrame(nanoseconds(0))) << "no JPEG yet";
  sink.consume(testPicture(1), nanoseconds(0));
  EXPECT_FALSE(sink.wantsFrame(milliseconds(33))) << "a JPEG exists and nobody is connected";

  // A snapshot asked for after a quiet time gets a fresh picture, not the stale one.
  std::this_thread::sleep_for(milliseconds(400));
  auto snapshot = std::async(std::launch::async,
                             [&] { return httpRequest(sink.port(), "GET", "/snapshot.jpg"); });
  ASSERT_TRUE(eventually([&] { return sink.wantsFrame(milliseconds(66)); }));
  sink.consume(testPicture(2), milliseconds(66));
  EXPECT_FALSE(sink.wantsFrame(milliseconds(100)));
  const testing::HttpResponse response = snapshot.get();
  EXPECT_EQ(response.status, 200);
  EXPECT_GE(psnrOf(response.body, testPicture(2)), 30.0);

  // Issue 50: a new stream viewer after a quiet time gets a fresh picture first, not the one
  // from when the last viewer left.
  std::this_thread::sleep_for(milliseconds(400));
  HttpConnection stream(sink.port());
  stream.send("GET /stream.mjpg HTTP/1.0\r\n\r\n");
  EXPECT_EQ(stream.readHead().status, 200);
  ASSERT_TRUE(eventually([&] { return sink.wantsFrame(milliseconds(133)); }));
  std::this_thread::sleep_for(milliseconds(100));
  sink.consume(testPicture(3), milliseconds(133));
  const std::string first = readPart(stream);
  EXPECT_GE(psnrOf(first, testPicture(3)), 30.0);
  EXPECT_LT(psnrOf(first, testPicture(2)), 30.0);
}

// Issue 50: with credentials, every request without their user and password is answered 401
// asking for them (HTTP basic authentication), the stream and the page alike.
TEST(HttpStreamSink, WithCredentialsOnlyTheirUserAndPasswordSeeAnything) {
  HttpStreamSettings settings = testSettings();
  settings.credentials = Credentials{"driver", "correct horse battery"};
  HttpStreamSink sink(settings);
  sink.consume(testPicture(1), nanoseconds(0));
  const auto ask = [&](std::string_view target, std::string_view authorization) {
    std::string request = fmt::format("GET {} HTTP/1.0\r\nHost: 127.0.0.1\r\n", target);
    if (!authorization.empty())
      request += fmt::format("Authorization: Basic {}\r\n", authorization);
    return testing::httpExchange(sink.port(), request + "\r\n");
  };
  // base64 of "driver:correct horse battery" and of "driver:wrong horse battery".
  constexpr std::string_view kRight = "ZHJpdmVyOmNvcnJlY3QgaG9yc2UgYmF0dGVyeQ==";
  constexpr std::string_view kWrong = "ZHJpdmVyOndyb25nIGhvcnNlIGJhdHRlcnk=";
  for (const char* target : {"/", "/snapshot.jpg", "/status.json", "/stream.mjpg"}) {
    const auto refused = ask(target, "");
    EXPECT_EQ(refused.status, 401) << target;
    EXPECT_THAT(refused.headers, HasSubstr("WWW-Authenticate: Basic realm=\"surroundd\""))
        << target;
    EXPECT_EQ(ask(target, kWrong).status, 401) << target;
  }
  const auto snapshot = ask("/snapshot.jpg", kRight);
  EXPECT_EQ(snapshot.status, 200);
  EXPECT_GE(psnrOf(snapshot.body, testPicture(1)), 30.0);
  EXPECT_EQ(ask("/", kRight).status, 200);
}

TEST(HttpStreamSink, StatusIsWhatThePipelineLastSet) {
  HttpStreamSink sink(testSettings());
  EXPECT_EQ(httpRequest(sink.port(), "GET", "/status.json").body, "{}");
  sink.setStatus(R"({"fps": 20.5, "frames": 12, "cameras": {"front": "ok"}})");
  const testing::HttpResponse status = httpRequest(sink.port(), "GET", "/status.json");
  EXPECT_EQ(status.status, 200);
  EXPECT_THAT(status.headers, HasSubstr("Content-Type: application/json"));
  EXPECT_EQ(status.body, R"({"fps": 20.5, "frames": 12, "cameras": {"front": "ok"}})");
}

TEST(HttpStreamSink, ViewRequestsAreHandedOverOnce) {
  HttpStreamSink sink(testSettings());
  EXPECT_EQ(httpRequest(sink.port(), "GET", "/views.json").body,
            R"({"views": ["top", "360", "orbit", "split"], "active": "orbit"})");
  EXPECT_EQ(sink.takeViewRequest(), std::nullopt);

  EXPECT_EQ(httpRequest(sink.port(), "POST", "/view?name=top").status, 202);
  EXPECT_EQ(sink.takeViewRequest(), "top");
  EXPECT_EQ(sink.takeViewRequest(), std::nullopt);
  EXPECT_THAT(httpRequest(sink.port(), "GET", "/views.json").body, HasSubstr(R"("active": "top")"));

  const testing::HttpResponse unknown = httpRequest(sink.port(), "POST", "/view?name=fisheye");
  EXPECT_EQ(unknown.status, 400);
  EXPECT_THAT(unknown.body, HasSubstr("unknown view 'fisheye'"));
  EXPECT_EQ(httpRequest(sink.port(), "POST", "/view").status, 400);
  EXPECT_EQ(httpRequest(sink.port(), "GET", "/view?name=top").status, 405);
  EXPECT_EQ(sink.takeViewRequest(), std::nullopt);

  // Switched another way (surroundctl view): the page is told, and no request is made of it.
  sink.setActiveView("360");
  EXPECT_THAT(httpRequest(sink.port(), "GET", "/views.json").body, HasSubstr(R"("active": "360")"));
  EXPECT_EQ(sink.takeViewRequest(), std::nullopt);
}

TEST(HttpStreamSink, ServesThePageAndRefusesUnknownPathsAndMethods) {
  HttpStreamSink sink(testSettings());
  const testing::HttpResponse page = httpRequest(sink.port(), "GET", "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_THAT(page.headers, HasSubstr("Content-Type: text/html"));
  EXPECT_THAT(page.body, HasSubstr(R"(<img id="live" src="/stream.mjpg")"));
  EXPECT_THAT(page.body, HasSubstr(R"(id="status")"));
  EXPECT_THAT(page.body, ::testing::Not(HasSubstr("http://"))) << "no external resources";

  EXPECT_EQ(httpRequest(sink.port(), "GET", "/nope").status, 404);
  EXPECT_EQ(httpRequest(sink.port(), "DELETE", "/status.json").status, 405);
}

// The status of the answer, or 0 if the server closed the connection while the request was still
// being sent (the kernel may then drop its answer too).
int statusOrCutOff(int port, const std::string& request) {
  try {
    return httpExchange(port, request).status;
  } catch (const std::system_error&) {
    return 0;
  }
}

TEST(HttpStreamSink, RefusesOversizedRequestsAndGoesOn) {
  HttpStreamSink sink(testSettings());
  EXPECT_EQ(httpRequest(sink.port(), "GET", "/status.json?pad=" + std::string(8000, 'x')).status,
            414);
  const int huge =
      statusOrCutOff(sink.port(), "GET /" + std::string(200'000, 'x') + " HTTP/1.0\r\n\r\n");
  EXPECT_TRUE(huge == 0 || huge == 414) << huge;
  // A declared body over the limit is refused before it is sent.
  EXPECT_EQ(
      httpExchange(sink.port(), "POST /view?name=top HTTP/1.0\r\nContent-Length: 100000\r\n\r\n")
          .status,
      413);
  // A chunked body is counted as it comes; one far too large is cut off.
  std::string chunked =
      "POST /view?name=top HTTP/1.1\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n";
  for (int i = 0; i < 4; ++i) chunked += "400\r\n" + std::string(1024, 'y') + "\r\n";
  EXPECT_EQ(httpExchange(sink.port(), chunked + "0\r\n\r\n").status, 413);
  for (int i = 0; i < 100; ++i) chunked += "400\r\n" + std::string(1024, 'z') + "\r\n";
  const int endless = statusOrCutOff(sink.port(), chunked);
  EXPECT_TRUE(endless == 0 || endless == 413) << endless;
  EXPECT_EQ(sink.takeViewRequest(), std::nullopt);

  EXPECT_EQ(httpRequest(sink.port(), "GET", "/status.json").status, 200);
}

// Issue 18: the Host header was never checked, POST /view had no Origin check, and error bodies
// that repeat the request went out without nosniff: a web page the driver's browser opened could
// switch views and, through DNS rebinding, read the snapshot.
TEST(HttpStreamSink, ForeignHostsAndOriginsAreRefused) {
  HttpStreamSettings settings = testSettings();
  settings.allowedHosts = {"surround.local"};
  HttpStreamSink sink(settings);
  const auto get = [&](std::string_view host) {
    return httpExchange(sink.port(), fmt::format("GET /snapshot.jpg HTTP/1.1\r\nHost: {}\r\n"
                                                 "Connection: close\r\n\r\n",
                                                 host));
  };
  EXPECT_EQ(get("attacker.example").status, 421);
  EXPECT_EQ(get("attacker.example:" + std::to_string(sink.port())).status, 421);
  for (const std::string& host :
       {fmt::format("127.0.0.1:{}", sink.port()), std::string("localhost"),
        std::string("LOCALHOST:80"), std::string("[::1]:8080"), std::string("surround.local:8080"),
        std::string("192.168.1.7")}) {
    EXPECT_EQ(get(host).status, 503) << host;  // no picture yet, but answered
  }
  const auto post = [&](std::string_view origin) {
    return httpExchange(sink.port(),
                        fmt::format("POST /view?name=top HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n{}"
                                    "Content-Length: 0\r\nConnection: close\r\n\r\n",
                                    sink.port(), origin));
  };
  const auto crossSite = post("Origin: http://attacker.example\r\n");
  EXPECT_EQ(crossSite.status, 403);
  EXPECT_EQ(sink.takeViewRequest(), std::nullopt);
  EXPECT_EQ(post(fmt::format("Origin: http://127.0.0.1:{}\r\n", sink.port())).status, 202);
  EXPECT_EQ(sink.takeViewRequest(), "top");
  EXPECT_EQ(post("").status, 202);  // not from a browser page: no Origin
  const auto echoed = httpRequest(sink.port(), "POST", "/view?name=<script>");
  EXPECT_EQ(echoed.status, 400);
  EXPECT_THAT(echoed.headers, HasSubstr("X-Content-Type-Options: nosniff"));
  EXPECT_THAT(echoed.headers, HasSubstr("Content-Type: text/plain"));
}

// Found by the HTTP fuzz target: a POST with an Origin and no Host (HTTP/1.0 sends none) compared
// the origin with a null Host and crashed the daemon. It cannot be compared, so it is refused.
TEST(HttpStreamSink, AnOriginWithoutAHostIsRefused) {
  HttpStreamSink sink(testSettings());
  const auto answer =
      httpExchange(sink.port(), "POST /view?name=top HTTP/1.0\r\nOrigin: http://127.0.0.1\r\n\r\n");
  EXPECT_EQ(answer.status, 403);
  EXPECT_EQ(sink.takeViewRequest(), std::nullopt);
  EXPECT_EQ(httpRequest(sink.port(), "GET", "/status.json").status, 200);  // and it serves on
}

TEST(HttpStreamSink, SameOriginComparesSchemeLessOriginWithHost) {
  EXPECT_TRUE(isSameOrigin("http://127.0.0.1:8080", "127.0.0.1:8080"));
  EXPECT_TRUE(isSameOrigin("http://Surround.Local", "surround.local"));
  EXPECT_FALSE(isSameOrigin("http://attacker.example", "127.0.0.1:8080"));
  EXPECT_FALSE(isSameOrigin("null", "127.0.0.1"));  // sandboxed pages send "null"
  EXPECT_FALSE(isSameOrigin("", ""));
}

// Found by the host-check fuzz target: the address parser read a C string, so a name with a NUL
// after an address ("127.0.0.1\0.evil.example") passed as that address.
TEST(HttpStreamSink, AHostWithANulIsNotAnAddress) {
  using namespace std::string_view_literals;
  EXPECT_TRUE(isAllowedHost("127.0.0.1:8080", {}));
  EXPECT_FALSE(isAllowedHost("127.0.0.1\0.evil.example"sv, {}));
  EXPECT_FALSE(isAllowedHost("127.0.0.1\0\0:8080"sv, {}));
  EXPECT_FALSE(isAllowedHost("[::1\0]:8080"sv, {}));
}

// Issue 18: 16 clients sending a header line every 5 s kept every other request out for as long
// as they liked. Now a request head must be whole within the header timeout, or the connection is
// cut off (and one address holds at most 8 connections: libmicrohttpd's per-IP limit).
TEST(HttpStreamSink, SlowHeadersAreCutOff) {
  HttpStreamSettings settings = testSettings();
  settings.headerTimeout = milliseconds(500);
  HttpStreamSink sink(settings);
  std::vector<std::unique_ptr<HttpConnection>> slow;
  for (unsigned k = 0; k < kMaxHttpConnectionsPerAddress; ++k) {
    slow.push_back(std::make_unique<HttpConnection>(sink.port()));
    slow.back()->send("GET / HTTP/1.1\r\nX-a: b\r\n");  // and never the blank line
  }
  // Each is cut off once its head is overdue: its connection ends without an answer.
  for (auto& connection : slow) EXPECT_EQ(connection->readUntil("\r\n"), std::nullopt);
  // The server frees a cut-off connection's per-address slot just after it closes the socket (CI
  // once saw the first request meet a still-full quota), so a new client must get through within
  // a second, not necessarily at its first try.
  int status = 0;
  for (int attempt = 0; attempt < 20 && status != 200; ++attempt) {
    if (attempt > 0) std::this_thread::sleep_for(milliseconds(50));
    status = httpRequest(sink.port(), "GET", "/status.json").status;
  }
  EXPECT_EQ(status, 200);
}

// A client of the loopback address `from` (127.0.0.x) that sends a request head a line at a time
// and never ends it, connecting again whenever it is cut off. Never throws: it is the attack.
class SlowHeadClient {
 public:
  SlowHeadClient(int port, const char* from) : port_(port), from_(from) {}
  ~SlowHeadClient() { close(); }
  SlowHeadClient(const SlowHeadClient&) = delete;
  SlowHeadClient& operator=(const SlowHeadClient&) = delete;

  // One more header line, or a new connection where the last one was cut off.
  void step() {
    if (fd_ >= 0 && ::send(fd_, "X-a: b\r\n", 8, MSG_NOSIGNAL | MSG_DONTWAIT) == 8) return;
    close();
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    ::inet_pton(AF_INET, from_, &address.sin_addr);
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) return;
    address.sin_port = htons(static_cast<std::uint16_t>(port_));
    ::inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) return;
    [[maybe_unused]] const auto sent = ::send(fd_, "GET / HTTP/1.1\r\n", 16, MSG_NOSIGNAL);
  }

 private:
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  int port_;
  const char* from_;
  int fd_ = -1;
};

// Issue 51: slow-header clients from two addresses (8 + 8, within the per-address limit, each
// connecting again when cut off) held every place: the page failed 19 tries in 19 for 40 s. Those
// still sending their heads now hold at most half the places, the slowest cut off first.
TEST(HttpStreamSink, SlowHeadersFromSeveralAddressesLeaveRoomForOthers) {
  HttpStreamSink sink(testSettings());  // the default header timeout: 10 s, longer than the test
  const int port = sink.port();
  const std::jthread attack([port](const std::stop_token& stop) {
    std::vector<std::unique_ptr<SlowHeadClient>> clients;
    for (unsigned k = 0; k < 2 * kMaxHttpConnectionsPerAddress; ++k) {
      clients.push_back(std::make_unique<SlowHeadClient>(
          port, k < kMaxHttpConnectionsPerAddress ? "127.0.0.2" : "127.0.0.3"));
    }
    while (!stop.stop_requested()) {
      for (auto& client : clients) client->step();
      std::this_thread::sleep_for(milliseconds(100));
    }
  });
  std::this_thread::sleep_for(milliseconds(500));  // every place taken
  // A page asks again when a connection is refused, as a browser does: while the cut-off
  // connections' threads are still closing (longer on a loaded machine), every place can be
  // taken for a moment. Locked out, as before the fix, no try of any request got an answer.
  int answered = 0;
  int firstTries = 0;
  for (int request = 0; request < 10; ++request) {
    for (int attempt = 0; attempt < 3; ++attempt) {
      try {
        if (httpRequest(port, "GET", "/status.json").status == 200) {
          ++answered;
          firstTries += attempt == 0 ? 1 : 0;
          break;
        }
      } catch (const std::system_error&) {
        // refused for the moment: ask again
      }
      std::this_thread::sleep_for(milliseconds(50));
    }
    std::this_thread::sleep_for(milliseconds(100));
  }
  EXPECT_EQ(answered, 10) << firstTries << " of them at the first try";
}

TEST(HttpStreamSink, PortInUseIsAnErrorNamingIt) {
  HttpStreamSink first(testSettings());
  HttpStreamSettings settings = testSettings();
  settings.port = first.port();
  const std::string where = "127.0.0.1:" + std::to_string(first.port());
  EXPECT_THAT([&] { HttpStreamSink second(settings); },
              ::testing::ThrowsMessage<std::runtime_error>(::testing::AllOf(
                  HasSubstr("HTTP stream: cannot listen on " + where), HasSubstr("in use"))));
}

TEST(HttpStreamSink, FinishReleasesThePort) {
  HttpStreamSink first(testSettings());
  first.finish(cv::Mat(), nanoseconds(0));
  first.finish(cv::Mat(), nanoseconds(0));  // idempotent
  HttpStreamSettings settings = testSettings();
  settings.port = first.port();
  HttpStreamSink second(settings);
  EXPECT_EQ(httpRequest(second.port(), "GET", "/status.json").status, 200);
}

TEST(HttpStreamSink, SettingsValidateThemselves) {
  const auto invalid = [](auto change) {
    HttpStreamSettings settings = testSettings();
    change(settings);
    EXPECT_THROW(settings.validate(), std::invalid_argument);
    EXPECT_THROW(HttpStreamSink{settings}, std::invalid_argument);
  };
  EXPECT_NO_THROW(testSettings().validate());
  invalid([](HttpStreamSettings& s) { s.address = "localhost"; });
  invalid([](HttpStreamSettings& s) { s.port = 70000; });
  invalid([](HttpStreamSettings& s) { s.jpegQuality = 0; });
  invalid([](HttpStreamSettings& s) { s.views.emplace_back("a b"); });
  invalid([](HttpStreamSettings& s) { s.initialView = "fisheye"; });
}

}  // namespace
}  // namespace surroundd::render

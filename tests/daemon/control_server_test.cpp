// The control socket in-process: requests parsed or refused with a reason, a round trip through
// the server to a handler on "the pipeline thread", and clients that misbehave.

#include "daemon/control_server.hpp"

#include <atomic>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include "tests/support/temp_dir.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;
using Kind = ControlRequest::Kind;

// Short: a socket path must fit in 108 bytes.
std::filesystem::path socketPath(std::string_view name) {
  return std::filesystem::temp_directory_path() / fmt::format("surroundd-{}-{}", ::getpid(), name) /
         "control.sock";
}

TEST(ControlProtocol, ParsesTheRequestsAndSaysWhatIsWrongWithOthers) {
  EXPECT_EQ(parseControlRequest("status").request.kind, Kind::kStatus);
  EXPECT_EQ(parseControlRequest("metrics").request.kind, Kind::kMetrics);
  EXPECT_EQ(parseControlRequest("snapshot").request.kind, Kind::kSnapshot);
  EXPECT_EQ(parseControlRequest("reload").request.kind, Kind::kReload);
  EXPECT_EQ(parseControlRequest("calibration").request.kind, Kind::kCalibration);
  for (const std::string what : {"status", "accept", "revert"}) {
    const auto calibration = parseControlRequest("calibration " + what);
    EXPECT_TRUE(calibration.error.empty()) << calibration.error;
    EXPECT_EQ(calibration.request.kind, Kind::kCalibration);
    EXPECT_EQ(calibration.request.argument, what);
  }
  EXPECT_THAT(parseControlRequest("calibration now").error,
              HasSubstr("'calibration' takes status, accept or revert, not 'now'"));
  const auto view = parseControlRequest("view top");
  EXPECT_TRUE(view.error.empty());
  EXPECT_EQ(view.request.kind, Kind::kView);
  EXPECT_EQ(view.request.argument, "top");
  EXPECT_THAT(parseControlRequest("view").error, HasSubstr("'view' needs an argument"));
  const auto signal = parseControlRequest("signal gear=R steering_deg=-12.5");
  EXPECT_TRUE(signal.error.empty());
  EXPECT_EQ(signal.request.kind, Kind::kSignal);
  EXPECT_EQ(signal.request.argument, "gear=R steering_deg=-12.5");
  EXPECT_THAT(parseControlRequest("signal").error, HasSubstr("'signal' needs an argument"));
  EXPECT_THAT(parseControlRequest("status now").error, HasSubstr("'status' takes no argument"));
  EXPECT_THAT(parseControlRequest("shutdown").error, HasSubstr("unknown request 'shutdown'"));
  EXPECT_THAT(parseControlRequest("").error, HasSubstr("unknown request ''"));
  EXPECT_THAT(parseControlRequest("stat\x01us").error, HasSubstr("control or non-ASCII"));
}

TEST(ControlProtocol, RepliesAreFramedWithTheirLength) {
  EXPECT_EQ(encodeReply(ControlReply::success("abc\n")), "ok 4\nabc\n");
  EXPECT_EQ(encodeReply(ControlReply::failure("two\nlines")), "error two lines\n");
}

// A connected raw client that has sent `bytes` (maybe nothing) and reads nothing yet.
int connectRaw(const std::filesystem::path& path, std::string_view bytes = {}) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path.c_str());
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    ::close(fd);
    return -1;
  }
  if (!bytes.empty()) {
    [[maybe_unused]] const auto sent = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  }
  return fd;
}

// A raw client, for sending what surroundctl never would.
std::string exchange(const std::filesystem::path& path, std::string_view bytes, bool closeWrite) {
  const int fd = connectRaw(path, bytes);
  if (fd < 0) return "connect failed";
  if (closeWrite) ::shutdown(fd, SHUT_WR);
  std::string reply;
  std::array<char, 4096> buffer{};
  for (ssize_t n = 0; (n = ::recv(fd, buffer.data(), buffer.size(), 0)) > 0;) {
    reply.append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(fd);
  return reply;
}

class ControlServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::remove_all(path_.parent_path());
    server_ = std::make_unique<ControlServer>(path_);
    // Stands in for the pipeline thread: serves between "frame sets".
    pipeline_ = std::thread([this] {
      while (!stop_) {
        server_->serve([this](const ControlRequest& request) -> ControlAnswer {
          ++served_;
          if (request.kind == Kind::kView && request.argument != "top") {
            return ControlReply::failure("unknown view '" + request.argument + "'");
          }
          if (request.kind == Kind::kSnapshot) {
            // Like surroundd's: 16 MB, made off the pipeline thread.
            return {ControlReply::success({}), [this] {
                      encodedOnPipelineThread_ = std::this_thread::get_id() == pipeline_.get_id();
                      return std::string(16 << 20, 'p');
                    }};
          }
          return ControlReply::success(
              fmt::format("answer to {} {}", static_cast<int>(request.kind), request.argument));
        });
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    });
  }
  void TearDown() override {
    stop_ = true;
    pipeline_.join();
    server_.reset();
    std::filesystem::remove_all(path_.parent_path());
  }

  std::filesystem::path path_ = socketPath("server");
  std::unique_ptr<ControlServer> server_;
  std::atomic<bool> stop_{false};
  std::atomic<int> served_{0};
  std::atomic<bool> encodedOnPipelineThread_{true};
  std::thread pipeline_;
};

TEST_F(ControlServerTest, RequestsRoundTripThroughThePipelineThread) {
  const auto reply = sendControlRequest(path_, "view top", std::chrono::seconds(5));
  EXPECT_TRUE(reply.ok);
  EXPECT_EQ(reply.body, "answer to 2 top");
  const auto refused = sendControlRequest(path_, "view sideways", std::chrono::seconds(5));
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(refused.body, "unknown view 'sideways'");
  EXPECT_EQ(served_, 2);
  // Only the service's user and group may talk to it.
  struct stat info {};
  ASSERT_EQ(::stat(path_.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0660);
  EXPECT_TRUE(S_ISSOCK(info.st_mode));
}

TEST_F(ControlServerTest, MisbehavingClientsGetAnErrorAndTheServerGoesOn) {
  EXPECT_EQ(
      exchange(path_, "shutdown\n", false),
      "error unknown request 'shutdown' (status, metrics, calibration [status|accept|revert], "
      "view NAME, signal ITEMS, snapshot, reload)\n");
  EXPECT_EQ(exchange(path_, std::string(10000, 'x'), false),
            fmt::format("error request longer than {} bytes\n", kMaxRequestBytes));
  EXPECT_EQ(exchange(path_, "status", true), "error the request ended without a newline\n");
  EXPECT_EQ(exchange(path_, "sta", false), "error no complete request line in time\n");
  EXPECT_EQ(exchange(path_, std::string("\xff\xfe\n", 3), false),
            "error request has control or non-ASCII characters\n");
  EXPECT_EQ(served_, 0);  // none of them reached the pipeline
  EXPECT_EQ(exchange(path_, "status\n", false), "ok 12\nanswer to 0 ");
  EXPECT_EQ(served_, 1);
}

// Whether the server has said anything to `fd` yet (without waiting).
bool heardBack(int fd) {
  char byte = 0;
  return ::recv(fd, &byte, 1, MSG_DONTWAIT | MSG_PEEK) > 0;
}

// Issue 18: one client at a time with a backlog of 8 let 500 idle connections hold up a client
// for 33.7 s, and slow ones for seconds. Now every client has its own deadline: a client asking
// while hundreds sit idle or trickle is answered before any of them has been timed out, and the
// idle ones beyond the limit make room for it.
TEST_F(ControlServerTest, IdleAndSlowClientsHoldUpNobody) {
  std::vector<int> idle;
  for (std::size_t k = 0; k < ControlServer::kMaxClients + 44; ++k) {
    idle.push_back(connectRaw(path_));
    ASSERT_GE(idle.back(), 0) << k;
  }
  const int slow = connectRaw(path_, "sta");
  const auto reply = sendControlRequest(path_, "status", std::chrono::seconds(5));
  EXPECT_TRUE(reply.ok) << reply.body;
  // Answered while the newest idle ones and the slow one are still within their second.
  EXPECT_FALSE(heardBack(slow));
  EXPECT_FALSE(heardBack(idle.back()));
  // The oldest made room, and were told so.
  EXPECT_THAT(exchange(path_, "status\r\n", false), HasSubstr("ok "));  // CRLF is a line end
  std::string first;
  std::array<char, 256> buffer{};
  const auto n = ::recv(idle.front(), buffer.data(), buffer.size(), 0);
  if (n > 0) first.assign(buffer.data(), static_cast<std::size_t>(n));
  EXPECT_THAT(first, HasSubstr("too many clients"));
  for (const int fd : idle) ::close(fd);
  ::close(slow);
}

// Issue 51: 500 idle clients that connect again as soon as they are put out made `surroundctl
// status` fail 14 times in 14 ("no reply in time"): past kMaxClients the client put out was the
// one with a request on its way, accepted last. Idle ones make room now; every request is answered.
TEST_F(ControlServerTest, IdleClientsThatReconnectLockNobodyOut) {
  // Stopped and joined however the test ends.
  const std::jthread attacker([this](const std::stop_token& stop) {
    std::vector<int> idle(ControlServer::kMaxClients + 244, -1);
    while (!stop.stop_requested()) {
      for (int& fd : idle) {
        // One put out (told so, or closed) connects again at once.
        pollfd told{fd, POLLIN, 0};
        if (fd >= 0 && ::poll(&told, 1, 0) == 0) continue;
        if (fd >= 0) ::close(fd);
        fd = connectRaw(path_);
      }
    }
    for (const int fd : idle) {
      if (fd >= 0) ::close(fd);
    }
  });
  // The attack under way: the server is full and putting clients out.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  int answered = 0;
  for (int i = 0; i < 14; ++i) {
    try {
      const auto reply = sendControlRequest(path_, "status", std::chrono::seconds(5));
      answered += reply.ok ? 1 : 0;
      EXPECT_TRUE(reply.ok) << i << ": " << reply.body;
    } catch (const std::exception& e) {
      ADD_FAILURE() << i << ": " << e.what();
    }
  }
  EXPECT_EQ(answered, 14);
}

// A client that asks for a big reply and never reads it holds up no other client, and the slow
// part of an answer runs on the server's thread, not the pipeline's.
TEST_F(ControlServerTest, AClientThatNeverReadsHoldsUpNobody) {
  const int stuck = connectRaw(path_, "snapshot\n");
  // Its reply has begun: the first bytes are waiting in its socket, the rest in the server.
  pollfd readable{stuck, POLLIN, 0};
  ASSERT_EQ(::poll(&readable, 1, 10'000), 1);
  const auto reply = sendControlRequest(path_, "status", std::chrono::seconds(5));
  EXPECT_TRUE(reply.ok);
  EXPECT_FALSE(encodedOnPipelineThread_);
  ::close(stuck);
}

TEST_F(ControlServerTest, ASecondServerOnTheSamePathIsRefusedAndAStaleOneReplaced) {
  EXPECT_THAT([&] { ControlServer second(path_); }, ::testing::ThrowsMessage<std::runtime_error>(
                                                        HasSubstr("in use by a running server")));
  // The first one still answers.
  EXPECT_TRUE(sendControlRequest(path_, "status", std::chrono::seconds(5)).ok);

  const auto stalePath = socketPath("stale");
  std::filesystem::create_directories(stalePath.parent_path());
  {
    // A socket file left behind by a process that is gone.
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", stalePath.c_str());
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
    ::close(fd);
  }
  { const ControlServer replaced(stalePath); }
  EXPECT_FALSE(std::filesystem::exists(stalePath));  // removed with its server
  std::filesystem::remove_all(stalePath.parent_path());
}

// Issue 50: with XDG_RUNTIME_DIR set (any login shell) surroundctl never tried the service's
// socket. The user's own surroundd's is asked where it exists, else the service's where that does.
TEST(ControlClient, AsksTheUsersOwnSurrounddElseTheServices) {
  const testing::TempDir dir;
  const auto own = dir / "own.sock";
  const auto service = dir / "service.sock";
  EXPECT_EQ(controlSocketToAsk(own, service), own);  // neither: the error names the user's
  dir.write("service.sock", "");
  EXPECT_EQ(controlSocketToAsk(own, service), service);
  EXPECT_EQ(controlSocketToAsk({}, service), service);  // no runtime folder at all
  dir.write("own.sock", "");
  EXPECT_EQ(controlSocketToAsk(own, service), own);
}

TEST(ControlClient, SaysWhichSocketItCouldNotReach) {
  EXPECT_THAT(
      [] { sendControlRequest("/nonexistent/control.sock", "status", std::chrono::seconds(1)); },
      ::testing::ThrowsMessage<std::runtime_error>(
          HasSubstr("/nonexistent/control.sock: cannot connect: No such file or directory")));
}

}  // namespace
}  // namespace surroundd::daemon

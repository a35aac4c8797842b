#include "render/http_server.hpp"

#include <array>
#include <cerrno>
#include <charconv>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

namespace surroundd::render {
namespace {

constexpr unsigned kIdleTimeoutS = 15;
// Per connection: the request line and headers, then the send buffer of a streamed answer.
constexpr std::size_t kConnectionMemory = std::size_t{64} * 1024;
constexpr std::size_t kMaxUrlBytes = 4096;
constexpr std::size_t kMaxBodyBytes = 1024;
// libmicrohttpd takes an answer only before a body or after all of it, so a body found too large
// as it comes (chunked) is read on for the 413, up to this; beyond it the connection is closed.
constexpr std::size_t kMaxDiscardBytes = std::size_t{64} * 1024;

struct RequestState {
  std::size_t bodyBytes = 0;
  bool answered = false;
};

std::string errnoText(int error) {
  return std::error_code(error, std::generic_category()).message();
}

// Listens on address:port and returns the socket, which libmicrohttpd takes over (and closes).
// Binding here rather than in libmicrohttpd gives the system's reason for a failure.
int listenOn(const std::string& name, const std::string& address, int port, int& boundPort) {
  const auto fail = [&](const std::string& reason) {
    return std::runtime_error(
        fmt::format("{}: cannot listen on {}:{}: {}", name, address, port, reason));
  };
  sockaddr_in socketAddress{};
  socketAddress.sin_family = AF_INET;
  socketAddress.sin_port = htons(static_cast<std::uint16_t>(port));
  if (port < 0 || port > 65535 ||
      inet_pton(AF_INET, address.c_str(), &socketAddress.sin_addr) != 1) {
    throw fail("not an IPv4 address and port");
  }
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) throw fail(errnoText(errno));
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);  // restart despite TIME_WAIT
  socklen_t length = sizeof socketAddress;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&socketAddress), sizeof socketAddress) != 0 ||
      ::listen(fd, static_cast<int>(kMaxHttpConnections)) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&socketAddress), &length) != 0) {
    const int error = errno;
    ::close(fd);
    throw fail(errnoText(error));
  }
  boundPort = ntohs(socketAddress.sin_port);
  return fd;
}

void logFromServer(void* cls, const char* format, va_list arguments) {
  std::array<char, 512> text{};
  std::vsnprintf(text.data(), text.size(), format, arguments);
  std::string_view line(text.data());
  while (!line.empty() && line.back() == '\n') line.remove_suffix(1);
  spdlog::debug("{}: {}", *static_cast<const std::string*>(cls), line);
}

MHD_Result addArgumentBytes(void* total, MHD_ValueKind /*kind*/, const char* key,
                            const char* value) {
  *static_cast<std::size_t*>(total) +=
      std::strlen(key) + 2 + (value != nullptr ? std::strlen(value) : 0);
  return MHD_YES;
}

// The URL's length as sent, near enough: the path and the query arguments.
std::size_t urlBytes(MHD_Connection* connection, const char* url) {
  std::size_t total = std::strlen(url);
  MHD_get_connection_values(connection, MHD_GET_ARGUMENT_KIND, &addArgumentBytes, &total);
  return total;
}

}  // namespace

HttpServer::HttpServer(std::string name, const std::string& address, int port, Handler handler)
    : name_(std::move(name)), handler_(std::move(handler)) {
  const int fd = listenOn(name_, address, port, port_);
  daemon_ = MHD_start_daemon(
      MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION | MHD_USE_POLL | MHD_USE_ITC |
          MHD_USE_ERROR_LOG,
      0, nullptr, nullptr, &HttpServer::onRequest, this, MHD_OPTION_EXTERNAL_LOGGER, &logFromServer,
      &name_, MHD_OPTION_LISTEN_SOCKET, fd, MHD_OPTION_CONNECTION_LIMIT, kMaxHttpConnections,
      MHD_OPTION_CONNECTION_TIMEOUT, kIdleTimeoutS, MHD_OPTION_CONNECTION_MEMORY_LIMIT,
      kConnectionMemory, MHD_OPTION_NOTIFY_COMPLETED, &HttpServer::onCompleted, this,
      MHD_OPTION_END);
  if (daemon_ == nullptr) {
    ::close(fd);
    throw std::runtime_error(
        fmt::format("{}: cannot start the HTTP server on {}:{}", name_, address, port_));
  }
}

HttpServer::~HttpServer() { stop(); }

void HttpServer::stop() {
  if (daemon_ != nullptr) MHD_stop_daemon(daemon_);
  daemon_ = nullptr;
}

MHD_Result HttpServer::onRequest(void* cls, MHD_Connection* connection, const char* url,
                                 const char* method, const char* /*version*/,
                                 const char* /*uploadData*/, size_t* uploadDataSize,
                                 void** requestState) {
  auto* state = static_cast<RequestState*>(*requestState);
  if (state == nullptr) {      // first call, headers only: refuse what is too large before a body
    state = new RequestState;  // deleted by onCompleted
    *requestState = state;
    std::uint64_t declared = 0;
    const char* length =
        MHD_lookup_connection_value(connection, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (length != nullptr) std::from_chars(length, length + std::strlen(length), declared);
    if (urlBytes(connection, url) > kMaxUrlBytes) {
      state->answered = true;
      return reply(connection, MHD_HTTP_URI_TOO_LONG, "URL too long\n");
    }
    if (declared > kMaxBodyBytes) {
      state->answered = true;
      return reply(connection, MHD_HTTP_CONTENT_TOO_LARGE, "request body too large\n");
    }
    return MHD_YES;
  }
  if (*uploadDataSize > 0) {  // a body: counted and dropped
    state->bodyBytes += *uploadDataSize;
    *uploadDataSize = 0;
    return state->bodyBytes <= kMaxDiscardBytes ? MHD_YES : MHD_NO;
  }
  if (state->answered) return MHD_YES;
  state->answered = true;
  if (state->bodyBytes > kMaxBodyBytes) {
    return reply(connection, MHD_HTTP_CONTENT_TOO_LARGE, "request body too large\n");
  }
  return static_cast<HttpServer*>(cls)->handler_(connection, url, method);
}

void HttpServer::onCompleted(void* /*cls*/, MHD_Connection* /*connection*/, void** requestState,
                             MHD_RequestTerminationCode /*reason*/) {
  delete static_cast<RequestState*>(*requestState);
  *requestState = nullptr;
}

MHD_Result queue(MHD_Connection* connection, unsigned status, MHD_Response* response,
                 const char* contentType) {
  if (response == nullptr) return MHD_NO;
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, contentType);
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  const MHD_Result result = MHD_queue_response(connection, status, response);
  MHD_destroy_response(response);
  return result;
}

MHD_Result reply(MHD_Connection* connection, unsigned status, std::string_view text,
                 const char* contentType) {
  // MUST_COPY: libmicrohttpd copies the text, so the non-const pointer is never written through.
  return queue(connection, status,
               MHD_create_response_from_buffer(text.size(), const_cast<char*>(text.data()),
                                               MHD_RESPMEM_MUST_COPY),
               contentType);
}

MHD_Result replyNotAllowed(MHD_Connection* connection, const char* allowed) {
  MHD_Response* response =
      MHD_create_response_from_buffer(0, const_cast<char*>(""), MHD_RESPMEM_PERSISTENT);
  if (response != nullptr) MHD_add_response_header(response, MHD_HTTP_HEADER_ALLOW, allowed);
  return queue(connection, MHD_HTTP_METHOD_NOT_ALLOWED, response, "text/plain; charset=utf-8");
}

}  // namespace surroundd::render

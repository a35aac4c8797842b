#include "render/outputs/http_server.hpp"

#include <algorithm>
#include <array>
#include <cctype>
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

std::string lowered(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// "host:port" -> "host"; "[::1]:port" -> "[::1]".
std::string_view withoutPort(std::string_view host) {
  if (host.starts_with('[')) {
    const auto end = host.find(']');
    return end == std::string_view::npos ? host : host.substr(0, end + 1);
  }
  const auto colon = host.rfind(':');
  return colon == std::string_view::npos ? host : host.substr(0, colon);
}

bool isIpAddress(std::string_view name) {
  // inet_pton reads a C string: it would stop at a NUL and pass what comes before.
  if (name.find('\0') != std::string_view::npos) return false;
  std::array<unsigned char, sizeof(in6_addr)> address{};
  if (name.starts_with('[') && name.ends_with(']')) {
    const std::string inner(name.substr(1, name.size() - 2));
    return inet_pton(AF_INET6, inner.c_str(), address.data()) == 1;
  }
  return inet_pton(AF_INET, std::string(name).c_str(), address.data()) == 1;
}

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

bool isAllowedHost(std::string_view host, const std::vector<std::string>& allowedHosts) {
  const std::string name = lowered(withoutPort(host));
  if (name.empty()) return false;
  if (name == "localhost" || isIpAddress(name)) return true;
  return std::ranges::any_of(allowedHosts, [&](const std::string& allowed) {
    return lowered(withoutPort(allowed)) == name;
  });
}

bool isSameOrigin(std::string_view origin, std::string_view host) {
  const auto scheme = origin.find("://");
  return scheme != std::string_view::npos && lowered(origin.substr(scheme + 3)) == lowered(host);
}

HttpServer::HttpServer(std::string name, const std::string& address, int port,
                       std::vector<std::string> allowedHosts,
                       std::chrono::milliseconds headerTimeout,
                       std::optional<Credentials> credentials, Handler handler)
    : name_(std::move(name)),
      allowedHosts_(std::move(allowedHosts)),
      headerTimeout_(headerTimeout),
      credentials_(std::move(credentials)),
      handler_(std::move(handler)) {
  const int fd = listenOn(name_, address, port, port_);
  daemon_ = MHD_start_daemon(
      MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION | MHD_USE_POLL | MHD_USE_ITC |
          MHD_USE_ERROR_LOG,
      0, nullptr, nullptr, &HttpServer::onRequest, this, MHD_OPTION_EXTERNAL_LOGGER, &logFromServer,
      &name_, MHD_OPTION_LISTEN_SOCKET, fd, MHD_OPTION_CONNECTION_LIMIT, kMaxHttpConnections,
      MHD_OPTION_PER_IP_CONNECTION_LIMIT, kMaxHttpConnectionsPerAddress,
      MHD_OPTION_CONNECTION_TIMEOUT, kIdleTimeoutS, MHD_OPTION_CONNECTION_MEMORY_LIMIT,
      kConnectionMemory, MHD_OPTION_NOTIFY_COMPLETED, &HttpServer::onCompleted, this,
      MHD_OPTION_NOTIFY_CONNECTION, &HttpServer::onConnection, this, MHD_OPTION_END);
  if (daemon_ == nullptr) {
    ::close(fd);
    throw std::runtime_error(
        fmt::format("{}: cannot start the HTTP server on {}:{}", name_, address, port_));
  }
  reaper_ = std::thread([this] { cutOffSlowHeaders(); });
}

HttpServer::~HttpServer() { stop(); }

void HttpServer::stop() {
  {
    const std::lock_guard lock(headMutex_);
    stopping_ = true;
  }
  reaperWake_.notify_all();
  if (reaper_.joinable()) reaper_.join();
  if (daemon_ != nullptr) MHD_stop_daemon(daemon_);
  daemon_ = nullptr;
}

void HttpServer::onConnection(void* cls, MHD_Connection* connection, void** /*socketContext*/,
                              MHD_ConnectionNotificationCode code) {
  auto* self = static_cast<HttpServer*>(cls);
  const std::lock_guard lock(self->headMutex_);
  if (code == MHD_CONNECTION_NOTIFY_STARTED) {
    const MHD_ConnectionInfo* info =
        MHD_get_connection_info(connection, MHD_CONNECTION_INFO_CONNECTION_FD);
    if (info != nullptr) {
      self->connections_[connection] = {info->connect_fd, std::chrono::steady_clock::now()};
      self->cutOffSlowestHeads();
    }
  } else {
    // Before libmicrohttpd closes the socket, so the reaper never touches a reused descriptor.
    self->connections_.erase(connection);
  }
}

void HttpServer::markHead(MHD_Connection* connection, bool sending) {
  const std::lock_guard lock(headMutex_);
  const auto open = connections_.find(connection);
  if (open == connections_.end()) return;
  open->second.headSince = sending ? std::optional(std::chrono::steady_clock::now()) : std::nullopt;
}

void HttpServer::cutOffSlowestHeads() {
  std::vector<OpenConnection*> sending;
  for (auto& [connection, open] : connections_) {
    if (open.headSince) sending.push_back(&open);
  }
  if (sending.size() <= kMaxConnectionsSendingHeads) return;
  const auto slowestFirst = sending.begin() + (sending.size() - kMaxConnectionsSendingHeads);
  std::ranges::nth_element(sending, slowestFirst, {},
                           [](const OpenConnection* open) { return *open->headSince; });
  for (auto it = sending.begin(); it != slowestFirst; ++it) {
    // Its connection thread sees the socket fail and closes the connection itself.
    ::shutdown((*it)->fd, SHUT_RDWR);
    (*it)->headSince.reset();
  }
  spdlog::debug("{}: {} clients still sending their request heads were cut off to make room", name_,
                slowestFirst - sending.begin());
}

void HttpServer::cutOffSlowHeaders() {
  std::unique_lock lock(headMutex_);
  while (!stopping_) {
    reaperWake_.wait_for(
        lock, std::min<std::chrono::milliseconds>(headerTimeout_ / 2, std::chrono::seconds(1)));
    const auto now = std::chrono::steady_clock::now();
    for (auto& [connection, open] : connections_) {
      if (!open.headSince || now - *open.headSince < headerTimeout_) continue;
      // Its connection thread sees the socket fail and closes the connection itself.
      ::shutdown(open.fd, SHUT_RDWR);
      open.headSince.reset();
      spdlog::debug("{}: a client that sent no whole request head in {} ms was cut off", name_,
                    headerTimeout_.count());
    }
  }
}

bool HttpServer::authorized(MHD_Connection* connection) const {
  char* password = nullptr;
  char* user = MHD_basic_auth_get_username_password(connection, &password);
  const bool match =
      user != nullptr && password != nullptr && credentialsMatch(*credentials_, user, password);
  MHD_free(user);
  MHD_free(password);
  return match;
}

MHD_Result HttpServer::onRequest(void* cls, MHD_Connection* connection, const char* url,
                                 const char* method, const char* /*version*/,
                                 const char* /*uploadData*/, size_t* uploadDataSize,
                                 void** requestState) {
  auto* self = static_cast<HttpServer*>(cls);
  auto* state = static_cast<RequestState*>(*requestState);
  if (state == nullptr) {      // first call, headers only: refuse what is too large before a body
    state = new RequestState;  // deleted by onCompleted
    *requestState = state;
    self->markHead(connection, false);  // its head is in
    const char* host =
        MHD_lookup_connection_value(connection, MHD_HEADER_KIND, MHD_HTTP_HEADER_HOST);
    // No Host at all is an HTTP/1.0 client, not a browser (browsers always send one).
    if (host != nullptr && !isAllowedHost(host, self->allowedHosts_)) {
      state->answered = true;
      return reply(connection, MHD_HTTP_MISDIRECTED_REQUEST,
                   "this server does not answer to that Host; add it to the output's "
                   "allowed_hosts\n");
    }
    // Only GET and HEAD may come from a page of another origin (a browser's cross-site form or
    // fetch says where it comes from in Origin).
    const std::string_view verb(method);
    const char* origin =
        MHD_lookup_connection_value(connection, MHD_HEADER_KIND, MHD_HTTP_HEADER_ORIGIN);
    // Without a Host (HTTP/1.0) the origin cannot be compared: such a request is refused too.
    if (verb != "GET" && verb != "HEAD" && origin != nullptr &&
        (host == nullptr || !isSameOrigin(origin, host))) {
      state->answered = true;
      return reply(connection, MHD_HTTP_FORBIDDEN, "cross-origin request refused\n");
    }
    if (self->credentials_ && !self->authorized(connection)) {
      state->answered = true;
      return askForCredentials(connection);
    }
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
  return self->handler_(connection, url, method);
}

void HttpServer::onCompleted(void* cls, MHD_Connection* connection, void** requestState,
                             MHD_RequestTerminationCode /*reason*/) {
  delete static_cast<RequestState*>(*requestState);
  *requestState = nullptr;
  // Kept alive, the connection's next request head is on the clock from now.
  static_cast<HttpServer*>(cls)->markHead(connection, true);
}

MHD_Result queue(MHD_Connection* connection, unsigned status, MHD_Response* response,
                 const char* contentType) {
  if (response == nullptr) return MHD_NO;
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, contentType);
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  // Error bodies repeat what the client sent: never let a browser take them for HTML.
  MHD_add_response_header(response, "X-Content-Type-Options", "nosniff");
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

MHD_Result askForCredentials(MHD_Connection* connection) {
  constexpr std::string_view kText = "this server asks for a user name and password\n";
  MHD_Response* response = MHD_create_response_from_buffer(
      kText.size(), const_cast<char*>(kText.data()), MHD_RESPMEM_PERSISTENT);
  if (response == nullptr) return MHD_NO;
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, "text/plain; charset=utf-8");
  MHD_add_response_header(response, "X-Content-Type-Options", "nosniff");
  const MHD_Result result = MHD_queue_basic_auth_fail_response(connection, "surroundd", response);
  MHD_destroy_response(response);
  return result;
}

}  // namespace surroundd::render

#pragma once
// The HTTP transport under render/'s HTTP outputs, on libmicrohttpd: listens on an IPv4 address,
// one thread per connection, at most kMaxHttpConnections at a time and
// kMaxHttpConnectionsPerAddress from one address, idle ones closed after 15 s and ones that have
// not sent their whole request head within the header timeout (kHeaderTimeout unless told) cut
// off, and those still sending their heads hold at most half the places (the slowest cut off
// first), so slow-header clients, from however many addresses, cannot hold every place. It refuses
// a URL over 4 KiB (414), a body over 1 KiB (413), a Host that is neither an IP address,
// "localhost" nor one of the allowed host names (421: a web page cannot reach the server through
// DNS rebinding; no Host at all is an HTTP/1.0 client, not a browser), and a request other than GET
// or HEAD from another origin (403: no cross-site requests), and, where it has credentials, a
// request without their user and password (401, HTTP basic authentication); every answer says
// "X-Content-Type-Options: nosniff". Every other request, once its body is in (and dropped), goes
// to the handler on that connection's thread.
//
// Error policy: the constructor throws std::runtime_error naming the address and port ("HTTP
// stream: cannot listen on 127.0.0.1:8080: Address already in use"). The handler must not throw
// (it runs on libmicrohttpd's threads): it answers with reply() or queue(), or returns MHD_NO to
// close the connection.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <microhttpd.h>

#include "render/outputs/credentials.hpp"

namespace surroundd::render {

inline constexpr unsigned kMaxHttpConnections = 16;
inline constexpr unsigned kMaxHttpConnectionsPerAddress = 8;
// Connections still sending their request head hold at most half the places: a new one past that
// cuts off the one that has been sending its head longest. Slow-header clients from two addresses
// (8 + 8) otherwise held every place, and the page was refused for as long as they went on.
inline constexpr unsigned kMaxConnectionsSendingHeads = kMaxHttpConnections / 2;
inline constexpr std::chrono::milliseconds kHeaderTimeout{10'000};

// Whether a request's Host header names this server: an IPv4 or [IPv6] address, "localhost", or
// one of `allowedHosts` (names, with or without ":port"), any port. Case does not matter.
bool isAllowedHost(std::string_view host, const std::vector<std::string>& allowedHosts);
// Whether a request's Origin ("http://name:port") is the server it was sent to, as its Host header
// names it. Case does not matter.
bool isSameOrigin(std::string_view origin, std::string_view host);

class HttpServer {
 public:
  using Handler =
      std::function<MHD_Result(MHD_Connection*, std::string_view path, std::string_view method)>;

  // `name` starts messages ("HTTP stream"); `port` 0 picks a free one (see port()).
  HttpServer(std::string name, const std::string& address, int port,
             std::vector<std::string> allowedHosts, std::chrono::milliseconds headerTimeout,
             std::optional<Credentials> credentials, Handler handler);
  ~HttpServer();  // stop()
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Closes the connections and joins their threads: wake any handler that waits first. Idempotent.
  void stop();
  int port() const { return port_; }

 private:
  static MHD_Result onRequest(void* cls, MHD_Connection* connection, const char* url,
                              const char* method, const char* version, const char* uploadData,
                              size_t* uploadDataSize, void** requestState);
  static void onCompleted(void* cls, MHD_Connection* connection, void** requestState,
                          MHD_RequestTerminationCode reason);
  static void onConnection(void* cls, MHD_Connection* connection, void** socketContext,
                           MHD_ConnectionNotificationCode code);
  void cutOffSlowHeaders();
  bool authorized(MHD_Connection* connection) const;  // the request carries credentials_

  std::string name_;
  std::vector<std::string> allowedHosts_;
  std::chrono::milliseconds headerTimeout_;
  std::optional<Credentials> credentials_;
  Handler handler_;
  int port_ = 0;

  // Every open connection: its socket, and since when it has been sending a request head (none
  // while a request is being answered). Guarded by headMutex_: libmicrohttpd's threads update it,
  // the reaper cuts off heads older than kHeaderTimeout.
  struct OpenConnection {
    int fd = -1;
    std::optional<std::chrono::steady_clock::time_point> headSince;
  };
  void markHead(MHD_Connection* connection, bool sending);
  // Under headMutex_: past kMaxConnectionsSendingHeads, cuts off the connections that have been
  // sending their heads longest.
  void cutOffSlowestHeads();
  std::mutex headMutex_;
  std::condition_variable reaperWake_;
  std::map<MHD_Connection*, OpenConnection> connections_;
  bool stopping_ = false;
  std::thread reaper_;

  MHD_Daemon* daemon_ = nullptr;
};

// Queues `response` (nullptr: MHD_NO) with Content-Type and "Cache-Control: no-store", and
// releases it.
MHD_Result queue(MHD_Connection* connection, unsigned status, MHD_Response* response,
                 const char* contentType);
// A copy of `text` as the body.
MHD_Result reply(MHD_Connection* connection, unsigned status, std::string_view text,
                 const char* contentType = "text/plain; charset=utf-8");
// 405 with an Allow header.
MHD_Result replyNotAllowed(MHD_Connection* connection, const char* allowed);
// 401 asking for HTTP basic authentication (realm "surroundd").
MHD_Result askForCredentials(MHD_Connection* connection);

}  // namespace surroundd::render

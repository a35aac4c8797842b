#pragma once
// The HTTP transport under render/'s HTTP outputs, on libmicrohttpd: listens on an IPv4 address,
// one thread per connection, at most kMaxConnections at a time, idle ones closed after 15 s. It
// refuses a URL over 4 KiB (414) and a body over 1 KiB (413) itself, and hands every other request,
// once its body is in (and dropped), to the handler on that connection's thread.
//
// Error policy: the constructor throws std::runtime_error naming the address and port ("HTTP
// stream: cannot listen on 127.0.0.1:8080: Address already in use"). The handler must not throw
// (it runs on libmicrohttpd's threads): it answers with reply() or queue(), or returns MHD_NO to
// close the connection.

#include <functional>
#include <string>
#include <string_view>

#include <microhttpd.h>

namespace surroundd::render {

inline constexpr unsigned kMaxHttpConnections = 16;

class HttpServer {
 public:
  using Handler =
      std::function<MHD_Result(MHD_Connection*, std::string_view path, std::string_view method)>;

  // `name` starts messages ("HTTP stream"); `port` 0 picks a free one (see port()).
  HttpServer(std::string name, const std::string& address, int port, Handler handler);
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

  std::string name_;
  Handler handler_;
  int port_ = 0;
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

}  // namespace surroundd::render

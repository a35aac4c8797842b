#include "daemon/outputs/server_settings.hpp"

#include <charconv>

#include <arpa/inet.h>
#include <fmt/format.h>

namespace surroundd::daemon {

// "ADDRESS:PORT" of an IPv4 address; port 0 picks a free one.
void readListen(YamlObject& item, ServerSettings& server) {
  const std::string listen =
      item.string("listen", fmt::format("{}:{}", server.address, server.port));
  const auto colon = listen.rfind(':');
  int port = -1;
  if (colon != std::string::npos) {
    const std::string_view digits = std::string_view(listen).substr(colon + 1);
    const auto [end, failed] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
    if (failed != std::errc() || end != digits.data() + digits.size()) port = -1;
  }
  in_addr address{};
  if (colon == std::string::npos || port < 0 || port > 65535 ||
      inet_pton(AF_INET, listen.substr(0, colon).c_str(), &address) != 1) {
    item.error("listen",
               fmt::format("expected IPv4-ADDRESS:PORT (e.g. 127.0.0.1:8080), got '{}'", listen));
    return;
  }
  server.address = listen.substr(0, colon);
  server.port = port;
}

void readPasswordFile(YamlObject& item, ServerSettings& server) {
  if (!item.has("password_file")) return;
  const auto file = item.existingFile("password_file");
  if (!file) return;
  try {
    server.credentials = render::readCredentialsFile(*file);
  } catch (const std::runtime_error& error) {
    item.error("password_file", error.what());
  }
}

void requireCredentialsBeyondThisMachine(YamlObject& item, const ServerSettings& server) {
  // A password_file given but refused has said so already.
  if (server.credentials || item.has("password_file") ||
      render::isLoopbackAddress(server.address)) {
    return;
  }
  item.error("listen",
             fmt::format("listens on {}, beyond this machine, and no password_file says who may "
                         "watch: anyone on the vehicle's networks would see its cameras; give a "
                         "password_file (USER:PASSWORD, chmod 600), or listen on 127.0.0.1",
                         server.address));
}

std::optional<OutputConflict> sharesPort(const ServerSettings& earlier,
                                         const ServerSettings& server) {
  const bool sameAddress = earlier.address == server.address || earlier.address == "0.0.0.0" ||
                           server.address == "0.0.0.0";
  if (server.port == 0 || server.port != earlier.port || !sameAddress) return std::nullopt;
  return OutputConflict{"listen", fmt::format("listens on port {} already", server.port)};
}

}  // namespace surroundd::daemon

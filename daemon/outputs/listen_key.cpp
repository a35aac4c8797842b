// The `listen` and `password_file` keys of the output types that serve (http, rtsp), the rule that
// two of them cannot listen on one port, and the one that a server reachable beyond this machine
// asks who is watching.
#include <charconv>

#include <arpa/inet.h>
#include <fmt/format.h>

#include "daemon/outputs/built_in_outputs.hpp"
#include "render/outputs/credentials.hpp"

namespace surroundd::daemon {
namespace {

// "ADDRESS:PORT" of an IPv4 address; port 0 picks a free one.
void readListen(YamlObject& item, OutputConfig& o, int defaultPort) {
  const std::string listen =
      item.string("listen", fmt::format("{}:{}", o.listenAddress, defaultPort));
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
  o.listenAddress = listen.substr(0, colon);
  o.listenPort = port;
}

bool sameListen(const OutputConfig& a, const OutputConfig& b) {
  return a.listenAddress == b.listenAddress && a.listenPort == b.listenPort;
}

}  // namespace

ConfigKey<OutputConfig> listenKey(int defaultPort) {
  return ConfigKey<OutputConfig>::custom(
      "listen", "the address and port it listens on",
      [defaultPort](YamlObject& item, OutputConfig& o) { readListen(item, o, defaultPort); },
      sameListen, {}, defaultPort == OutputConfig{}.listenPort ? Shown::kDefault : Shown::kExample);
}

ConfigKey<OutputConfig> passwordFileKey() {
  return ConfigKey<OutputConfig>::custom(
      "password_file", "who may watch: a file with USER:PASSWORD on its first line (chmod 600)",
      [](YamlObject& item, OutputConfig& o) {
        if (!item.has("password_file")) return;
        const auto file = item.existingFile("password_file");
        if (!file) return;
        try {
          o.credentials = render::readCredentialsFile(*file);
        } catch (const std::runtime_error& error) {
          item.error("password_file", error.what());
        }
      },
      [](const OutputConfig& a, const OutputConfig& b) { return a.credentials == b.credentials; },
      {}, Shown::kExample);
}

void requireCredentialsBeyondThisMachine(YamlObject& item, const OutputConfig& o) {
  // A password_file given but refused has said so already.
  if (o.credentials || item.has("password_file") || render::isLoopbackAddress(o.listenAddress)) {
    return;
  }
  item.error("listen",
             fmt::format("listens on {}, beyond this machine, and no password_file says who may "
                         "watch: anyone on the vehicle's networks would see its cameras; give a "
                         "password_file (USER:PASSWORD, chmod 600), or listen on 127.0.0.1",
                         o.listenAddress));
}

// Two servers cannot listen on one port of one address (0.0.0.0 is every address).
std::optional<OutputConflict> sharesPort(const OutputConfig& earlier, const OutputConfig& output) {
  const bool sameAddress = earlier.listenAddress == output.listenAddress ||
                           earlier.listenAddress == "0.0.0.0" || output.listenAddress == "0.0.0.0";
  if (output.listenPort == 0 || output.listenPort != earlier.listenPort || !sameAddress) {
    return std::nullopt;
  }
  return OutputConflict{"listen", fmt::format("listens on port {} already", output.listenPort)};
}

}  // namespace surroundd::daemon

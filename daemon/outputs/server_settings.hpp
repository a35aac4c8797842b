#pragma once
// Where an output type that serves (http, rtsp) listens and who may watch it: the `listen` and
// `password_file` keys, the rule that two of a type cannot listen on one port, and the one that a
// server reachable beyond this machine asks who is watching. A type's settings hold them as
// `server`.

#include <optional>
#include <string>

#include "daemon/config/config_keys.hpp"
#include "daemon/config/output_type.hpp"
#include "render/outputs/credentials.hpp"

namespace surroundd::daemon {

struct ServerSettings {
  std::string address = "127.0.0.1";               // only this machine, unless configured otherwise
  int port = 8080;                                 // 0: a free one
  std::optional<render::Credentials> credentials;  // who may watch; required beyond loopback

  bool operator==(const ServerSettings&) const = default;
};

// `listen: ADDRESS:PORT` into `server` (the settings' default where absent).
void readListen(YamlObject& item, ServerSettings& server);
void readPasswordFile(YamlObject& item, ServerSettings& server);

template <class Settings>
ConfigKey<Settings> listenKey() {
  return ConfigKey<Settings>::custom(
      "listen", "the address and port it listens on",
      [](YamlObject& item, Settings& s) { readListen(item, s.server); },
      [](const Settings& a, const Settings& b) {
        return a.server.address == b.server.address && a.server.port == b.server.port;
      });
}

template <class Settings>
ConfigKey<Settings> passwordFileKey() {
  return ConfigKey<Settings>::custom(
      "password_file", "who may watch: a file with USER:PASSWORD on its first line (chmod 600)",
      [](YamlObject& item, Settings& s) { readPasswordFile(item, s.server); },
      [](const Settings& a, const Settings& b) {
        return a.server.credentials == b.server.credentials;
      },
      {}, Shown::kExample);
}

// A server listening beyond 127.0.0.0/8 must say who may watch (an error on `listen` otherwise).
void requireCredentialsBeyondThisMachine(YamlObject& item, const ServerSettings& server);
// Two servers cannot listen on one port of one address (0.0.0.0 is every address).
std::optional<OutputConflict> sharesPort(const ServerSettings& earlier,
                                         const ServerSettings& server);

}  // namespace surroundd::daemon

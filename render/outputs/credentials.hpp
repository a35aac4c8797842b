#pragma once
// Who may watch a served output (HTTP, RTSP) that listens beyond this machine: one user name and
// password, kept in a file of their own (USER:PASSWORD on its first line, readable by its owner
// only), so that the config can be shown around and the secret cannot.

#include <filesystem>
#include <string>
#include <string_view>

namespace surroundd::render {

struct Credentials {
  std::string user;
  std::string password;
  bool operator==(const Credentials&) const = default;
};

// Reads `file`. Throws std::runtime_error naming it: missing or unreadable, readable or writable by
// others than its owner (chmod 600 it), or without USER:PASSWORD (a name without ':' and a password
// of at least 8 characters) on its first line.
Credentials readCredentialsFile(const std::filesystem::path& file);

// Whether `given` is the user and password of `expected`, compared in a time that does not depend
// on where they first differ.
bool credentialsMatch(const Credentials& expected, std::string_view user,
                      std::string_view password);

// Whether an IPv4 listen address is this machine's loopback (127.0.0.0/8): a server listening
// anywhere else is reachable from the vehicle's networks.
bool isLoopbackAddress(std::string_view address);

}  // namespace surroundd::render

#include "render/outputs/credentials.hpp"

#include <stdexcept>

#include <arpa/inet.h>
#include <fmt/format.h>
#include <sys/stat.h>

#include "common/regular_file.hpp"

namespace surroundd::render {
namespace {

constexpr std::size_t kMaxCredentialsBytes = 4096;
constexpr std::size_t kShortestPassword = 8;

// The time depends on `expected`'s length only: every byte of it is looked at.
bool sameBytes(std::string_view expected, std::string_view given) {
  std::size_t differ = expected.size() ^ given.size();
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto other = static_cast<unsigned char>(i < given.size() ? given[i] : 0);
    differ |= static_cast<unsigned char>(expected[i]) ^ other;
  }
  return differ == 0;
}

}  // namespace

Credentials readCredentialsFile(const std::filesystem::path& file) {
  struct stat status {};
  if (::stat(file.c_str(), &status) == 0 && (status.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    throw std::runtime_error(
        fmt::format("{}: others than its owner may read or change it (mode {:o}): chmod 600 it",
                    file.string(), status.st_mode & 0777));
  }
  std::string text;
  try {
    text = readRegularFile(file, kMaxCredentialsBytes);
  } catch (const FileReadError& error) {
    throw std::runtime_error(error.what());
  }
  const std::string line = text.substr(0, text.find('\n'));
  const auto colon = line.find(':');
  const std::string password =
      colon == std::string::npos ? "" : line.substr(colon + 1, line.find_last_not_of('\r') - colon);
  if (colon == std::string::npos || colon == 0 || password.size() < kShortestPassword) {
    throw std::runtime_error(fmt::format(
        "{}: expected USER:PASSWORD on its first line, the password at least {} characters",
        file.string(), kShortestPassword));
  }
  return {line.substr(0, colon), password};
}

bool credentialsMatch(const Credentials& expected, std::string_view user,
                      std::string_view password) {
  // Both compared whatever the first gives: no early return tells which one was wrong.
  const bool userMatches = sameBytes(expected.user, user);
  const bool passwordMatches = sameBytes(expected.password, password);
  return userMatches && passwordMatches;
}

bool isLoopbackAddress(std::string_view address) {
  in_addr parsed{};
  if (inet_pton(AF_INET, std::string(address).c_str(), &parsed) != 1) return false;
  return (ntohl(parsed.s_addr) >> 24) == 127;
}

}  // namespace surroundd::render

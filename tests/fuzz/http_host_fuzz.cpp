// The HTTP server's own checks of a request's headers, as pure functions: the Host allow-list (DNS
// rebinding) and the same-origin test (cross-site POSTs). Input: "host\norigin\nallowed...".
// What they promise, checked on every input: with no allow-list only "localhost" and IP literals
// pass (a name a rebinding page could use never does); adding names never refuses a host that
// passed; case never matters; a page of the server's own origin is always same-origin.

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "render/outputs/http_server.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {

std::string upper(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// The host's name (before ":port"; an IPv6 address in brackets keeps its colons) is "localhost" or
// spelled with what an IPv4 or IPv6 literal can hold.
bool isLocalhostOrAddress(std::string_view host) {
  const std::size_t nameEnd = host.starts_with('[') ? host.find(']') + 1 : host.rfind(':');
  const std::string_view name = host.substr(0, nameEnd);
  if (upper(name) == "LOCALHOST") return true;
  constexpr std::string_view kAddressCharacters = "0123456789abcdefABCDEF.:[]";
  return !name.empty() && name.find_first_not_of(kAddressCharacters) == std::string_view::npos;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view rest = surroundd::fuzz::asText(data, size);
  const auto line = [&rest] {
    const auto end = rest.find('\n');
    const std::string_view taken = rest.substr(0, end);
    rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
    return taken;
  };
  const std::string_view host = line();
  const std::string_view origin = line();
  std::vector<std::string> allowedNames;
  while (!rest.empty()) allowedNames.emplace_back(line());
  using surroundd::render::isAllowedHost;
  using surroundd::render::isSameOrigin;
  const bool allowed = isAllowedHost(host, allowedNames);
  FUZZ_CHECK(!isAllowedHost(host, {}) || (allowed && isLocalhostOrAddress(host)));
  FUZZ_CHECK(isAllowedHost(upper(host), allowedNames) == allowed);
  FUZZ_CHECK(isSameOrigin(origin, host) == isSameOrigin(upper(origin), host));
  FUZZ_CHECK(isSameOrigin("http://" + std::string(host), host));
  return 0;
}

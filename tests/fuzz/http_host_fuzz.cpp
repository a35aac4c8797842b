// The HTTP server's own checks of a request's headers, as pure functions: the Host allow-list (DNS
// rebinding) and the same-origin test (cross-site POSTs). Input: "host\norigin\nallowed...".

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "render/http_server.hpp"
#include "tests/fuzz/fuzz_support.hpp"

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
  std::vector<std::string> allowed;
  while (!rest.empty()) allowed.emplace_back(line());
  (void)surroundd::render::isAllowedHost(host, allowed);
  (void)surroundd::render::isSameOrigin(origin, host);
  return 0;
}

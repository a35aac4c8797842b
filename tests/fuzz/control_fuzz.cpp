// The control socket's request parser on any line (it never throws), and the reply encoder on what
// it gives: a good request is one of the kinds with its argument, a bad one has a message.

#include <cstddef>
#include <cstdint>

#include "daemon/control/control_protocol.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using surroundd::daemon::ControlReply;
  using surroundd::daemon::ControlRequest;
  const auto parsed = surroundd::daemon::parseControlRequest(surroundd::fuzz::asText(data, size));
  // A view request names its view.
  FUZZ_CHECK(!parsed.error.empty() || parsed.request.kind != ControlRequest::Kind::kView ||
             !parsed.request.argument.empty());
  const auto reply = parsed.error.empty() ? ControlReply::success(parsed.request.argument)
                                          : ControlReply::failure(parsed.error);
  (void)surroundd::daemon::encodeReply(reply);
  return 0;
}

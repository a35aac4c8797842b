#pragma once
// The live page that HttpStreamSink serves at "/": one self-contained HTML file (no external
// resources). Elements tests rely on: #live (the stream), #status (data-state "waiting", "ok" or
// "error"; data-updates counts refreshes), #fps, #frames, #cameras, #views with one #view-NAME
// button per view (class "active" on the shown one), #view-error.

#include <string_view>

namespace surroundd::render {

std::string_view livePage();

}  // namespace surroundd::render

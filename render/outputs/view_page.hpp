#pragma once
// A page a viewer acts on while the pipeline runs: it asks for a view and shows the pipeline's
// status (the HTTP output's live page). An output that has one offers it through
// FrameSink::page(); the pipeline asks every output, so it needs to know no kind of output.
//
// Threads: called from the pipeline thread while the output's own threads (its queue, its server)
// run; an implementation keeps these calls safe for that.

#include <optional>
#include <string>

namespace surroundd::render {

class ViewPage {
 public:
  virtual ~ViewPage() = default;
  ViewPage() = default;
  ViewPage(const ViewPage&) = delete;
  ViewPage& operator=(const ViewPage&) = delete;

  // The view a viewer asked for since the last call, once; nullopt if none.
  virtual std::optional<std::string> takeViewRequest() = 0;
  // The view shown now, when it was switched another way (surroundctl): the page marks it.
  virtual void setActiveView(std::string name) = 0;
  // The pipeline's status as a JSON object (statusJson()), about once a second.
  virtual void setStatus(std::string json) = 0;
};

}  // namespace surroundd::render

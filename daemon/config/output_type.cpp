#include "daemon/config/output_type.hpp"

#include <algorithm>
#include <deque>
#include <stdexcept>

#include <fmt/format.h>

#include "render/outputs/queued_sink.hpp"

namespace surroundd::daemon {
namespace {

// A deque: a registered type (and the name an OutputKind views) never moves.
using Registry = std::deque<OutputType>;

void add(Registry& registry, OutputType type) {
  if (std::ranges::any_of(registry, [&](const OutputType& t) { return t.name == type.name; })) {
    throw std::logic_error(fmt::format("output type '{}' is registered twice", type.name));
  }
  const bool opens = type.input == OutputInput::kPicture ? bool(type.openPictureSink)
                                                         : bool(type.openCameraFramesSink);
  if (type.leftOut.empty() && (!opens || !type.readSettings)) {
    throw std::logic_error(
        fmt::format("output type '{}' has no schema or no factory for its input", type.name));
  }
  registry.push_back(std::move(type));
}

ConfigKeys<OutputConfig> pathKeys(const OutputType& type) {
  if (type.pathDoc.empty()) return {};
  return {ConfigKey<OutputConfig>::requiredPath("path", &OutputConfig::path, type.pathDoc)};
}

Registry& registry() {
  static Registry types;
  return types;
}

}  // namespace

void registerOutputType(OutputType type) { add(registry(), std::move(type)); }

std::vector<KeyDoc> ownKeyDocs(const OutputType& type) {
  std::vector<KeyDoc> docs = pathKeys(type).docs();
  docs.insert(docs.end(), type.keyDocs.begin(), type.keyDocs.end());
  return docs;
}

void readOutputPath(YamlObject& item, const OutputType& type, OutputConfig& output) {
  pathKeys(type).read(item, output);
}

const OutputType* findOutputType(std::string_view name) {
  const auto& types = registry();
  const auto found = std::ranges::find(types, name, &OutputType::name);
  return found == types.end() ? nullptr : &*found;
}

const OutputType& outputTypeOf(const OutputConfig& output) {
  const OutputType* type = findOutputType(output.kind.name());
  if (type == nullptr) {
    throw std::logic_error(fmt::format("output type '{}' is not registered", output.kind.name()));
  }
  return *type;
}

std::vector<std::string_view> outputTypeNames() {
  std::vector<std::string_view> names;
  for (const OutputType& type : registry()) names.emplace_back(type.name);
  return names;
}

std::unique_ptr<render::FrameSink> queuedSink(std::unique_ptr<render::FrameSink> sink,
                                              const OutputContext& context, std::size_t depth) {
  return std::make_unique<render::QueuedSink>(std::move(sink), context.pictureSize, depth,
                                              context.latestWins
                                                  ? render::QueuedSink::WhenFull::kDropOldest
                                                  : render::QueuedSink::WhenFull::kWait);
}

}  // namespace surroundd::daemon

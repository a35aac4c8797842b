// An output type added through the factory alone: registered from this test (its schema, its
// factory, what it takes), named in a config, read with its own keys, and run through the pipeline
// on a generated recording behind the same queue as surroundd's own outputs. No other file knows
// it.

#include "daemon/config/output_type.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "tests/daemon/config/config_test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

// The type's own settings, with their default and range in its schema below.
struct TallySettings {
  int every = 1;  // keeps every this many pictures; 1..100

  bool operator==(const TallySettings&) const = default;
};

// What the sinks of the type saw, for the test to read after the run.
struct Tally {
  std::mutex mutex;
  std::vector<cv::Size> sizes;  // of each picture kept
  std::vector<std::chrono::nanoseconds> times;
  int finishes = 0;
  bool lastFrameGiven = false;
  int opened = 0;
};
Tally& tally() {
  static Tally seen;
  return seen;
}

class TallySink final : public render::FrameSink {
 public:
  explicit TallySink(TallySettings settings) : settings_(settings) {}

  void consume(const cv::Mat& bgr, const render::PictureTime& time) override {
    if (count_++ % settings_.every != 0) return;
    const std::lock_guard lock(tally().mutex);
    tally().sizes.push_back(bgr.size());
    tally().times.push_back(time.stream);
  }
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds /*lastTime*/) override {
    const std::lock_guard lock(tally().mutex);
    ++tally().finishes;
    tally().lastFrameGiven = !lastFrame.empty();
  }
  std::string describe() const override { return fmt::format("tally of {} pictures", count_); }

 private:
  TallySettings settings_;
  int count_ = 0;
};

OutputType tallyType() {
  OutputType type;
  type.name = "tally";
  readsSettings<TallySettings>(
      type, {ConfigKey<TallySettings>::integer("every", &TallySettings::every, 1, 100,
                                               "every this many pictures is kept")});
  type.openPictureSink = [](const OutputConfig& output, const OutputContext& context) {
    ++tally().opened;
    return queuedSink(std::make_unique<TallySink>(settingsOf<TallySettings>(output)), context, 2);
  };
  return type;
}

// A type this build "leaves out", as CMake's options do for X11, DRM and HTTP.
OutputType hologramType() {
  OutputType type;
  type.name = "hologram";
  type.leftOut = "configure with -DSURROUNDD_WITH_HOLOGRAM=ON (needs libhologram-dev)";
  return type;
}

// Registers both types once, from whichever test comes first.
bool registered() {
  static const bool kDone = [] {
    registerOutputType(tallyType());
    registerOutputType(hologramType());
    return true;
  }();
  return kDone;
}

TEST_F(ConfigTest, ATypeRegisteredFromOutsideReadsItsOwnKeys) {
  ASSERT_TRUE(registered());
  const std::string_view snapshot = "{type: snapshot, path: out/mosaic.png, at_s: 0.5}";
  const Config config = loadConfig(configWith(snapshot, "{type: tally, every: 3}"));
  ASSERT_EQ(config.outputs.size(), 2u);
  EXPECT_EQ(config.outputs[1].kind, OutputKind{"tally"});
  ASSERT_NE(config.outputs[1].settings.get<TallySettings>(), nullptr);
  EXPECT_EQ(config.outputs[1].settings.get<TallySettings>()->every, 3);
  EXPECT_EQ(config.outputs[0].settings.get<TallySettings>(), nullptr);  // a snapshot's are not
  EXPECT_THROW(settingsOf<TallySettings>(config.outputs[0]), std::logic_error);
  EXPECT_EQ(loadConfig(configWith(snapshot, "{type: tally}")).outputs[1].settings,
            OutputSettings(TallySettings{}));

  expectOneError(snapshot, "{type: tally, every: 0}",
                 {"outputs[1].every: expected a whole number in [1, 100]"});
  expectOneError(snapshot, "{type: tally, evry: 2}", {"outputs[1].evry: unknown key"});
  // Its keys are its own: another type does not take them.
  expectOneError(snapshot, "{type: snapshot, path: out/b.png, every: 2}",
                 {"outputs[1].every: unknown key"});
  // And the config's messages list it among the types.
  expectOneError(snapshot, "{path: out/b.mp4}", {"missing key 'type'", "'recording' 'tally'"});
}

TEST_F(ConfigTest, ATypeLeftOutOfTheBuildIsRefusedSayingHowToBuildItIn) {
  ASSERT_TRUE(registered());
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: hologram, stream: surround, depth_m: 3}",
                 {"outputs[1].type: this surroundd is built without 'hologram' outputs: "
                  "configure with -DSURROUNDD_WITH_HOLOGRAM=ON (needs libhologram-dev)"});
}

TEST(OutputType, ANameIsRegisteredOnce) {
  ASSERT_TRUE(registered());
  EXPECT_THROW(registerOutputType(tallyType()), std::logic_error);
  OutputType noFactory;
  noFactory.name = "nothing";
  noFactory.readSettings = [](YamlObject&, const OutputConfig&) { return OutputSettings(); };
  EXPECT_THROW(registerOutputType(noFactory), std::logic_error);
  EXPECT_EQ(findOutputType("nothing"), nullptr);
}

TEST(OutputType, ARegisteredTypeRunsThroughThePipeline) {
  ASSERT_TRUE(registered());
  const testing::TempDir dir;
  const auto rig = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small" / "rig.yaml";
  const Config config = loadConfig(dir.write("tally.yaml", fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: as_fast_as_possible}}
render: {{width_px: 320, height_px: 180}}
outputs:
  - {{type: tally, stream: mosaic, every: 2}}
)",
                                                                       rig.string())));
  Pipeline pipeline(config);
  const std::atomic<bool> stop{false};
  const RunSummary summary = pipeline.run(stop);

  ASSERT_GT(summary.frameSets, 2u);
  EXPECT_EQ(summary.failedOutputs, 0u);
  EXPECT_EQ(tally().opened, 1);
  const std::lock_guard lock(tally().mutex);
  // Every set's picture reached it in order (a replay waits for its outputs), every second kept.
  EXPECT_EQ(tally().sizes.size(), (summary.frameSets + 1) / 2);
  EXPECT_THAT(tally().sizes, ::testing::Each(cv::Size(320, 180)));
  EXPECT_TRUE(std::ranges::is_sorted(tally().times));
  EXPECT_EQ(tally().finishes, 1);
  EXPECT_TRUE(tally().lastFrameGiven);
  EXPECT_THAT(summary.outputs,
              ::testing::ElementsAre(fmt::format("tally of {} pictures", summary.frameSets)));
}

}  // namespace
}  // namespace surroundd::daemon

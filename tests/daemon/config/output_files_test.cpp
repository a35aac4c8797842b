// No run destroys another's data (issue 18): two outputs of one config that would write the same
// file are refused at load, and a run that finds an earlier run's file, .part or recording
// writes the next name instead. Retention (issue 50): a video's keep_last and max_mb remove its
// oldest files, over restarts and segments alike.

#include "daemon/config/output_files.hpp"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "daemon/config/rig_yaml.hpp"
#include "daemon/pipeline.hpp"
#include "render/outputs/numbered_files.hpp"
#include "tests/daemon/config/config_test_support.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

TEST_F(ConfigTest, OutputsThatWouldWriteOneFileAreRefused) {
  std::filesystem::create_directories(dir_ / "out");
  std::filesystem::create_directory_symlink(dir_ / "out", dir_ / "link");
  const std::string_view snapshot = "{type: snapshot, path: out/mosaic.png, at_s: 0.5}";
  // outputs[0] is the video out/mosaic.mp4.
  expectOneError(snapshot, "{type: video, path: link/mosaic.mp4}",
                 {"outputs[1].path: two outputs write", "(as '", "(outputs[0] too)"});
  const std::string_view both =
      "  - {type: video, path: out/mosaic.mp4, crf: 18}\n"
      "  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}";
  expectOneError(both,
                 "  - {type: video, path: out/mosaic.mp4, segment_s: 2}\n"
                 "  - {type: video, path: out/mosaic-00001.mp4}",
                 {"outputs[1].path: '",
                  "out/mosaic-00001.mp4' would be named like the segments "
                  "of '",
                  "out/mosaic.mp4' (outputs[0] too)"});
  // Through the symlink, and a plain video's later runs would be mosaic-1.mp4, ...
  expectOneError(both,
                 "  - {type: video, path: out/mosaic.mp4, segment_s: 2}\n"
                 "  - {type: video, path: link/mosaic.mp4}",
                 {"outputs[1].path: two outputs write"});
}

TEST_F(ConfigTest, AVideoInsideARecordingAndTwoHttpOutputsOnOnePortAreRefused) {
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: recording, path: out}",
                 {"outputs[1].path: '", "out/mosaic.mp4' is inside the recording folder '"});
  dir_.write("viewers.pw", "driver:correct horse battery\n");
  std::filesystem::permissions(dir_ / "viewers.pw", std::filesystem::perms::owner_read |
                                                        std::filesystem::perms::owner_write);
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: http, listen: \"127.0.0.1:8081\"}\n"
                 "  - {type: http, listen: \"0.0.0.0:8081\", password_file: viewers.pw}",
                 {"outputs[2].listen: outputs[1] listens on port 8081 already"});
  const std::string socket(120, 's');
  std::string text(kGoodConfig);
  text += "control: {socket: /tmp/" + socket + "}\n";
  const auto messages = errorsOf(dir_.write("config.yaml", text));
  ASSERT_EQ(messages.size(), 1u) << ::testing::PrintToString(messages);
  EXPECT_THAT(messages[0], HasSubstr("control.socket: expected a path of at most 107 bytes"));
}

TEST_F(ConfigTest, TwoRtspOutputsOnOnePortAreRefused) {
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: rtsp, stream: surround}\n"
                 "  - {type: rtsp, stream: mosaic, listen: \"127.0.0.1:8554\"}",
                 {"outputs[2].listen: outputs[1] listens on port 8554 already"});
}

TEST(OutputFiles, AnEarlierRunsFilesAreKeptAndTheNextFreeNameTaken) {
  const testing::TempDir dir;
  OutputConfig video;
  video.path = dir / "whole.mkv";
  EXPECT_EQ(unusedOutputPath(video), dir / "whole.mkv");
  dir.write("whole.mkv.part", "frames of a killed run");
  EXPECT_EQ(unusedOutputPath(video), dir / "whole-1.mkv");
  dir.write("whole-1.mkv", "a finished run");
  EXPECT_EQ(unusedOutputPath(video), dir / "whole-2.mkv");
  // A FIFO is no data (a test stalls a writer with one): it is written into.
  ASSERT_EQ(::mkfifo((dir / "whole-2.mkv.part").c_str(), 0600), 0);
  EXPECT_EQ(unusedOutputPath(video), dir / "whole-2.mkv");
  // After the highest number, not into a gap a retention left: numbers follow the runs' order.
  dir.write("whole-7.mkv", "a later run");
  EXPECT_EQ(unusedOutputPath(video), dir / "whole-8.mkv");

  OutputConfig recording;
  recording.kind = OutputKind::kRecording;
  recording.path = dir / "drive";
  std::filesystem::create_directory(dir / "drive");
  EXPECT_EQ(unusedOutputPath(recording), dir / "drive");  // empty: nothing to keep
  dir.write("drive/front.mp4", "x");
  EXPECT_EQ(unusedOutputPath(recording), dir / "drive-1");

  OutputConfig snapshot;
  snapshot.kind = OutputKind::kSnapshot;
  snapshot.path = dir / "whole.mkv";  // the newest picture replaces the last
  EXPECT_EQ(unusedOutputPath(snapshot), dir / "whole.mkv");
}

TEST(OutputFiles, AFolderThatCannotBeMadeNamesItsOutput) {
  const testing::TempDir dir;
  dir.write("file", "x");
  EXPECT_THAT([&] { createOutputFolder(dir / "file" / "out", dir / "file/out/top.png"); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  HasSubstr("output " + (dir / "file/out/top.png").string() +
                            ": cannot create the folder " + (dir / "file/out").string() + ": ")));
}

// Three runs of one config, the first killed before it finished (its .part left behind): nothing
// any run wrote is lost, truncated or overwritten.
TEST(OutputFiles, RestartsKeepEveryRunsVideo) {
  const testing::TempDir dir;
  const Config config = fixtureReplay("synth_small", {videoOutputAt(dir / "whole.mkv")});
  const std::string killed = "the frames of a run that was killed";
  dir.write("whole.mkv.part", killed);
  const std::atomic<bool> stop{false};
  for (int run = 0; run < 2; ++run) {
    Pipeline pipeline(config);
    EXPECT_EQ(pipeline.run(stop).failedOutputs, 0u);
  }
  EXPECT_EQ(surroundd::testing::fileBytes(dir / "whole.mkv.part"), killed);
  const auto first = surroundd::testing::decodeAll(dir / "whole-1.mkv");
  const auto second = surroundd::testing::decodeAll(dir / "whole-2.mkv");
  EXPECT_GT(first.images.size(), 5u);
  EXPECT_EQ(second.images.size(), first.images.size());
  EXPECT_FALSE(std::filesystem::exists(dir / "whole.mkv"));
}

TEST(OutputFiles, RetentionRemovesTheOldestOfTheFamilyNeverTheOneBeingWritten) {
  const testing::TempDir dir;
  for (const char* name : {"drive.mp4", "drive-1.mp4", "drive-2.mp4.part", "drive-10.mp4",
                           "drive-x.mp4", "drive.mkv", "drives-3.mp4"}) {
    dir.write(name, std::string(1000, 'x'));
  }
  const auto family = render::numberedFiles(dir / "drive.mp4");
  std::vector<std::string> names;
  names.reserve(family.size());
  for (const auto& file : family) names.push_back(file.path.filename().string());
  EXPECT_THAT(names, ::testing::ElementsAre("drive.mp4", "drive-1.mp4", "drive-2.mp4.part",
                                            "drive-10.mp4"));
  // Three kept, the one being written (drive-11, not there yet as a finished file) among them.
  dir.write("drive-11.mp4.part", "being written");
  const auto removed = render::retainNewest({dir / "drive.mp4", 3, 0}, dir / "drive-11.mp4");
  EXPECT_EQ(removed.size(), 2U);
  EXPECT_FALSE(std::filesystem::exists(dir / "drive.mp4"));
  EXPECT_FALSE(std::filesystem::exists(dir / "drive-1.mp4"));
  EXPECT_TRUE(std::filesystem::exists(dir / "drive-2.mp4.part"));
  EXPECT_TRUE(std::filesystem::exists(dir / "drive-11.mp4.part"));
  // 1500 bytes together: of the two finished 1000-byte files, only the newer stays.
  EXPECT_EQ(render::retainNewest({dir / "drive.mp4", 0, 1500}, dir / "drive-11.mp4").size(), 1U);
  EXPECT_TRUE(std::filesystem::exists(dir / "drive-10.mp4"));
  // Other names are no part of it.
  for (const char* other : {"drive-x.mp4", "drive.mkv", "drives-3.mp4"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / other)) << other;
  }
}

// Ten runs of a video output with keep_last: 3, and a segmented one with keep_last: 2: what stays
// is the newest, each whole.
TEST(OutputFiles, RestartsAndSegmentsStayWithinTheirRetention) {
  const testing::TempDir dir;
  VideoOutputSettings lastThree;
  lastThree.keepLast = 3;
  VideoOutputSettings lastTwoSegments;
  lastTwoSegments.segmentS = 0.25;
  lastTwoSegments.keepLast = 2;
  const OutputConfig runs = videoOutputAt(dir / "whole.mkv", lastThree);
  const OutputConfig segments = videoOutputAt(dir / "seg.mkv", lastTwoSegments);
  const Config config = fixtureReplay("synth_small", {runs, segments});
  const std::atomic<bool> stop{false};
  for (int run = 0; run < 10; ++run) {
    Pipeline pipeline(config);
    EXPECT_EQ(pipeline.run(stop).failedOutputs, 0u);
  }
  std::vector<std::string> kept;
  for (const auto& file : render::numberedFiles(dir / "whole.mkv")) {
    kept.push_back(file.path.filename().string());
    EXPECT_GT(surroundd::testing::decodeAll(file.path).images.size(), 5u) << file.path;
  }
  EXPECT_THAT(kept, ::testing::ElementsAre("whole-7.mkv", "whole-8.mkv", "whole-9.mkv"));
  const auto segmentFiles = render::numberedFiles(dir / "seg.mkv");
  ASSERT_EQ(segmentFiles.size(), 2U);
  EXPECT_GT(segmentFiles[0].number, 10) << "ten runs of several segments each";
  EXPECT_EQ(segmentFiles[1].number, segmentFiles[0].number + 1);
}

}  // namespace
}  // namespace surroundd::daemon

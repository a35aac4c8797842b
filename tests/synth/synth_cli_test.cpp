// surround-synth as a user runs it: the same seed gives the same bytes, a different seed different
// ones; a second run with the same arguments is a cache hit; bad input exits non-zero with a
// message naming the problem.

#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "processing/lens/camera_model.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/synth/synth_test_support.hpp"
#include "tools/synth/recording_plan.hpp"

namespace surroundd::synth {
namespace {

using ::testing::HasSubstr;

const std::string kPaper = std::string(SURROUNDD_SOURCE_DIR) + "/config/rigs/paper.yaml";

struct SynthRun {
  int status;
  std::string output;
};

SynthRun synth(const surroundd::testing::TempDir& dir, std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), SURROUND_SYNTH);
  surroundd::testing::ChildProcess child(arguments, dir / "log.txt");
  const int status = child.wait();
  return {status, child.output()};
}

std::vector<std::string> smallRun(const std::filesystem::path& out, int seed) {
  return {"--rig",     kPaper, "--out",  out.string(),         "--size",          "128x72",
          "--seconds", "0.3",  "--seed", std::to_string(seed), "--panorama-size", "256x128"};
}

// An OCamCalib lens at another size (columns and rows scaled differently) sees each ray at the
// scaled pixel, and unprojects it (through its image-to-world polynomial) to the same ray.
TEST(ScaleIntrinsics, AnOcamLensSeesTheSameRaysAtAnotherSize) {
  processing::Intrinsics in;
  in.model = processing::LensModel::kOcam;
  in.imageSize = {1280, 960};
  in.cx = 648.6, in.cy = 481.4;
  in.ocam = {1.002,
             0.0015,
             -0.0008,
             {627.9, 466.0, -2.9, 24.2, 72.7, -33.4, -23.5, 114.2},
             {-318.5, 0, 0.0007, -2e-7}};
  in.maxFieldAngleRad = 100 * std::numbers::pi / 180;
  const processing::CameraModel model(in);
  const processing::CameraModel scaled(scaleIntrinsics(in, {640, 360}));
  for (double degrees = 0; degrees <= 100; degrees += 10) {
    const double a = degrees * std::numbers::pi / 180;
    const cv::Vec3d ray(std::sin(a) * 0.6, std::sin(a) * -0.8, std::cos(a));
    const auto pixel = model.project(ray);
    const auto scaledPixel = scaled.project(ray);
    ASSERT_TRUE(pixel && scaledPixel) << degrees;
    EXPECT_NEAR(scaledPixel->x, (pixel->x + 0.5) * 0.5 - 0.5, 1e-9) << degrees;
    EXPECT_NEAR(scaledPixel->y, (pixel->y + 0.5) * 0.375 - 0.5, 1e-9) << degrees;
    EXPECT_LT(cv::norm(*scaled.unproject(*scaledPixel) - *model.unproject(*pixel)), 1e-12);
  }
}

// Every file of a recording but the manifest (which records how long the run took).
std::map<std::string, std::string> contents(const std::filesystem::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().filename() == "manifest.yaml") continue;
    files[std::filesystem::relative(entry.path(), folder).string()] =
        testing::fileBytes(entry.path());
  }
  return files;
}

TEST(SynthCli, SameSeedSameBytesOtherSeedOtherBytes) {
  const surroundd::testing::TempDir dir;
  for (const auto& [name, seed] : {std::pair{"a", 3}, {"b", 3}, {"c", 4}}) {
    const SynthRun run = synth(dir, smallRun(dir / name, seed));
    ASSERT_EQ(run.status, 0) << run.output;
  }
  const auto a = contents(dir / "a"), b = contents(dir / "b"), c = contents(dir / "c");
  EXPECT_EQ(a.size(), 4 + 1 + 1 + 3 * 5u);  // videos, rig, ground truth, 3 frames x 5 images
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [file, bytes] : a) {
    EXPECT_TRUE(b.at(file) == bytes) << file << " differs between two runs with seed 3";
  }
  for (const auto& file : {"front.mkv", "ground_truth/panorama_0.png", "ground_truth.yaml"}) {
    EXPECT_FALSE(c.at(file) == a.at(file)) << file << " is the same for seeds 3 and 4";
  }
}

TEST(SynthCli, SecondRunIsUpToDateAndWritesNothing) {
  const surroundd::testing::TempDir dir;
  auto arguments = smallRun(dir / "rec", 1);
  ASSERT_EQ(synth(dir, arguments).status, 0);
  const auto before = std::filesystem::last_write_time(dir / "rec" / "front.mkv");
  const auto manifest = std::filesystem::last_write_time(dir / "rec" / "manifest.yaml");
  arguments.push_back("--force");  // even with --force: the same recording is not made again
  const SynthRun again = synth(dir, arguments);
  EXPECT_EQ(again.status, 0);
  EXPECT_THAT(again.output, HasSubstr("up to date: " + (dir / "rec").string()));
  EXPECT_EQ(std::filesystem::last_write_time(dir / "rec" / "front.mkv"), before);
  EXPECT_EQ(std::filesystem::last_write_time(dir / "rec" / "manifest.yaml"), manifest);

  // Other arguments: refused without --force, replaced with it.
  auto other = smallRun(dir / "rec", 2);
  const SynthRun refused = synth(dir, other);
  EXPECT_EQ(refused.status, 2);
  EXPECT_THAT(refused.output, HasSubstr("--force"));
  other.push_back("--force");
  EXPECT_EQ(synth(dir, other).status, 0);
  EXPECT_THAT(testing::fileBytes(dir / "rec" / "ground_truth.yaml"), HasSubstr("seed: 2"));
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(HasSubstr(".tmp-")));
  }
}

TEST(SynthCli, BadInputExitsWithAMessage) {
  const surroundd::testing::TempDir dir;
  const auto out = (dir / "rec").string();
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--rig", (dir / "missing.yaml").string(), "--out", out}, "no such file"},
      {{"--rig", kPaper, "--out", out, "--size", "320by180"}, "--size: expected WIDTHxHEIGHT"},
      {{"--rig", kPaper, "--out", out, "--size", "321x180"}, "--size"},
      {{"--rig", kPaper, "--out", out, "--seconds", "-1"}, "--seconds"},
      {{"--rig", kPaper, "--out", out, "--drop-every", "middle:3"}, "no camera named 'middle'"},
      {{"--rig", kPaper, "--out", out, "--photometrics", "fancy"},
       "'random', 'identity' or 'extreme'"},
      {{"--rig", kPaper}, "--out: missing"},
      {{"--rig", kPaper, "--out", out, "--frobnicate"}, "unknown option"},
  };
  for (const auto& [arguments, message] : cases) {
    const SynthRun run = synth(dir, arguments);
    EXPECT_EQ(run.status, 2) << message;
    EXPECT_THAT(run.output, HasSubstr(message));
    EXPECT_FALSE(std::filesystem::exists(out)) << message;
  }
  dir.write("broken.yaml", "cameras:\n  - name: front\n");
  const SynthRun broken = synth(dir, {"--rig", (dir / "broken.yaml").string(), "--out", out});
  EXPECT_EQ(broken.status, 2);
  EXPECT_THAT(broken.output, HasSubstr("broken.yaml"));
  EXPECT_THAT(broken.output, HasSubstr("lens"));

  const SynthRun help = synth(dir, {"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_THAT(help.output, HasSubstr("--drop-every"));
}

}  // namespace
}  // namespace surroundd::synth

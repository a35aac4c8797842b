// The LUT cache: what is stored comes back identical; a file for other inputs or another format
// is stale, a damaged or truncated one corrupt, an entry that is no file (a FIFO, a device, a
// directory) refused unread, and none of them is ever used.

#include "processing/stitch/panorama_lut_cache.hpp"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "common/work_pool.hpp"
#include "tests/processing/panorama_test_support.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::processing {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

class PanoramaLutCacheTest : public ::testing::Test {
 protected:
  void writeBytes(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  }

  surroundd::testing::TempDir dir_;
  PanoramaLutCache cache_{dir_ / "cache"};
  WorkPool pool_{2};
  const bench::RecordingTruth& truth_ = testing::smallRecording();
  PanoramaSettings settings_ = testing::settingsFor(truth_);
  PanoramaLut lut_ = buildPanoramaLut(truth_.rig, settings_, pool_);
  std::string key_ = panoramaLutKey(truth_.rig, settings_);
};

TEST_F(PanoramaLutCacheTest, StoredLutComesBackIdentical) {
  EXPECT_EQ(cache_.load(key_, lut_.size).problem, "absent");
  cache_.store(key_, lut_);
  const auto lookup = cache_.load(key_, lut_.size);
  ASSERT_TRUE(lookup.lut.has_value()) << lookup.problem;
  EXPECT_EQ(*lookup.lut, lut_);
  // Written under its final name only: no temporary file left behind.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_ / "cache"), {}), 1);
}

// A LUT with no blend taps (one camera, no seams) reads back an empty array: under UBSan that was
// a memcpy into an empty vector's null data() (found by the fuzz seed writer, tests/fuzz).
TEST_F(PanoramaLutCacheTest, ALutWithoutBlendTapsComesBackIdentical) {
  PanoramaLut single;
  single.size = {2, 1};
  single.cameraSizes = {{4, 4}};
  single.taps = {{0, 0, 0, 0, 0}, {5, 64, 64, 0, 0}};
  single.blendRowBegin = {0, 0};
  cache_.store("single", single);
  const auto lookup = cache_.load("single", single.size);
  ASSERT_TRUE(lookup.lut.has_value()) << lookup.problem;
  EXPECT_EQ(*lookup.lut, single);
}

// Blend rows that go back down ({0, 5, 0} over no blend taps) once let the first row be read past
// the end of the blend taps, before the second row's order was checked (found by the fuzz target).
TEST_F(PanoramaLutCacheTest, BlendRowsOutOfOrderAreCorruptNotReadPastTheEnd) {
  PanoramaLut damaged;
  damaged.size = {1, 2};
  damaged.cameraSizes = {{4, 4}};
  damaged.taps = {{0, 0, 0, 0, 0}, {5, 0, 0, 0, 0}};
  damaged.blendRowBegin = {0, 5, 0};
  cache_.store("damaged", damaged);  // a faulty writer's file: its checksum is right
  const auto lookup = cache_.load("damaged", damaged.size);
  EXPECT_FALSE(lookup.lut.has_value());
  EXPECT_THAT(lookup.problem, HasSubstr("is corrupt (inconsistent contents)"));
}

// A size whose area overflows an int (201326594 x 262146) was signed overflow (UB) in the check of
// the tap count; now it is a corrupt file (found by the fuzz target).
TEST_F(PanoramaLutCacheTest, ASizeWhoseAreaOverflowsIsCorrupt) {
  PanoramaLut damaged;
  damaged.size = {201326594, 262146};
  damaged.cameraSizes = {{4, 4}};
  damaged.taps = {{0, 0, 0, 0, 0}, {5, 0, 0, 0, 0}};
  damaged.blendRowBegin = {0, 0};
  cache_.store("damaged", damaged);
  const auto lookup = cache_.load("damaged", damaged.size);
  EXPECT_FALSE(lookup.lut.has_value());
  EXPECT_THAT(lookup.problem, HasSubstr("is corrupt (inconsistent contents)"));
}

TEST_F(PanoramaLutCacheTest, EveryInputIsPartOfTheKey) {
  auto settings = settings_;
  settings.featherRad *= 1.0000001;
  EXPECT_NE(panoramaLutKey(truth_.rig, settings), key_);
  settings = settings_;
  settings.projection = PanoramaProjection::kSphere;
  EXPECT_NE(panoramaLutKey(truth_.rig, settings), key_);
  settings = settings_;
  settings.bowl.rimHeightM += 0.01;
  EXPECT_NE(panoramaLutKey(truth_.rig, settings), key_);
  auto rig = truth_.rig;
  rig.cameras[1].pose.position[2] += 1e-9;
  EXPECT_NE(panoramaLutKey(rig, settings_), key_);
  rig = truth_.rig;
  rig.cameras[3].intrinsics.distortion[0] = 1e-6;
  EXPECT_NE(panoramaLutKey(rig, settings_), key_);
  EXPECT_NE(cache_.fileFor(panoramaLutKey(rig, settings_)), cache_.fileFor(key_));
}

TEST_F(PanoramaLutCacheTest, AFileBuiltForOtherInputsIsStale) {
  auto settings = settings_;
  settings.featherRad = 0.01;
  const std::string otherKey = panoramaLutKey(truth_.rig, settings);
  cache_.store(otherKey, lut_);
  // As if the file had been renamed, or two keys shared a checksum.
  std::filesystem::rename(cache_.fileFor(otherKey), cache_.fileFor(key_));
  const auto lookup = cache_.load(key_, lut_.size);
  EXPECT_FALSE(lookup.lut.has_value());
  EXPECT_THAT(lookup.problem, HasSubstr("is stale (built for other inputs)"));
}

TEST_F(PanoramaLutCacheTest, AnotherFormatVersionIsStale) {
  cache_.store(key_, lut_);
  std::string bytes = surroundd::testing::fileBytes(cache_.fileFor(key_));
  bytes[8] = 99;  // the version follows the 8-byte magic
  writeBytes(cache_.fileFor(key_), bytes);
  EXPECT_THAT(cache_.load(key_, lut_.size).problem, HasSubstr("is stale (format 99"));
}

TEST_F(PanoramaLutCacheTest, DamagedOrTruncatedFilesAreCorrupt) {
  cache_.store(key_, lut_);
  const std::string good = surroundd::testing::fileBytes(cache_.fileFor(key_));
  std::string flipped = good;
  flipped[good.size() / 2] = static_cast<char>(flipped[good.size() / 2] ^ 0x10);
  for (const auto& [bytes, why] : {std::pair{flipped, "checksum mismatch"},
                                   std::pair{good.substr(0, good.size() / 3), "checksum mismatch"},
                                   std::pair{good.substr(0, 10), "not a LUT file"},
                                   std::pair{std::string("hello"), "not a LUT file"}}) {
    writeBytes(cache_.fileFor(key_), bytes);
    const auto lookup = cache_.load(key_, lut_.size);
    EXPECT_FALSE(lookup.lut.has_value());
    EXPECT_THAT(lookup.problem, HasSubstr(std::string("is corrupt (") + why)) << bytes.size();
  }
  // Rebuilt and stored again, it loads.
  cache_.store(key_, lut_);
  EXPECT_TRUE(cache_.load(key_, lut_.size).lut.has_value());
}

// Issue 51: a sparse file of 2.9 GB in the cache's place was read whole (3.1 GB resident, the
// first picture after 19 s). A file larger than the panorama's LUT can be is refused unread.
TEST_F(PanoramaLutCacheTest, AFileLargerThanThePanoramasLutCanBeIsRefusedUnread) {
  const auto path = cache_.fileFor(key_);
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path).close();  // made, then given a hole of 2.9 GB
  std::filesystem::resize_file(path, std::uintmax_t{2900} << 20);
  const auto lookup = cache_.load(key_, lut_.size);
  EXPECT_FALSE(lookup.lut.has_value());
  EXPECT_THAT(lookup.problem, AllOf(HasSubstr(path.string()), HasSubstr("larger than")));
  cache_.store(key_, lut_);
  EXPECT_TRUE(cache_.load(key_, lut_.size).lut.has_value());
}

// Issue 18: a FIFO in the cache hung start-up in open(), a symlink to /dev/zero was read without
// bound (3 GB), a directory stopped the daemon with no file named. Each is now refused, named,
// and replaced by the rebuilt LUT where a file can take its place.
TEST_F(PanoramaLutCacheTest, AnEntryThatIsNoFileIsRefusedWithoutReadingIt) {
  const auto path = cache_.fileFor(key_);
  std::filesystem::create_directories(path.parent_path());
  const auto expectRefused = [&](std::string_view kind) {
    const auto lookup = cache_.load(key_, lut_.size);
    EXPECT_FALSE(lookup.lut.has_value());
    EXPECT_THAT(lookup.problem, AllOf(HasSubstr(path.string()), HasSubstr(kind)));
  };
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  expectRefused("a FIFO, not a file");
  ASSERT_EQ(::mkfifo((path.string() + ".part").c_str(), 0600), 0);
  cache_.store(key_, lut_);  // neither the FIFO nor one under the temporary name blocks it
  EXPECT_TRUE(cache_.load(key_, lut_.size).lut.has_value());

  std::filesystem::remove(path);
  std::filesystem::create_symlink("/dev/zero", path);
  expectRefused("a character device, not a file");
  cache_.store(key_, lut_);
  EXPECT_TRUE(cache_.load(key_, lut_.size).lut.has_value());

  std::filesystem::remove(path);
  std::filesystem::create_directory(path);
  expectRefused("a directory, not a file");
  EXPECT_THAT([&] { cache_.store(key_, lut_); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr(path.string())));
}

TEST_F(PanoramaLutCacheTest, AnUnwritableFolderIsAClearError) {
  writeBytes(dir_ / "file", "x");
  const PanoramaLutCache blocked(dir_ / "file" / "cache");
  EXPECT_THAT([&] { blocked.store(key_, lut_); }, ::testing::ThrowsMessage<std::runtime_error>(
                                                      HasSubstr("cannot write the LUT cache")));
}

}  // namespace
}  // namespace surroundd::processing

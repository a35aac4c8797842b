#include "render/outputs/rtsp_stream_sink.hpp"

#include <atomic>
#include <chrono>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "tests/support/stream_receiver.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::render {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// NOLINTNEXTLINE(cert-err58-cpp): cv::Size stores two ints; its constructor throws nothing.
const cv::Size kSize(320, 240);

cv::Mat testPicture(int index) { return testing::syntheticPicture(kSize, index); }

// Picture `index`'s capture time: the index in seconds after an arbitrary start, so that a
// viewer's picture says which one it is.
constexpr auto kStart = std::chrono::system_clock::time_point(std::chrono::hours(24 * 365 * 56));
std::chrono::system_clock::time_point capturedAt(int index) {
  return kStart + std::chrono::seconds(index);
}
int indexOf(const bench::ViewedPicture& picture) {
  return static_cast<int>(
      std::chrono::duration_cast<std::chrono::seconds>(*picture.captured - kStart).count());
}

RtspStreamSettings settingsOnAnyPort() {
  RtspStreamSettings settings;
  settings.address = "127.0.0.1";
  settings.port = 0;
  settings.name = "surround";
  settings.video.size = kSize;
  settings.video.nominalFps = 30;  // a keyframe every 30 pictures, besides those on request
  settings.video.crf = 18;
  settings.video.encoder = "libx264";
  return settings;
}

// The sink's pictures at about 100 per second, as an output queue hands them over, until `until`
// says stop; returns how many.
template <typename Until>
int feed(RtspStreamSink& sink, int first, Until until) {
  int index = first;
  for (; !until(index); ++index) {
    sink.consume(testPicture(index), {milliseconds(10 * index), capturedAt(index)});
    std::this_thread::sleep_for(milliseconds(10));
  }
  return index;
}

// Each viewer's pictures are the sent ones from where it joined to the last, in order, none
// missing, each carrying its capture time.
void expectEveryPictureFrom(const std::vector<bench::ViewedPicture>& pictures, int first, int last,
                            const std::string& viewer) {
  ASSERT_FALSE(pictures.empty()) << viewer;
  ASSERT_TRUE(pictures.front().captured.has_value()) << viewer;
  EXPECT_LE(indexOf(pictures.front()), first) << viewer;
  for (std::size_t k = 0; k < pictures.size(); ++k) {
    ASSERT_TRUE(pictures[k].captured.has_value()) << viewer << " picture " << k;
    const int index = indexOf(pictures[k]);
    EXPECT_EQ(index, indexOf(pictures.front()) + static_cast<int>(k)) << viewer;
    // 4:2:0 at crf 18 on hard colour edges, as over UDP.
    EXPECT_GE(cv::PSNR(pictures[k].bgr, testPicture(index)), 30.0) << viewer << " " << index;
  }
  EXPECT_EQ(indexOf(pictures.back()), last) << viewer;
}

TEST(RtspStreamSink, ServesOneStreamToViewersOverUdpAndTcpEachFromTheNextPicture) {
  RtspStreamSink sink(settingsOnAnyPort());
  EXPECT_EQ(sink.url(), fmt::format("rtsp://127.0.0.1:{}/surround", sink.port()));
  // Nobody watches yet: nothing is wanted, and what comes anyway is not encoded.
  EXPECT_FALSE(sink.wantsFrame(milliseconds(0)));
  sink.consume(testPicture(0), {milliseconds(0), capturedAt(0)});

  const auto viewer = [&](const char* transport) {
    return bench::StreamViewerSettings{sink.url(), transport, std::chrono::seconds(5)};
  };
  // The first viewer's PLAY waits for the stream's first picture: it connects while pictures come.
  testing::StreamReceiver udp(viewer("udp"));
  const int sent = feed(sink, 1, [&](int index) { return udp.started() || index > 500; });
  ASSERT_TRUE(sink.wantsFrame(milliseconds(10 * sent)));
  // Past the next regular keyframe's place, so that only a keyframe on request lets the second
  // viewer start at once.
  const int beforeTcp = feed(sink, sent, [&](int index) { return index % 30 == 5; });
  testing::StreamReceiver tcp(viewer("tcp"));
  const int joinedBefore =
      feed(sink, beforeTcp, [&](int index) { return tcp.started() || index > 1000; });
  // A few more pictures to both, then the end.
  const int last =
      feed(sink, joinedBefore, [&](int index) { return index == joinedBefore + 20; }) - 1;
  sink.finish({}, {});

  const auto onUdp = udp.pictures();
  const auto onTcp = tcp.pictures();
  ASSERT_TRUE(udp.error().empty()) << udp.error();
  ASSERT_TRUE(tcp.error().empty()) << tcp.error();
  ASSERT_FALSE(onUdp.empty());
  ASSERT_FALSE(onTcp.empty());
  // Its PLAY was answered once the first picture had been encoded: it has that one on.
  expectEveryPictureFrom(onUdp, sent, last, "udp");
  // It joined at a picture 5 or more past a keyframe: without one on request it would have
  // waited up to 25 pictures for the next.
  expectEveryPictureFrom(onTcp, joinedBefore + 3, last, "tcp");
  // Encoded from the first viewer's first picture on.
  EXPECT_THAT(sink.describe(), HasSubstr(fmt::format("RTSP stream {} ({} frames, 2 viewers)",
                                                     sink.url(), last - indexOf(onUdp[0]) + 1)));
  EXPECT_EQ(sink.viewers(), 0);
}

// A player that leaves ends the encoding once it was the last; the next one gets a new pipeline
// and pictures again, from its own start.
TEST(RtspStreamSink, APlayerAfterTheLastOneLeftIsServedAfresh) {
  RtspStreamSink sink(settingsOnAnyPort());
  std::atomic<bool> feeding{true};
  std::atomic<int> sent{0};
  std::thread feeder([&] {
    for (int index = 0; feeding; ++index) {
      sink.consume(testPicture(index), {milliseconds(10 * index), capturedAt(index)});
      sent = index;
      std::this_thread::sleep_for(milliseconds(10));
    }
  });
  const auto watch = [&](int pictures) {
    bench::StreamViewer viewer({sink.url(), "tcp", std::chrono::seconds(5)});
    std::vector<int> indices;
    while (static_cast<int>(indices.size()) < pictures) {
      const auto picture = viewer.next();
      if (!picture || !picture->captured) break;
      indices.push_back(indexOf(*picture));
    }
    return indices;
  };
  const std::vector<int> first = watch(10);
  // Gone: nobody watches, nothing is wanted.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while ((sink.viewers() > 0 || sink.wantsFrame(milliseconds(0))) &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(10));
  }
  EXPECT_EQ(sink.viewers(), 0);
  EXPECT_FALSE(sink.wantsFrame(milliseconds(0)));
  const int before = sent;
  const std::vector<int> second = watch(10);
  feeding = false;
  feeder.join();
  sink.finish({}, {});
  ASSERT_EQ(first.size(), 10u);
  ASSERT_EQ(second.size(), 10u);
  for (std::size_t k = 1; k < 10; ++k) {
    EXPECT_EQ(first[k], first[k - 1] + 1);
    EXPECT_EQ(second[k], second[k - 1] + 1);
  }
  EXPECT_GT(second.front(), before);  // its own pictures, none left over from the first pipeline
  EXPECT_THAT(sink.describe(), HasSubstr("2 viewers"));
}

TEST(RtspStreamSink, APortInUseIsRefusedWithTheAddress) {
  const RtspStreamSink first(settingsOnAnyPort());
  RtspStreamSettings settings = settingsOnAnyPort();
  settings.port = first.port();
  EXPECT_THAT([&] { RtspStreamSink second(settings); },
              ThrowsMessage<std::runtime_error>(HasSubstr(
                  fmt::format("RTSP stream: cannot listen on 127.0.0.1:{}", first.port()))));
}

TEST(RtspStreamSink, ANameThatIsNotOnePathSegmentIsRefused) {
  RtspStreamSettings settings = settingsOnAnyPort();
  settings.name = "front/left";
  EXPECT_THAT([&] { RtspStreamSink sink(settings); },
              ThrowsMessage<std::runtime_error>(
                  HasSubstr("the name must be one path segment, got 'front/left'")));
}

TEST(RtspStreamSink, AStreamNobodyWatchedEndsWithNothingEncoded) {
  RtspStreamSink sink(settingsOnAnyPort());
  sink.finish({}, {});
  EXPECT_THAT(sink.describe(), HasSubstr("(0 frames, 0 viewers)"));
}

}  // namespace
}  // namespace surroundd::render

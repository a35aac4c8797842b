#pragma once
// Receives an MPEG-TS stream over UDP with FFmpeg and decodes every picture to BGR, on a thread of
// its own, the way a viewer on the network would. Listening starts in the constructor, so a sender
// started afterwards loses nothing; reading ends when nothing has come for `idle`.

#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <netinet/in.h>
#include <opencv2/core.hpp>
#include <sys/socket.h>
#include <unistd.h>

#include "common/ffmpeg_util.hpp"

namespace surroundd::testing {

// A UDP port nothing listens on right now.
inline int freeUdpPort() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address));
  socklen_t length = sizeof(address);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  ::close(fd);
  return ntohs(address.sin_port);
}

// Whether a UDP socket of this machine is bound to `port` (any address): /proc/net/udp lists each
// as "sl local_address:PORT ...", the port in hexadecimal.
inline bool udpPortBound(int port) {
  std::ifstream table("/proc/net/udp");
  const std::string suffix = fmt::format(":{:04X}", port);
  std::string line;
  std::getline(table, line);  // the header
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot;
    std::string localAddress;
    fields >> slot >> localAddress;
    if (localAddress.ends_with(suffix)) return true;
  }
  return false;
}

class StreamReceiver {
 public:
  StreamReceiver(int port, std::chrono::seconds idle) {
    // The socket is bound when avformat_open_input() opens the URL; it then waits for data, so it
    // runs on the thread while the test starts the sender.
    const std::string url = fmt::format(
        "udp://127.0.0.1:{}?timeout={}&fifo_size=1000000&overrun_nonfatal=1&buffer_size=8388608",
        port, std::chrono::microseconds(idle).count());
    ready_ = std::jthread([this, url] { receive(url); });
    // avformat_open_input() binds before it blocks on the first datagram: once the port is bound,
    // nothing the sender sends is lost. Bounded, so a receiver that never binds fails the test.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!udpPortBound(port)) {
      if (std::chrono::steady_clock::now() > deadline) {
        throw std::runtime_error(fmt::format("the stream receiver never bound UDP port {}", port));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  // Waits for the stream to end; the decoded pictures in order.
  std::vector<cv::Mat> pictures() {
    if (ready_.joinable()) ready_.join();
    return pictures_;
  }
  const std::string& error() const { return error_; }

 private:
  void receive(const std::string& url) {
    AVFormatContext* raw = nullptr;
    AVDictionary* options = nullptr;
    av_dict_set(&options, "probesize", "5000000", 0);
    const int opened =
        avformat_open_input(&raw, url.c_str(), av_find_input_format("mpegts"), &options);
    av_dict_free(&options);
    if (opened < 0) {
      error_ = "cannot open " + url + ": " + ffmpeg::errorText(opened);
      return;
    }
    ffmpeg::InputFormatPtr input(raw);
    if (avformat_find_stream_info(input.get(), nullptr) < 0) {
      error_ = "no stream info";
      return;
    }
    const int index = av_find_best_stream(input.get(), AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    if (index < 0) {
      error_ = "no video stream";
      return;
    }
    const AVCodecParameters* parameters = input->streams[index]->codecpar;
    ffmpeg::CodecContextPtr codec(
        avcodec_alloc_context3(avcodec_find_decoder(parameters->codec_id)));
    avcodec_parameters_to_context(codec.get(), parameters);
    avcodec_open2(codec.get(), codec->codec, nullptr);
    ffmpeg::PacketPtr packet(av_packet_alloc());
    ffmpeg::FramePtr frame(av_frame_alloc());
    const auto drain = [&] {
      while (avcodec_receive_frame(codec.get(), frame.get()) == 0) {
        cv::Mat bgr(frame->height, frame->width, CV_8UC3);
        ffmpeg::SwsContextPtr sws(sws_getContext(
            frame->width, frame->height, static_cast<AVPixelFormat>(frame->format), frame->width,
            frame->height, AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr));
        std::uint8_t* planes[] = {bgr.data};
        const int strides[] = {static_cast<int>(bgr.step[0])};
        sws_scale(sws.get(), frame->data, frame->linesize, 0, frame->height, planes, strides);
        pictures_.push_back(bgr);
      }
    };
    while (av_read_frame(input.get(), packet.get()) >= 0) {
      if (packet->stream_index == index) {
        avcodec_send_packet(codec.get(), packet.get());
        drain();
      }
      av_packet_unref(packet.get());
    }
    avcodec_send_packet(codec.get(), nullptr);
    drain();
  }

  std::vector<cv::Mat> pictures_;
  std::string error_;
  std::jthread ready_;
};

}  // namespace surroundd::testing

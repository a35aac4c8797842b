#include "render/outputs/xlib_image.hpp"

#include <cstdint>

#include <fmt/format.h>
#include <sys/ipc.h>
#include <sys/shm.h>

#include "render/render_error.hpp"

namespace surroundd::render {

std::unique_ptr<SharedMemorySegment> SharedMemorySegment::create(std::size_t bytes) {
  const int id = ::shmget(IPC_PRIVATE, bytes, IPC_CREAT | 0600);
  if (id < 0) return nullptr;
  void* address = ::shmat(id, nullptr, 0);
  if (reinterpret_cast<std::intptr_t>(address) == -1) {  // shmat's (void*) -1
    ::shmctl(id, IPC_RMID, nullptr);
    return nullptr;
  }
  return std::unique_ptr<SharedMemorySegment>(
      new SharedMemorySegment(id, static_cast<char*>(address)));
}

SharedMemorySegment::~SharedMemorySegment() {
  ::shmdt(address_);
  removeWhenDetached();
}

void SharedMemorySegment::removeWhenDetached() {
  if (removed_) return;
  ::shmctl(id_, IPC_RMID, nullptr);
  removed_ = true;
}

void XlibImage::ImageDeleter::operator()(XImage* image) const {
  image->data = nullptr;  // the memory is not Xlib's to free
  XDestroyImage(image);
}

XlibImage::XlibImage(XlibDisplay& display, const XVisualInfo& visual, cv::Size size)
    : display_(&display) {
  // The conversion writes bytes B, G, R, X: pixel values 0x00RRGGBB in little-endian order.
  if (visual.depth != 24 || visual.red_mask != 0xff0000 || visual.green_mask != 0xff00 ||
      visual.blue_mask != 0xff) {
    throw RenderError(fmt::format(
        "X11 window on {}: the visual is not 24-bit TrueColor with 8 bits per channel (depth {}, "
        "masks {:#x} {:#x} {:#x})",
        display.name(), visual.depth, visual.red_mask, visual.green_mask, visual.blue_mask));
  }
  trySharedMemory(visual, size);
  if (!attached_) {
    image_.reset(XCreateImage(display.get(), visual.visual, 24, ZPixmap, 0, nullptr,
                              static_cast<unsigned>(size.width), static_cast<unsigned>(size.height),
                              32, 0));
    if (!image_) throw RenderError("X11 window: cannot create an image (out of memory)");
    // Whatever the server's byte order, XPutImage converts from the one we write.
    image_->byte_order = LSBFirst;
    memory_.resize(static_cast<std::size_t>(image_->bytes_per_line) * image_->height);
    image_->data = reinterpret_cast<char*>(memory_.data());
  }
  if (image_->bits_per_pixel != 32) {
    throw RenderError(
        fmt::format("X11 window on {}: the server stores depth 24 in {} bits per "
                    "pixel; only 32 is supported",
                    display.name(), image_->bits_per_pixel));
  }
  pixels_ = cv::Mat(size, CV_8UC4, image_->data, static_cast<std::size_t>(image_->bytes_per_line));
}

void XlibImage::trySharedMemory(const XVisualInfo& visual, cv::Size size) {
  Display* x = display_->get();
  // XShmPutImage takes the memory in the server's byte order, with no conversion.
  if (XShmQueryExtension(x) == False || ImageByteOrder(x) != LSBFirst) return;
  image_.reset(XShmCreateImage(x, visual.visual, 24, ZPixmap, nullptr, &shmInfo_,
                               static_cast<unsigned>(size.width),
                               static_cast<unsigned>(size.height)));
  if (image_) {
    segment_ = SharedMemorySegment::create(static_cast<std::size_t>(image_->bytes_per_line) *
                                           image_->height);
  }
  if (segment_) {
    shmInfo_.shmid = segment_->id();
    shmInfo_.shmaddr = segment_->address();
    shmInfo_.readOnly = True;
    image_->data = segment_->address();
    // A server on another host, in another IPC namespace or under another user refuses the
    // segment (BadAccess), which only shows after a round trip.
    XShmAttach(x, &shmInfo_);
    attached_ = display_->syncForErrorCode() == 0 && !display_->lost();
  }
  if (attached_) {
    segment_->removeWhenDetached();
    return;
  }
  image_.reset();
  segment_.reset();
  shmInfo_ = {};
}

XlibImage::~XlibImage() {
  if (attached_ && !display_->lost()) {
    XShmDetach(display_->get(), &shmInfo_);
    display_->syncForErrorCode();
  }
}

void XlibImage::put(Drawable drawable, GC gc) {
  const auto width = static_cast<unsigned>(pixels_.cols);
  const auto height = static_cast<unsigned>(pixels_.rows);
  if (attached_) {
    XShmPutImage(display_->get(), drawable, gc, image_.get(), 0, 0, 0, 0, width, height, False);
  } else {
    XPutImage(display_->get(), drawable, gc, image_.get(), 0, 0, 0, 0, width, height);
  }
}

}  // namespace surroundd::render

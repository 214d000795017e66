#include "support/virtual_display.h"

#include <X11/Xutil.h>

#include <chrono>
#include <regex>
#include <stdexcept>
#include <thread>

#include <opencv2/imgproc.hpp>

namespace everytouch::test {

namespace {

// XDestroyImage is a macro.
void destroyImage(XImage* image) {
    XDestroyImage(image);
}

}  // namespace

VirtualDisplay::VirtualDisplay(cv::Size size) {
    const std::filesystem::path log = directory_.path() / "xvfb.log";
    // -displayfd 1: the server takes the first free display number and writes it to its standard output.
    server_ = std::make_unique<BackgroundProcess>(
        std::vector<std::string>{"Xvfb", "-displayfd", "1", "-nolisten", "tcp", "-screen", "0",
                                 std::to_string(size.width) + "x" + std::to_string(size.height) + "x24"},
        log);
    const std::regex number(R"((?:^|\n)(\d+)\n)");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    std::smatch match;
    std::string output;
    while (!std::regex_search(output = server_->output(), match, number)) {
        if (!server_->running() || std::chrono::steady_clock::now() > deadline)
            throw std::runtime_error("Xvfb did not start: " + output);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    name_ = ":" + match[1].str();
    connection_.reset(XOpenDisplay(name_.c_str()));
    if (!connection_)
        throw std::runtime_error("cannot connect to the Xvfb on " + name_);
}

cv::Mat VirtualDisplay::grab() const {
    Display* display = connection_.get();
    const Window root = DefaultRootWindow(display);
    XWindowAttributes attributes{};
    XGetWindowAttributes(display, root, &attributes);
    const io::UniqueHandle<XImage, destroyImage> image(
        XGetImage(display, root, 0, 0, static_cast<unsigned>(attributes.width),
                  static_cast<unsigned>(attributes.height), AllPlanes, ZPixmap));
    if (!image || image->bits_per_pixel != 32)
        throw std::runtime_error("cannot read the screen of " + name_);
    // 24-bit TrueColor in 32-bit pixels, little-endian: B, G, R, unused.
    const cv::Mat bgrx(image->height, image->width, CV_8UC4, image->data,
                       static_cast<std::size_t>(image->bytes_per_line));
    cv::Mat bgr;
    cv::cvtColor(bgrx, bgr, cv::COLOR_BGRA2BGR);
    return bgr;
}

}  // namespace everytouch::test

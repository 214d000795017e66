#include "support/compositor.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

#include <opencv2/core.hpp>

#include <X11/Xlib.h>

#include "io/x11_handles.h"

namespace everytouch::test {

namespace {

// Waits up to 10 s for the screen's compositing selection to be owned (or free); true when it is.
bool waitForCompositor(const std::string& display, bool owned) {
    const io::XDisplay connection(XOpenDisplay(display.c_str()));
    if (!connection)
        throw std::runtime_error("cannot connect to the X server " + display);
    const Atom selection = XInternAtom(connection.get(), "_NET_WM_CM_S0", False);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while ((XGetSelectionOwner(connection.get(), selection) != None) != owned) {
        if (std::chrono::steady_clock::now() > deadline)
            return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
}

}  // namespace

Compositor::Compositor(const std::string& display) : display_(display) {
    // No configuration file: no shadows, fading or transparency rules of its own.
    process_ = std::make_unique<BackgroundProcess>(
        std::vector<std::string>{"picom", "--backend", "xrender", "--config", "/dev/null"},
        directory_ / "picom.log", std::vector<std::pair<std::string, std::string>>{{"DISPLAY", display}});
    if (!waitForCompositor(display_, true))
        throw std::runtime_error("picom did not start on " + display_ + ": " + process_->output());
}

void Compositor::stop() {
    process_.reset();
    if (!waitForCompositor(display_, false))
        throw std::runtime_error("picom's selection on " + display_ + " stayed owned after it ended");
}

cv::Mat compositedOver(const cv::Mat& overlay, const cv::Mat& desktop) {
    CV_Assert(overlay.type() == CV_8UC4 && desktop.type() == CV_8UC3 && overlay.size() == desktop.size());
    cv::Mat result(desktop.size(), CV_8UC3);
    for (int y = 0; y < desktop.rows; ++y)
        for (int x = 0; x < desktop.cols; ++x) {
            const cv::Vec4b& top = overlay.at<cv::Vec4b>(y, x);
            const cv::Vec3b& below = desktop.at<cv::Vec3b>(y, x);
            for (int c = 0; c < 3; ++c)
                result.at<cv::Vec3b>(y, x)[c] =
                    cv::saturate_cast<uchar>(top[c] + std::lround(below[c] * (255.0 - top[3]) / 255.0));
        }
    return result;
}

}  // namespace everytouch::test

#pragma once

#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>

#include "support/process.h"
#include "support/temp_dir.h"

namespace everytouch::test {

// A Wayland compositor of the test's own, from construction until stop() or destruction: sway on its
// headless backend, drawing with pixman, with one output, HEADLESS-1, of `size` pixels at 60 Hz whose
// desktop is the colour `background` (BGR). Sway refuses to run as root: a test run as root runs it as
// nobody. Construction returns once the desktop shows.
class WaylandCompositor {
public:
    WaylandCompositor(cv::Size size, const cv::Vec3b& background);
    WaylandCompositor(const WaylandCompositor&) = delete;
    WaylandCompositor& operator=(const WaylandCompositor&) = delete;

    // What clients set WAYLAND_DISPLAY to: the socket's absolute path.
    const std::string& socket() const { return socket_; }
    // The output as it shows now (grim), BGR; empty when it cannot be grabbed.
    cv::Mat grab() const;
    // Ends it, as when the user logs out or the compositor crashes.
    void stop() { process_.reset(); }
    // Starts it again after stop(), on the same socket.
    void start();

private:
    cv::Size size_;
    cv::Vec3b background_;
    TempDir directory_;
    std::string socket_;
    std::unique_ptr<BackgroundProcess> process_;
};

}  // namespace everytouch::test

#pragma once

#include <chrono>
#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

// Xlib's connection, declared here so that its macros stay out of the tests that use this window.
struct _XDisplay;

namespace everytouch::test {

// An application's window on an X server of the test's, over `area` of the screen, showing `picture` (BGR,
// the area's size) and listening for mouse buttons: the desktop the code overlay must leave usable.
class DesktopWindow {
public:
    DesktopWindow(const std::string& display, const cv::Rect& area, const cv::Mat& picture);

    // Presses and releases the first mouse button at `point` (screen pixels) as a user would (XTEST); true
    // when this window received the press within `timeout`.
    bool clickReaches(cv::Point point, std::chrono::milliseconds timeout);

private:
    struct CloseConnection {
        void operator()(_XDisplay* connection) const;
    };
    std::unique_ptr<_XDisplay, CloseConnection> connection_;
    unsigned long window_ = 0;
};

}  // namespace everytouch::test

#include "support/desktop_window.h"

#include <stdexcept>
#include <thread>

#include <opencv2/imgproc.hpp>

#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/extensions/XTest.h>

namespace everytouch::test {

void DesktopWindow::CloseConnection::operator()(_XDisplay* connection) const {
    XCloseDisplay(connection);
}

DesktopWindow::DesktopWindow(const std::string& display, const cv::Rect& area, const cv::Mat& picture)
    : connection_(XOpenDisplay(display.c_str())) {
    if (!connection_)
        throw std::runtime_error("cannot connect to the X server " + display);
    if (picture.type() != CV_8UC3 || picture.size() != area.size())
        throw std::invalid_argument("the desktop's picture must be BGR of its window's size");
    Display* x = connection_.get();
    const int screen = DefaultScreen(x);
    const Window root = RootWindow(x, screen);
    const auto width = static_cast<unsigned>(area.width), height = static_cast<unsigned>(area.height);
    // The picture as the window's background, so that the server draws it whenever the window shows.
    const Pixmap background =
        XCreatePixmap(x, root, width, height, static_cast<unsigned>(DefaultDepth(x, screen)));
    cv::Mat bgrx;
    cv::cvtColor(picture, bgrx, cv::COLOR_BGR2BGRA);
    XImage* image =
        XCreateImage(x, DefaultVisual(x, screen), static_cast<unsigned>(DefaultDepth(x, screen)), ZPixmap, 0,
                     reinterpret_cast<char*>(bgrx.data), width, height, 32, static_cast<int>(bgrx.step));
    if (!image)
        throw std::runtime_error("cannot make the desktop's picture on " + display);
    XPutImage(x, background, DefaultGC(x, screen), image, 0, 0, 0, 0, width, height);
    image->data = nullptr;  // the Mat owns the pixels
    XDestroyImage(image);

    XSetWindowAttributes attributes{};
    attributes.background_pixmap = background;
    attributes.event_mask = ButtonPressMask;
    window_ = XCreateWindow(x, root, area.x, area.y, width, height, 0, CopyFromParent, InputOutput,
                            CopyFromParent, CWBackPixmap | CWEventMask, &attributes);
    XMapWindow(x, window_);
    XSync(x, False);
}

bool DesktopWindow::clickReaches(cv::Point point, std::chrono::milliseconds timeout) {
    Display* x = connection_.get();
    XTestFakeMotionEvent(x, DefaultScreen(x), point.x, point.y, 0);
    XTestFakeButtonEvent(x, 1, True, 0);
    XTestFakeButtonEvent(x, 1, False, 0);
    XSync(x, False);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
        XEvent event;
        if (XCheckTypedWindowEvent(x, window_, ButtonPress, &event))
            return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
}

}  // namespace everytouch::test

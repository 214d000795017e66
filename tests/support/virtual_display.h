#pragma once

#include <X11/Xlib.h>

#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>

#include "io/handles.h"
#include "support/process.h"
#include "support/temp_dir.h"

namespace everytouch::test {

// An X server of the test's own (Xvfb, 24-bit colour, no compositor), on a display number it chose itself,
// and a connection to it that reads the screen back. Stopped when the object goes.
class VirtualDisplay {
public:
    explicit VirtualDisplay(cv::Size size);

    // ":N", for DISPLAY.
    const std::string& name() const { return name_; }
    // The whole screen as it is now, BGR.
    cv::Mat grab() const;

private:
    TempDir directory_;
    std::unique_ptr<BackgroundProcess> server_;
    std::string name_;
    io::UniqueHandle<Display, XCloseDisplay> connection_;
};

}  // namespace everytouch::test

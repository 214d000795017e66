#pragma once

#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>

#include "support/process.h"
#include "support/temp_dir.h"

namespace everytouch::test {

// A compositing manager (picom, drawing with XRender) on an X server of the test's, from construction until
// stop() or destruction. Construction returns once it owns the screen's _NET_WM_CM_S0 selection.
class Compositor {
public:
    explicit Compositor(const std::string& display);
    Compositor(const Compositor&) = delete;
    Compositor& operator=(const Compositor&) = delete;

    // Ends it, as when a compositing manager crashes or the user quits it; returns once the selection is
    // free.
    void stop();

private:
    std::string display_;
    TempDir directory_;
    std::unique_ptr<BackgroundProcess> process_;
};

// What a compositor's "over" makes of a premultiplied BGRA overlay above a BGR desktop, rounded as XRender
// rounds.
cv::Mat compositedOver(const cv::Mat& overlay, const cv::Mat& desktop);

}  // namespace everytouch::test

#include "support/screen_grabs.h"

#include <chrono>
#include <thread>

#include <opencv2/core.hpp>

namespace everytouch::test {

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) <= 1.0;
}

AlternateGrabs grabAlternates(const VirtualDisplay& display, const cv::Mat& positive,
                              const cv::Mat& negative) {
    AlternateGrabs grabbed;
    bool matched = false;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while ((grabbed.positive.empty() || grabbed.negative.empty()) &&
           std::chrono::steady_clock::now() < deadline) {
        const cv::Mat screen = display.grab();
        if (sameImage(screen, positive))
            grabbed.positive = screen;
        else if (sameImage(screen, negative))
            grabbed.negative = screen;
        else if (matched)
            ++grabbed.others;
        matched = matched || !grabbed.positive.empty() || !grabbed.negative.empty();
        std::this_thread::sleep_for(std::chrono::milliseconds(3));
    }
    return grabbed;
}

}  // namespace everytouch::test

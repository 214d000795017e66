#include "support/screen_grabs.h"

#include <chrono>
#include <thread>

#include <opencv2/core.hpp>

namespace everytouch::test {

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) <= 1.0;
}

namespace {

// The pause before the next grab. A grab that waits for the compositor's next frame and takes as many
// refreshes each time sees the same one of two alternating images every time (a loaded machine's grabs of
// the headless sway took two frames each and saw one polarity for seconds); each grab that repeats an image
// already grabbed shifts the next by another 5 ms, a third of a 60 Hz refresh, so the phase walks over both.
void keep(const cv::Mat& screen, cv::Mat& grabbed, int& repeats) {
    if (!grabbed.empty())
        ++repeats;
    grabbed = screen;
}

void pauseBeforeTheNextGrab(int repeats) {
    std::this_thread::sleep_for(std::chrono::milliseconds(3 + 5 * (repeats % 4)));
}

}  // namespace

AlternateGrabs grabAlternates(const std::function<cv::Mat()>& grab, const cv::Mat& positive,
                              const cv::Mat& negative) {
    AlternateGrabs grabbed;
    bool matched = false;
    int repeats = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while ((grabbed.positive.empty() || grabbed.negative.empty()) &&
           std::chrono::steady_clock::now() < deadline) {
        const cv::Mat screen = grab();
        if (sameImage(screen, positive))
            keep(screen, grabbed.positive, repeats);
        else if (sameImage(screen, negative))
            keep(screen, grabbed.negative, repeats);
        else if (matched)
            ++grabbed.others;
        matched = matched || !grabbed.positive.empty() || !grabbed.negative.empty();
        pauseBeforeTheNextGrab(repeats);
    }
    return grabbed;
}

AlternateGrabs grabAlternates(const VirtualDisplay& display, const cv::Mat& positive,
                              const cv::Mat& negative) {
    return grabAlternates([&display] { return display.grab(); }, positive, negative);
}

AlternateGrabs grabBothPolarities(const std::function<cv::Mat()>& grab, const cv::Mat& pattern, int delta) {
    CV_Assert(pattern.type() == CV_8UC1);
    const cv::Mat ones = pattern != 0;
    const cv::Mat zeros = pattern == 0;
    // One colour over each kind of bit, within rounding: the code over a desktop of one colour, not what
    // the screen showed before (a calibration image) nor a grab mixing two frames.
    const auto uniform = [](const cv::Scalar& spread) {
        return spread[0] < 1.0 && spread[1] < 1.0 && spread[2] < 1.0;
    };
    AlternateGrabs grabbed;
    int repeats = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while ((grabbed.positive.empty() || grabbed.negative.empty()) &&
           std::chrono::steady_clock::now() < deadline) {
        const cv::Mat screen = grab();
        if (screen.size() != pattern.size() || screen.type() != CV_8UC3)
            continue;
        cv::Scalar onOnes, onZeros, spreadOnOnes, spreadOnZeros;
        cv::meanStdDev(screen, onOnes, spreadOnOnes, ones);
        cv::meanStdDev(screen, onZeros, spreadOnZeros, zeros);
        const double brighter = onOnes[0] + onOnes[1] + onOnes[2] - (onZeros[0] + onZeros[1] + onZeros[2]);
        if (!uniform(spreadOnOnes) || !uniform(spreadOnZeros))
            ++grabbed.others;
        else if (brighter >= delta)
            keep(screen, grabbed.positive, repeats);
        else if (brighter <= -delta)
            keep(screen, grabbed.negative, repeats);
        else
            ++grabbed.others;
        pauseBeforeTheNextGrab(repeats);
    }
    return grabbed;
}

}  // namespace everytouch::test

#include "core/code_overlay.h"

#include <opencv2/core.hpp>

namespace everytouch::core {

void makeCodeOverlay(const cv::Mat& bits, int delta, cv::Mat& positive, cv::Mat& negative) {
    CV_Assert(bits.type() == CV_8UC1);
    CV_Assert(delta >= 1 && delta <= 127);
    const auto alpha = static_cast<uchar>(2 * delta);
    const cv::Vec4b white(alpha, alpha, alpha, alpha), black(0, 0, 0, alpha);
    const auto grey = static_cast<uchar>(delta);  // 127.5 x alpha / 255
    const cv::Vec4b midGrey(grey, grey, grey, alpha);
    positive.create(bits.size(), CV_8UC4);
    negative.create(bits.size(), CV_8UC4);
    for (int y = 0; y < bits.rows; ++y) {
        const uchar* bit = bits.ptr<uchar>(y);
        auto* plus = positive.ptr<cv::Vec4b>(y);
        auto* minus = negative.ptr<cv::Vec4b>(y);
        for (int x = 0; x < bits.cols; ++x) {
            plus[x] = bit[x] ? white : midGrey;
            minus[x] = bit[x] ? black : midGrey;
        }
    }
}

}  // namespace everytouch::core

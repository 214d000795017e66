#include "core/embedding.h"

#include <opencv2/core.hpp>

namespace everytouch::core {

void embedCode(const cv::Mat& content, const cv::Mat& bits, int delta, cv::Mat& positive, cv::Mat& negative) {
    CV_Assert(content.type() == CV_8UC1 || content.type() == CV_8UC3);
    CV_Assert(bits.type() == CV_8UC1 && bits.size() == content.size());
    CV_Assert(delta >= 1 && delta <= 127);

    cv::Mat compression(1, 256, CV_8UC1);
    for (int level = 0; level < 256; ++level)
        compression.at<uchar>(level) =
            cv::saturate_cast<uchar>(delta + level * (255.0 - 2.0 * delta) / 255.0);
    cv::LUT(content, compression, positive);
    positive.copyTo(negative);
    const cv::Scalar amplitude = cv::Scalar::all(delta);
    cv::add(positive, amplitude, positive, bits);
    cv::subtract(negative, amplitude, negative, bits);
}

}  // namespace everytouch::core

#include "core/embedding.h"

#include <array>

#include <opencv2/core.hpp>

namespace everytouch::core {

void embedCode(const cv::Mat& content, const cv::Mat& bits, int delta, cv::Mat& positive, cv::Mat& negative) {
    CV_Assert(content.type() == CV_8UC1 || content.type() == CV_8UC3);
    CV_Assert(bits.type() == CV_8UC1 && bits.size() == content.size());
    CV_Assert(delta >= 1 && delta <= 127);

    std::array<uchar, 256> compressed;
    for (int level = 0; level < 256; ++level)
        compressed[level] = cv::saturate_cast<uchar>(delta + level * (255.0 - 2.0 * delta) / 255.0);
    positive.create(content.size(), content.type());
    negative.create(content.size(), content.type());
    const int channels = content.channels();
    for (int y = 0; y < content.rows; ++y) {
        const uchar* source = content.ptr<uchar>(y);
        const uchar* bit = bits.ptr<uchar>(y);
        uchar* plus = positive.ptr<uchar>(y);
        uchar* minus = negative.ptr<uchar>(y);
        for (int x = 0; x < content.cols; ++x) {
            const int amplitude = bit[x] ? delta : 0;
            for (int c = 0; c < channels; ++c, ++source, ++plus, ++minus) {
                const int level = compressed[*source];
                *plus = static_cast<uchar>(level + amplitude);
                *minus = static_cast<uchar>(level - amplitude);
            }
        }
    }
}

}  // namespace everytouch::core

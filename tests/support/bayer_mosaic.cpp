#include "support/bayer_mosaic.h"

#include <stdexcept>

namespace everytouch::test {

namespace {

int channelOf(char filter) {
    switch (filter) {
        case 'B':
            return 0;
        case 'G':
            return 1;
        case 'R':
            return 2;
        default:
            throw std::invalid_argument(std::string("not a Bayer filter: ") + filter);
    }
}

}  // namespace

cv::Mat bayerMosaic(const cv::Mat& bgr, const std::string& pattern) {
    if (pattern.size() != 8 || pattern.rfind("Bayer", 0) != 0 || pattern.back() != '8')
        throw std::invalid_argument("not a Bayer pattern: " + pattern);
    // The first row alternates the two named filters; the second row the other two.
    const char first = pattern[5], second = pattern[6];
    const char third = first == 'G' ? (second == 'R' ? 'B' : 'R') : 'G';
    const char fourth = first == 'G' ? 'G' : (first == 'R' ? 'B' : 'R');
    const int channels[2][2] = {{channelOf(first), channelOf(second)}, {channelOf(third), channelOf(fourth)}};
    cv::Mat mosaic(bgr.size(), CV_8UC1);
    for (int y = 0; y < bgr.rows; ++y)
        for (int x = 0; x < bgr.cols; ++x)
            mosaic.at<uchar>(y, x) = bgr.at<cv::Vec3b>(y, x)[channels[y % 2][x % 2]];
    return mosaic;
}

}  // namespace everytouch::test

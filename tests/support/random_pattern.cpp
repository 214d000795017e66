#include "support/random_pattern.h"

#include <opencv2/core.hpp>

namespace everytouch::test {

cv::Mat randomPattern(cv::Size size, unsigned seed) {
    cv::Mat pattern(size, CV_8UC1);
    cv::RNG rng(seed);
    rng.fill(pattern, cv::RNG::UNIFORM, 0, 2);
    return pattern;
}

}  // namespace everytouch::test

#pragma once

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// Paper eq. 4-6: the two images the projector shows for one content image O and a binary code B,
//   I = O + P,  I' = O - P,  P = delta where B = 1, 0 where B = 0,  on every channel.
// O is first compressed from [0, 255] into [delta, 255 - delta] so neither image clips and the code survives
// on black and on white content; people see the average, which is the compressed O.
//
// content:  CV_8UC1 or CV_8UC3, the projector's size
// bits:     CV_8UC1, the projector's size, 0 or 1
// delta:    code amplitude in digital levels, 1..127
// positive, negative: receive I and I' (same type as content); reallocated only when size or type changes.
void embedCode(const cv::Mat& content, const cv::Mat& bits, int delta, cv::Mat& positive, cv::Mat& negative);

}  // namespace everytouch::core

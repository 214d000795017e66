#include "core/gray_frame.h"

#include <opencv2/imgproc.hpp>

namespace everytouch::core {

Status grayFrame(const cv::Mat& cameraImage, cv::Mat& gray) {
    if (cameraImage.empty() || cameraImage.depth() != CV_8U ||
        (cameraImage.channels() != 1 && cameraImage.channels() != 3))
        return Failure{"camera frame: expected an 8-bit gray or BGR image"};
    if (cameraImage.channels() == 3)
        cv::cvtColor(cameraImage, gray, cv::COLOR_BGR2GRAY);
    else
        gray = cameraImage;
    return {};
}

}  // namespace everytouch::core

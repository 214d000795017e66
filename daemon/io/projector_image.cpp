#include "io/projector_image.h"

#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "io/input_error.h"

namespace everytouch::io {

cv::Mat projectorImageInColour(const cv::Mat& image, cv::Size panel) {
    if (image.size() != panel || (image.type() != CV_8UC1 && image.type() != CV_8UC3))
        throw std::invalid_argument("projector image: expected an 8-bit gray or BGR image of " +
                                    std::to_string(panel.width) + "x" + std::to_string(panel.height) +
                                    " pixels, got " + std::to_string(image.cols) + "x" +
                                    std::to_string(image.rows) + " of type " + std::to_string(image.type()));
    if (image.type() == CV_8UC3)
        return image;
    cv::Mat colour;
    cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
    return colour;
}

void checkCodeDelta(int delta) {
    if (delta < 1 || delta > 127)
        throw InputError("[Projector] Delta=", std::to_string(delta), "expected 1 to 127 levels");
}

}  // namespace everytouch::io

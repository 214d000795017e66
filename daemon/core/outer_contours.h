#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// One traced outer boundary: a run of OuterContours::points.
struct ContourSpan {
    int begin = 0;      // index of its first point
    int size = 0;       // number of points
    double area = 0.0;  // enclosed by the polygon through the pixel centres, square pixels
};

// The outer boundaries of the 8-connected regions of a binary mask, with the buffers they are traced in.
// Every buffer is kept from call to call: once a frame size and a boundary length have been seen, tracing
// allocates nothing (cv::findContours allocates its storage and a copy of the image on every call).
struct OuterContours {
    // Every boundary traced, one after another; `contours` says where the kept ones lie. An outer boundary
    // runs clockwise as seen in the image (x right, y down): its region lies on the right of the direction
    // of travel. A pixel where the boundary passes twice (a one-pixel neck) appears twice.
    std::vector<cv::Point> points;
    std::vector<ContourSpan> contours;  // the kept outer boundaries, in raster order of their first pixels
    cv::Mat visited;                    // CV_8UC1, mask size: all zero between calls
};

// Traces the outer boundary of every 8-connected region of `mask` (CV_8UC1, nonzero = inside) whose boundary
// encloses at least `minArea` square pixels. The boundaries of holes are traced as well, so that they are not
// mistaken for regions, and dropped. Throws std::invalid_argument for a mask of another type.
void findOuterContours(const cv::Mat& mask, double minArea, OuterContours& contours);

}  // namespace everytouch::core

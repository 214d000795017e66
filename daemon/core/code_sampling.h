#pragma once

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "core/observed_code.h"

namespace everytouch::core {

// Paper eq. 17-18: the code the camera sees where the projector window anchored at `anchor` (its bottom-right
// pixel) falls, if the surface there induces `projectorToCamera` (H_PC^-1). Each of the window*window
// projector pixels is mapped into the camera and the code image (core/code_image.h) is read at the nearest
// camera pixel; bits outside the image or on unknown pixels are unknown. Bit order as in core/pattern.h.
ObservedCode sampleCode(const cv::Mat& codeImage, const Eigen::Matrix3d& projectorToCamera, cv::Point anchor,
                        int window);

// Paper eq. 16-18 at a camera point such as a fingertip: the projector window F_P = H_PC F_C (nearest pixel)
// and the code the camera sees there, through the surface hypothesis `cameraToProjector` (H_PC; for a plane
// at height d: Calibration::cameraToProjectorHomography(d)). Compare with codeAt(pattern, anchor, window)
// when the anchor lies in codedRegion.
struct CodeSample {
    cv::Point anchor;       // F_P, projector pixels
    ObservedCode observed;  // BC_S
};
CodeSample sampleCodeAtCamera(const cv::Mat& codeImage, const Eigen::Matrix3d& cameraToProjector,
                              const Eigen::Vector2d& cameraPoint, int window);

// Every projector window at once, under one surface hypothesis: the same sampling as sampleCode for all
// anchors. Only anchors in codedRegion(pattern.size(), window) carry whole windows.
struct WindowAgreement {
    cv::Mat mismatches;  // CV_8UC1, pattern size: per anchor, known bits that differ from the pattern
    cv::Mat known;       // CV_8UC1, pattern size: per anchor, bits the camera saw
    cv::Mat observed;  // CV_8UC1, pattern size: the code image read at each projector pixel (or kUnknownBit)
    cv::Mat mismatchFlags;  // CV_8UC1 scratch
    cv::Mat knownFlags;     // CV_8UC1 scratch
};

// pattern: CV_8UC1 0/1 (core/pattern.h). All outputs are reallocated only when the pattern size changes.
void matchAllWindows(const cv::Mat& codeImage, const Eigen::Matrix3d& projectorToCamera,
                     const cv::Mat& pattern, int window, WindowAgreement& agreement);

}  // namespace everytouch::core

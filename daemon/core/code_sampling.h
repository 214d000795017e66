#pragma once

#include <optional>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "core/code_index.h"
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

// Where on the panel the light seen at a camera point came from, found without the homography of the surface
// it fell on (a hand, a tilted board): the code image is sampled around the camera point with the local shape
// of `approximateCameraToProjector` (the table's, say: the homography of any nearby plane differs from it
// mainly by a shift) and the codes are looked up in `index`. The surface's unknown shift puts the sampling
// grid at an unknown sub-pixel phase against the projector's pixels, which blurs bits, so the grid is tried
// at phases x phases offsets of 1/phases pixel and the most significant match is kept. A match counts only if
// the expected number of windows that would match as well by chance, over all phases, is at most
// maxChanceMatches (CodeIndex::chanceMatches): with 301 625 windows, 3x3 phases and the default 0.01, 29
// known bits must all agree, 34 may have one mismatch.
struct CodeLocation {
    Eigen::Vector2d projectorPoint;  // projector pixel seen at the camera point, to 1/phases pixel
    CodeMatch match;                 // the window read there
    int knownBits = 0;               // bits of that window that were read
};
std::optional<CodeLocation> locateCode(const cv::Mat& codeImage, const CodeIndex& index,
                                       const Eigen::Matrix3d& approximateCameraToProjector,
                                       const Eigen::Vector2d& cameraPoint, double maxChanceMatches = 0.01,
                                       int phases = 3);

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

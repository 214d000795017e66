#include "core/code_sampling.h"

#include <Eigen/LU>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_image.h"

namespace everytouch::core {

namespace {

// The pixel nearest to where `homography` maps pixel (x, y); pixel centres sit at integer coordinates, as in
// cv::warpPerspective.
cv::Point nearestMappedPixel(const Eigen::Matrix3d& homography, double x, double y) {
    const Eigen::Vector3d mapped = homography * Eigen::Vector3d(x, y, 1.0);
    return {cvRound(mapped.x() / mapped.z()), cvRound(mapped.y() / mapped.z())};
}

}  // namespace

ObservedCode sampleCode(const cv::Mat& codeImage, const Eigen::Matrix3d& projectorToCamera, cv::Point anchor,
                        int window) {
    CV_Assert(codeImage.type() == CV_8UC1 && window >= 1 && window <= 8);
    const cv::Rect bounds(0, 0, codeImage.cols, codeImage.rows);
    ObservedCode observed;
    int bit = 0;
    for (int y = anchor.y - window + 1; y <= anchor.y; ++y)
        for (int x = anchor.x - window + 1; x <= anchor.x; ++x, ++bit) {
            const cv::Point camera = nearestMappedPixel(projectorToCamera, x, y);
            if (!bounds.contains(camera))
                continue;
            const uchar value = codeImage.at<uchar>(camera);
            if (value == kUnknownBit)
                continue;
            observed.known |= std::uint64_t{1} << bit;
            observed.bits |= std::uint64_t{value == kOneBit} << bit;
        }
    return observed;
}

CodeSample sampleCodeAtCamera(const cv::Mat& codeImage, const Eigen::Matrix3d& cameraToProjector,
                              const Eigen::Vector2d& cameraPoint, int window) {
    CodeSample sample;
    sample.anchor = nearestMappedPixel(cameraToProjector, cameraPoint.x(), cameraPoint.y());
    sample.observed = sampleCode(codeImage, cameraToProjector.inverse(), sample.anchor, window);
    return sample;
}

void matchAllWindows(const cv::Mat& codeImage, const Eigen::Matrix3d& projectorToCamera,
                     const cv::Mat& pattern, int window, WindowAgreement& agreement) {
    CV_Assert(codeImage.type() == CV_8UC1 && pattern.type() == CV_8UC1 && window >= 1 && window <= 8);
    cv::Matx33d homography;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            homography(r, c) = projectorToCamera(r, c);
    // With WARP_INVERSE_MAP the matrix maps each output (projector) pixel to where it is read in the camera.
    cv::warpPerspective(codeImage, agreement.observed, homography, pattern.size(),
                        cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                        cv::Scalar(kUnknownBit));

    agreement.mismatchFlags.create(pattern.size(), CV_8UC1);
    agreement.knownFlags.create(pattern.size(), CV_8UC1);
    for (int y = 0; y < pattern.rows; ++y) {
        const uchar* expected = pattern.ptr<uchar>(y);
        const uchar* seen = agreement.observed.ptr<uchar>(y);
        uchar* mismatch = agreement.mismatchFlags.ptr<uchar>(y);
        uchar* known = agreement.knownFlags.ptr<uchar>(y);
        for (int x = 0; x < pattern.cols; ++x) {
            known[x] = seen[x] != kUnknownBit;
            mismatch[x] = known[x] && seen[x] != expected[x];
        }
    }
    // Sums over the window that ends at each pixel: the kernel's anchor is its bottom-right cell.
    const cv::Size kernel(window, window);
    const cv::Point bottomRight(window - 1, window - 1);
    cv::boxFilter(agreement.mismatchFlags, agreement.mismatches, CV_8U, kernel, bottomRight, false,
                  cv::BORDER_CONSTANT);
    cv::boxFilter(agreement.knownFlags, agreement.known, CV_8U, kernel, bottomRight, false,
                  cv::BORDER_CONSTANT);
}

}  // namespace everytouch::core

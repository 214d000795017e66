#include "core/code_sampling.h"

#include <Eigen/LU>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_image.h"
#include "core/geometry.h"

namespace everytouch::core {

namespace {

// The pixel nearest to where `homography` maps pixel (x, y); pixel centres sit at integer coordinates, as in
// cv::warpPerspective.
cv::Point nearestMappedPixel(const Eigen::Matrix3d& homography, double x, double y) {
    const Eigen::Vector3d mapped = homography * Eigen::Vector3d(x, y, 1.0);
    return {cvRound(mapped.x() / mapped.z()), cvRound(mapped.y() / mapped.z())};
}

// The code of the window whose bottom-right sampling point is `anchor` (projector px, possibly fractional).
ObservedCode sampleWindow(const cv::Mat& codeImage, const Eigen::Matrix3d& projectorToCamera,
                          const Eigen::Vector2d& anchor, int window) {
    CV_Assert(codeImage.type() == CV_8UC1 && window >= 1 && window <= 8);
    const cv::Rect bounds(0, 0, codeImage.cols, codeImage.rows);
    ObservedCode observed;
    int bit = 0;
    for (int dy = window - 1; dy >= 0; --dy)
        for (int dx = window - 1; dx >= 0; --dx, ++bit) {
            const cv::Point camera = nearestMappedPixel(projectorToCamera, anchor.x() - dx, anchor.y() - dy);
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

}  // namespace

ObservedCode sampleCode(const cv::Mat& codeImage, const Eigen::Matrix3d& projectorToCamera, cv::Point anchor,
                        int window) {
    return sampleWindow(codeImage, projectorToCamera, Eigen::Vector2d(anchor.x, anchor.y), window);
}

CodeSample sampleCodeAtCamera(const cv::Mat& codeImage, const Eigen::Matrix3d& cameraToProjector,
                              const Eigen::Vector2d& cameraPoint, int window) {
    CodeSample sample;
    sample.anchor = nearestMappedPixel(cameraToProjector, cameraPoint.x(), cameraPoint.y());
    sample.observed = sampleCode(codeImage, cameraToProjector.inverse(), sample.anchor, window);
    return sample;
}

std::optional<CodeLocation> locateCode(const cv::Mat& codeImage, const CodeIndex& index,
                                       const Eigen::Matrix3d& approximateCameraToProjector,
                                       const Eigen::Vector2d& cameraPoint, double maxChanceMatches,
                                       int phases) {
    CV_Assert(phases >= 1 && maxChanceMatches > 0);
    const Eigen::Matrix3d projectorToCamera = approximateCameraToProjector.inverse();
    const Eigen::Vector2d seen = applyHomography(approximateCameraToProjector, cameraPoint);
    // Each phase is a separate chance for a wrong window to match.
    const double chancePerLookup = maxChanceMatches / (phases * phases);
    std::optional<CodeLocation> best;
    double bestChance = 0;
    for (int py = 0; py < phases; ++py)
        for (int px = 0; px < phases; ++px) {
            const Eigen::Vector2d phase(double(px) / phases, double(py) / phases);
            const ObservedCode observed =
                sampleWindow(codeImage, projectorToCamera, seen + phase, index.window());
            const int known = observed.knownCount();
            int allowed = -1;
            while (allowed < known && index.chanceMatches(known, allowed + 1) <= chancePerLookup)
                ++allowed;
            if (allowed < 0)
                continue;
            const std::optional<CodeMatch> match = index.match(observed, allowed);
            if (!match)
                continue;
            const double chance = index.chanceMatches(known, match->mismatches);
            if (best && chance >= bestChance)
                continue;
            // The grid's bottom-right point fell on the window's anchor; the camera point lies `phase`
            // before.
            const Eigen::Vector2d anchor(match->position.x, match->position.y);
            best = CodeLocation{anchor - phase, *match, known};
            bestChance = chance;
        }
    return best;
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

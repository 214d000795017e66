#include "core/code_blur.h"

#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/table_code.h"

namespace everytouch::core {

namespace {

// The local means taken out of S and of the prediction: wide enough to hold many code bits, narrow enough
// that the content's brightness and the table's albedo hardly change across it.
constexpr int kLocalMeanPx = 9;

constexpr int kCandidates = static_cast<int>(CodeBlurMeter::kMostBlurPx / CodeBlurMeter::kStepPx + 0.5) + 1;

}  // namespace

void CodeBlurMeter::setRig(const Calibration& calibration, const cv::Mat& pattern, const cv::Mat& region) {
    CV_Assert(region.type() == CV_8UC1 && region.size() == calibration.cameraSize);
    const TableCode code = predictTableCode(calibration, pattern, 0.0);
    // The most blurred candidate reaches three sigmas into what lies beyond the panel's light: those pixels
    // are left out.
    cv::Mat lit = code.predicted >= 0.0f;
    const int reach = static_cast<int>(std::ceil(3.0 * kMostBlurPx)) + kLocalMeanPx / 2;
    cv::erode(lit, lit, cv::getStructuringElement(cv::MORPH_RECT, {2 * reach + 1, 2 * reach + 1}));
    cv::Mat usable = lit & region;
    box_ = cv::boundingRect(usable);
    sharp_.release();
    if (box_.empty())
        return;
    sharp_ = code.predicted(box_).clone();
    inRegion_ = usable(box_).clone();
    const double pixels = cv::countNonZero(inRegion_);
    // Neighbouring pixels share light through the blur: about two pixels per independent sample.
    chance_ = std::sqrt(2.0 / pixels);
}

std::optional<double> CodeBlurMeter::measure(const cv::Mat& subtraction) {
    CV_Assert(subtraction.type() == CV_16SC1 && hasRig());
    subtraction(box_).convertTo(subtraction_, CV_32F);
    cv::boxFilter(subtraction_, localMean_, CV_32F, {kLocalMeanPx, kLocalMeanPx});
    subtraction_ -= localMean_;

    std::array<double, kCandidates> correlation{};
    for (int i = 0; i < kCandidates; ++i) {
        const double sigma = i * kStepPx;
        if (i == 0)
            sharp_.copyTo(blurred_);
        else
            cv::GaussianBlur(sharp_, blurred_, cv::Size(), sigma);
        cv::boxFilter(blurred_, localMean_, CV_32F, {kLocalMeanPx, kLocalMeanPx});
        blurred_ -= localMean_;
        double cross = 0.0, squaresS = 0.0, squaresP = 0.0;
        for (int y = 0; y < box_.height; ++y) {
            const float* s = subtraction_.ptr<float>(y);
            const float* p = blurred_.ptr<float>(y);
            const uchar* inside = inRegion_.ptr<uchar>(y);
            float rowCross = 0.0f, rowS = 0.0f, rowP = 0.0f;
            for (int x = 0; x < box_.width; ++x)
                if (inside[x]) {
                    rowCross += s[x] * p[x];
                    rowS += s[x] * s[x];
                    rowP += p[x] * p[x];
                }
            cross += rowCross;
            squaresS += rowS;
            squaresP += rowP;
        }
        // A pair taken the wrong way round shows the code negated: its blur is the same.
        correlation[i] =
            squaresS > 0.0 && squaresP > 0.0 ? std::abs(cross) / std::sqrt(squaresS * squaresP) : 0.0;
    }
    int best = 0;
    for (int i = 1; i < kCandidates; ++i)
        if (correlation[i] > correlation[best])
            best = i;
    if (correlation[best] < kSignificance * chance_ || best == kCandidates - 1)
        return std::nullopt;
    if (best == 0)
        return 0.0;
    // The peak between the best candidate and its neighbours, from the parabola through the three.
    const double left = correlation[best - 1], centre = correlation[best], right = correlation[best + 1];
    const double curvature = left - 2.0 * centre + right;
    const double offset = curvature < 0.0 ? 0.5 * (left - right) / curvature : 0.0;
    return (best + offset) * kStepPx;
}

}  // namespace everytouch::core

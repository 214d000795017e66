#include "core/shifted_code_match.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace everytouch::core {

void ShiftedCodeMatcher::setCode(const cv::Mat& predicted) {
    CV_Assert(predicted.type() == CV_32FC1 && !predicted.empty());
    const int rows = predicted.rows, cols = predicted.cols;
    phases_[0][0] = predicted.clone();
    for (int fy = 0; fy < 2; ++fy)
        for (int fx = 0; fx < 2; ++fx) {
            if (fx == 0 && fy == 0)
                continue;
            cv::Mat& phase = phases_[fy][fx];
            phase.create(rows, cols, CV_32FC1);
            for (int y = 0; y < rows; ++y) {
                const float* here = predicted.ptr<float>(y);
                const float* below = predicted.ptr<float>(std::min(y + fy, rows - 1));
                float* out = phase.ptr<float>(y);
                for (int x = 0; x < cols; ++x) {
                    const int right = std::min(x + fx, cols - 1);
                    out[x] = 0.25f * (here[x] + here[right] + below[x] + below[right]);
                }
            }
        }
}

float ShiftedCodeMatcher::correlationAt(const cv::Mat& subtraction, const std::vector<cv::Point>& blocks,
                                        int blockPx, int halfStepsX, int halfStepsY) const {
    // A shift of k half pixels is floor(k / 2) whole pixels and a half when k is odd.
    const int wholeX = halfStepsX >= 0 ? halfStepsX / 2 : -((-halfStepsX + 1) / 2);
    const int wholeY = halfStepsY >= 0 ? halfStepsY / 2 : -((-halfStepsY + 1) / 2);
    const cv::Mat& code = phases_[halfStepsY - 2 * wholeY][halfStepsX - 2 * wholeX];
    const int rows = code.rows, cols = code.cols;
    const float perBlock = 1.0f / static_cast<float>(blockPx * blockPx);
    double covariance = 0.0, varianceS = 0.0, varianceCode = 0.0;
    for (const cv::Point& block : blocks) {
        float sumS = 0.0f, sumP = 0.0f, sumSP = 0.0f, sumSS = 0.0f, sumPP = 0.0f;
        for (int y = block.y; y < block.y + blockPx; ++y) {
            const short* s = subtraction.ptr<short>(y);
            const float* p = code.ptr<float>(std::clamp(y + wholeY, 0, rows - 1));
            for (int x = block.x; x < block.x + blockPx; ++x) {
                const float value = s[x], predicted = p[std::clamp(x + wholeX, 0, cols - 1)];
                sumS += value;
                sumP += predicted;
                sumSP += value * predicted;
                sumSS += value * value;
                sumPP += predicted * predicted;
            }
        }
        covariance += sumSP - sumS * sumP * perBlock;
        varianceS += sumSS - sumS * sumS * perBlock;
        varianceCode += sumPP - sumP * sumP * perBlock;
    }
    const double denominator = std::sqrt(varianceS * varianceCode);
    return denominator > 0.0 ? static_cast<float>(covariance / denominator) : 0.0f;
}

CodeShiftMatch ShiftedCodeMatcher::bestMatch(const cv::Mat& subtraction, const std::vector<cv::Point>& blocks,
                                             int blockPx, double radiusPx) const {
    CV_Assert(hasCode() && subtraction.type() == CV_16SC1 && subtraction.size() == phases_[0][0].size());
    CodeShiftMatch best;
    if (blocks.empty())
        return best;
    int bestX = 0, bestY = 0;  // half pixels
    best.correlation = correlationAt(subtraction, blocks, blockPx, 0, 0);
    const int reach = static_cast<int>(std::floor(radiusPx));
    for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx) {
            if ((dx == 0 && dy == 0) || dx * dx + dy * dy > radiusPx * radiusPx)
                continue;
            const float r = correlationAt(subtraction, blocks, blockPx, 2 * dx, 2 * dy);
            if (r > best.correlation) {
                best.correlation = r;
                bestX = 2 * dx;
                bestY = 2 * dy;
            }
        }
    const int coarseX = bestX, coarseY = bestY;
    for (int hy = -1; hy <= 1; ++hy)
        for (int hx = -1; hx <= 1; ++hx) {
            if (hx == 0 && hy == 0)
                continue;
            const int x = coarseX + hx, y = coarseY + hy;
            if (0.25 * (x * x + y * y) > radiusPx * radiusPx)
                continue;
            const float r = correlationAt(subtraction, blocks, blockPx, x, y);
            if (r > best.correlation) {
                best.correlation = r;
                bestX = x;
                bestY = y;
            }
        }
    best.shiftX = 0.5f * static_cast<float>(bestX);
    best.shiftY = 0.5f * static_cast<float>(bestY);
    return best;
}

}  // namespace everytouch::core

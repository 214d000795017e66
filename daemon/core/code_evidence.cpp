#include "core/code_evidence.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace everytouch::core {

namespace {

// Per-block count, sum P and sum P^2 of the predicted code; blocks that reach outside the projection count 0.
void sumCode(const cv::Mat& predicted, int blockPx, cv::Mat& codeSums) {
    const int rows = predicted.rows / blockPx;
    const int cols = predicted.cols / blockPx;
    codeSums.create(rows, cols, CV_64FC3);
    for (int by = 0; by < rows; ++by)
        for (int bx = 0; bx < cols; ++bx) {
            double count = 0, sum = 0, sumSquares = 0;
            bool outside = false;
            for (int y = by * blockPx; y < (by + 1) * blockPx; ++y) {
                const float* p = predicted.ptr<float>(y) + bx * blockPx;
                for (int x = 0; x < blockPx; ++x) {
                    outside |= p[x] < 0.0f;
                    count += 1;
                    sum += p[x];
                    sumSquares += double(p[x]) * p[x];
                }
            }
            codeSums.at<cv::Vec3d>(by, bx) = outside ? cv::Vec3d(0, 0, 0) : cv::Vec3d(count, sum, sumSquares);
        }
}

}  // namespace

void measureCodeEvidence(const cv::Mat& subtraction, const TableCode& tableCode, CodeEvidence& evidence) {
    CV_Assert(subtraction.type() == CV_16SC1 && subtraction.size() == tableCode.predicted.size());
    const int blockPx = evidence.blockPx;
    const int rows = subtraction.rows / blockPx;
    const int cols = subtraction.cols / blockPx;
    if (evidence.codeOf != &tableCode.predicted || evidence.codeSums.size() != cv::Size(cols, rows)) {
        sumCode(tableCode.predicted, blockPx, evidence.codeSums);
        evidence.codeOf = &tableCode.predicted;
    }
    evidence.sums.create(rows, cols, CV_64FC3);
    for (int by = 0; by < rows; ++by) {
        cv::Vec3d* sums = evidence.sums.ptr<cv::Vec3d>(by);
        for (int bx = 0; bx < cols; ++bx)
            sums[bx] = cv::Vec3d(0, 0, 0);
        for (int y = by * blockPx; y < (by + 1) * blockPx; ++y) {
            const short* s = subtraction.ptr<short>(y);
            const float* p = tableCode.predicted.ptr<float>(y);
            for (int bx = 0; bx < cols; ++bx) {
                int sum = 0, sumSquares = 0;
                float cross = 0.0f;
                for (int x = bx * blockPx; x < (bx + 1) * blockPx; ++x) {
                    sum += s[x];
                    sumSquares += s[x] * s[x];
                    cross += s[x] * p[x];
                }
                sums[bx] += cv::Vec3d(sum, sumSquares, cross);
            }
        }
    }
    const int reach = evidence.windowBlocks / 2;
    const double pixelsPerWindow = double(blockPx) * blockPx * evidence.windowBlocks * evidence.windowBlocks;
    evidence.correlation.create(rows, cols, CV_32FC1);
    evidence.meanS.create(rows, cols, CV_32FC1);
    evidence.varianceS.create(rows, cols, CV_32FC1);
    evidence.varianceCode.create(rows, cols, CV_32FC1);
    for (int by = 0; by < rows; ++by)
        for (int bx = 0; bx < cols; ++bx) {
            // Each block's statistics are taken about its own means: the code's amplitude follows the
            // surface's albedo and the content's brightness, which change across a window (a printed line, a
            // stain); within a small block it is nearly constant, so the correlation measures the code's
            // pattern, not them.
            double sumS = 0, sumSquaresS = 0, count = 0, covariance = 0, varianceS = 0, varianceP = 0;
            for (int wy = by - reach; wy <= by + reach; ++wy)
                for (int wx = bx - reach; wx <= bx + reach; ++wx) {
                    if (wy < 0 || wy >= rows || wx < 0 || wx >= cols)
                        continue;
                    const cv::Vec3d& s = evidence.sums.at<cv::Vec3d>(wy, wx);
                    const cv::Vec3d& c = evidence.codeSums.at<cv::Vec3d>(wy, wx);
                    sumS += s[0];
                    sumSquaresS += s[1];
                    if (c[0] == 0)
                        continue;
                    count += c[0];
                    covariance += s[2] - s[0] * c[1] / c[0];
                    varianceS += s[1] - s[0] * s[0] / c[0];
                    varianceP += c[2] - c[1] * c[1] / c[0];
                }
            const double meanS = sumS / pixelsPerWindow;
            evidence.meanS.at<float>(by, bx) = static_cast<float>(meanS);
            evidence.varianceS.at<float>(by, bx) =
                static_cast<float>(std::max(0.0, sumSquaresS / pixelsPerWindow - meanS * meanS));
            evidence.varianceCode.at<float>(by, bx) =
                static_cast<float>(std::max(0.0, varianceP) / pixelsPerWindow);
            const double denominator = std::sqrt(std::max(0.0, varianceS) * std::max(0.0, varianceP));
            float& correlation = evidence.correlation.at<float>(by, bx);
            if (count < pixelsPerWindow - 0.5)
                correlation = std::numeric_limits<float>::quiet_NaN();
            else
                correlation = denominator > 0 ? static_cast<float>(covariance / denominator) : 0.0f;
        }
}

}  // namespace everytouch::core

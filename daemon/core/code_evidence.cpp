#include "core/code_evidence.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace everytouch::core {

namespace {

constexpr int kSums = 6;
using BlockSums = cv::Vec<double, kSums>;

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

void windowStatistics(const cv::Mat& integral, int side, int blockPx, CodeEvidence::Window& window) {
    const int rows = integral.rows - 1, cols = integral.cols - 1, reach = side / 2;
    window.pixels = side * side * blockPx * blockPx;
    window.correlation.create(rows, cols, CV_32FC1);
    window.meanS.create(rows, cols, CV_32FC1);
    window.varianceS.create(rows, cols, CV_32FC1);
    window.varianceCode.create(rows, cols, CV_32FC1);
    const double pixels = window.pixels;
    for (int by = 0; by < rows; ++by) {
        const int y0 = std::max(by - reach, 0), y1 = std::min(by + reach + 1, rows);
        const BlockSums* top = integral.ptr<BlockSums>(y0);
        const BlockSums* bottom = integral.ptr<BlockSums>(y1);
        for (int bx = 0; bx < cols; ++bx) {
            const int x0 = std::max(bx - reach, 0), x1 = std::min(bx + reach + 1, cols);
            const BlockSums w = bottom[x1] - bottom[x0] - top[x1] + top[x0];
            const double meanS = w[0] / pixels;
            window.meanS.at<float>(by, bx) = static_cast<float>(meanS);
            window.varianceS.at<float>(by, bx) =
                static_cast<float>(std::max(0.0, w[1] / pixels - meanS * meanS));
            window.varianceCode.at<float>(by, bx) = static_cast<float>(std::max(0.0, w[4]) / pixels);
            const double denominator = std::sqrt(std::max(0.0, w[3]) * std::max(0.0, w[4]));
            float& correlation = window.correlation.at<float>(by, bx);
            if (w[5] < pixels - 0.5)
                correlation =
                    std::numeric_limits<float>::quiet_NaN();  // off the code, or at the image's edge
            else
                correlation = denominator > 0 ? static_cast<float>(w[2] / denominator) : 0.0f;
        }
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
    // Each block's statistics are taken about its own means: the code's amplitude follows the surface's
    // albedo and the content's brightness, which change across a window (a printed line, a stain); within a
    // small block it is nearly constant, so the correlation measures the code's pattern, not them.
    evidence.blockSums.create(rows, cols, CV_64FC(kSums));
    for (int by = 0; by < rows; ++by) {
        BlockSums* sums = evidence.blockSums.ptr<BlockSums>(by);
        const cv::Vec3d* code = evidence.codeSums.ptr<cv::Vec3d>(by);
        for (int bx = 0; bx < cols; ++bx) {
            int sum = 0, sumSquares = 0;
            float cross = 0.0f;
            for (int y = by * blockPx; y < (by + 1) * blockPx; ++y) {
                const short* s = subtraction.ptr<short>(y) + bx * blockPx;
                const float* p = tableCode.predicted.ptr<float>(y) + bx * blockPx;
                for (int x = 0; x < blockPx; ++x) {
                    sum += s[x];
                    sumSquares += s[x] * s[x];
                    cross += s[x] * p[x];
                }
            }
            const cv::Vec3d& c = code[bx];
            BlockSums& b = sums[bx];
            b[0] = sum;
            b[1] = sumSquares;
            if (c[0] > 0) {
                b[2] = cross - sum * c[1] / c[0];
                b[3] = sumSquares - double(sum) * sum / c[0];
                b[4] = c[2] - c[1] * c[1] / c[0];
            } else {
                b[2] = b[3] = b[4] = 0.0;
            }
            b[5] = c[0];
        }
    }
    evidence.integral.create(rows + 1, cols + 1, CV_64FC(kSums));
    BlockSums* firstRow = evidence.integral.ptr<BlockSums>(0);
    for (int bx = 0; bx <= cols; ++bx)
        firstRow[bx] = BlockSums::all(0);
    for (int by = 0; by < rows; ++by) {
        const BlockSums* sums = evidence.blockSums.ptr<BlockSums>(by);
        const BlockSums* above = evidence.integral.ptr<BlockSums>(by);
        BlockSums* out = evidence.integral.ptr<BlockSums>(by + 1);
        BlockSums rowSum = BlockSums::all(0);
        out[0] = BlockSums::all(0);
        for (int bx = 0; bx < cols; ++bx) {
            rowSum += sums[bx];
            out[bx + 1] = above[bx + 1] + rowSum;
        }
    }
    windowStatistics(evidence.integral, evidence.windowBlocks, blockPx, evidence.narrow);
    windowStatistics(evidence.integral, evidence.wideWindowBlocks, blockPx, evidence.wide);
}

}  // namespace everytouch::core

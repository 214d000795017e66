#include "core/code_evidence.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>

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

// Adds one row of S, its squares and its products with the predicted code P to the columns' sums, a vector
// of columns at a time (the whole evidence of a 648 x 488 frame: 595 us, against 739 us a block at a time;
// BM_CodeEvidence).
void addRow(const short* s, const float* p, int width, int* sum, int* sumSquares, float* cross) {
    int x = 0;
#if CV_SIMD128
    for (; x + 8 <= width; x += 8) {
        cv::v_int32x4 low, high;
        cv::v_expand(cv::v_load(s + x), low, high);
        cv::v_store(sum + x, cv::v_load(sum + x) + low);
        cv::v_store(sum + x + 4, cv::v_load(sum + x + 4) + high);
        cv::v_store(sumSquares + x, cv::v_load(sumSquares + x) + low * low);
        cv::v_store(sumSquares + x + 4, cv::v_load(sumSquares + x + 4) + high * high);
        cv::v_store(cross + x, cv::v_load(cross + x) + cv::v_cvt_f32(low) * cv::v_load(p + x));
        cv::v_store(cross + x + 4, cv::v_load(cross + x + 4) + cv::v_cvt_f32(high) * cv::v_load(p + x + 4));
    }
#endif
    for (; x < width; ++x) {
        sum[x] += s[x];
        sumSquares[x] += s[x] * s[x];
        cross[x] += static_cast<float>(s[x]) * p[x];
    }
}

// The statistics of the window of side x side blocks centred on (bx, by), from the integral of the blocks'
// sums; it is clipped at the grid's edges, where its pixels fall short of a whole window's (NaN).
WindowStatistics statisticsAt(const cv::Mat& integral, int side, int pixels, int by, int bx) {
    const int rows = integral.rows - 1, cols = integral.cols - 1, reach = side / 2;
    const double* top = integral.ptr<double>(std::max(by - reach, 0));
    const double* bottom = integral.ptr<double>(std::min(by + reach + 1, rows));
    const int x0 = std::max(bx - reach, 0) * kSums, x1 = std::min(bx + reach + 1, cols) * kSums;
    double w[kSums];
    for (int k = 0; k < kSums; ++k)
        w[k] = bottom[x1 + k] - bottom[x0 + k] - top[x1 + k] + top[x0 + k];
    const double perPixel = 1.0 / pixels;
    const double meanS = w[0] * perPixel;
    WindowStatistics statistics;
    statistics.meanS = static_cast<float>(meanS);
    statistics.varianceS = static_cast<float>(std::max(0.0, w[1] * perPixel - meanS * meanS));
    statistics.varianceCode = static_cast<float>(std::max(0.0, w[4]) * perPixel);
    // In single precision: the correlation is kept as a float, and a double's square root and division
    // cost several times a float's.
    const float denominator =
        std::sqrt(static_cast<float>(std::max(0.0, w[3])) * static_cast<float>(std::max(0.0, w[4])));
    if (w[5] < pixels - 0.5)
        statistics.correlation = std::numeric_limits<float>::quiet_NaN();  // off the code, or at the edge
    else
        statistics.correlation = denominator > 0 ? static_cast<float>(w[2]) / denominator : 0.0f;
    return statistics;
}

void windowStatistics(const cv::Mat& integral, int side, int blockPx, CodeEvidence::Window& window) {
    const int rows = integral.rows - 1, cols = integral.cols - 1;
    window.pixels = side * side * blockPx * blockPx;
    window.correlation.create(rows, cols, CV_32FC1);
    window.meanS.create(rows, cols, CV_32FC1);
    window.varianceS.create(rows, cols, CV_32FC1);
    window.varianceCode.create(rows, cols, CV_32FC1);
    for (int by = 0; by < rows; ++by) {
        float* meanS = window.meanS.ptr<float>(by);
        float* varianceS = window.varianceS.ptr<float>(by);
        float* varianceCode = window.varianceCode.ptr<float>(by);
        float* correlation = window.correlation.ptr<float>(by);
        for (int bx = 0; bx < cols; ++bx) {
            const WindowStatistics statistics = statisticsAt(integral, side, window.pixels, by, bx);
            meanS[bx] = statistics.meanS;
            varianceS[bx] = statistics.varianceS;
            varianceCode[bx] = statistics.varianceCode;
            correlation[bx] = statistics.correlation;
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
    // A row of blocks at a time: each pixel column's sums over the block's rows, then each block's over its
    // columns.
    const int width = cols * blockPx;
    evidence.columnSum.resize(static_cast<std::size_t>(width));
    evidence.columnSumSquares.resize(static_cast<std::size_t>(width));
    evidence.columnCross.resize(static_cast<std::size_t>(width));
    int* columnSum = evidence.columnSum.data();
    int* columnSumSquares = evidence.columnSumSquares.data();
    float* columnCross = evidence.columnCross.data();
    for (int by = 0; by < rows; ++by) {
        std::fill_n(columnSum, width, 0);
        std::fill_n(columnSumSquares, width, 0);
        std::fill_n(columnCross, width, 0.0f);
        for (int y = by * blockPx; y < (by + 1) * blockPx; ++y)
            addRow(subtraction.ptr<short>(y), tableCode.predicted.ptr<float>(y), width, columnSum,
                   columnSumSquares, columnCross);
        BlockSums* sums = evidence.blockSums.ptr<BlockSums>(by);
        const cv::Vec3d* code = evidence.codeSums.ptr<cv::Vec3d>(by);
        for (int bx = 0; bx < cols; ++bx) {
            int sum = 0, sumSquares = 0;
            float cross = 0.0f;
            for (int x = bx * blockPx; x < (bx + 1) * blockPx; ++x) {
                sum += columnSum[x];
                sumSquares += columnSumSquares[x];
                cross += columnCross[x];
            }
            const cv::Vec3d& c = code[bx];
            BlockSums& b = sums[bx];
            b[0] = sum;
            b[1] = sumSquares;
            if (c[0] > 0) {
                // A block's pixel count, a power of two at the default block size: its reciprocal is exact.
                const double perPixel = 1.0 / c[0];
                b[2] = cross - sum * c[1] * perPixel;
                b[3] = sumSquares - double(sum) * sum * perPixel;
                b[4] = c[2] - c[1] * c[1] * perPixel;
            } else {
                b[2] = b[3] = b[4] = 0.0;
            }
            b[5] = c[0];
        }
    }
    evidence.integral.create(rows + 1, cols + 1, CV_64FC(kSums));
    std::fill_n(evidence.integral.ptr<double>(0), (cols + 1) * kSums, 0.0);
    for (int by = 0; by < rows; ++by) {
        const double* sums = evidence.blockSums.ptr<double>(by);
        const double* above = evidence.integral.ptr<double>(by);
        double* out = evidence.integral.ptr<double>(by + 1);
        double rowSum[kSums] = {};
        std::fill_n(out, kSums, 0.0);
        for (int i = 0; i < cols * kSums; i += kSums)
            for (int k = 0; k < kSums; ++k) {
                rowSum[k] += sums[i + k];
                out[i + kSums + k] = above[i + kSums + k] + rowSum[k];
            }
    }
    windowStatistics(evidence.integral, evidence.windowBlocks, blockPx, evidence.narrow);
}

int CodeEvidence::widePixels() const {
    return wideWindowBlocks * wideWindowBlocks * blockPx * blockPx;
}

WindowStatistics CodeEvidence::wideAt(int by, int bx) const {
    return statisticsAt(integral, wideWindowBlocks, widePixels(), by, bx);
}

}  // namespace everytouch::core

#include "core/segment_confidence.h"

#include <algorithm>
#include <cmath>

namespace everytouch::core {

std::optional<std::string> ConfidenceOptions::validate() const {
    if (!std::isfinite(threshold) || threshold < 0.0)
        return "threshold: must be a non-negative number";
    return std::nullopt;
}

void selectConfidentRegions(const cv::Mat& labels, int count, const cv::Mat& saliency, const cv::Rect& roi,
                            cv::Size imageSize, const ConfidenceOptions& options, ConfidenceScratch& scratch,
                            cv::Mat& mask) {
    CV_Assert(labels.type() == CV_32SC1 && saliency.type() == CV_32FC1 && labels.size() == saliency.size());
    scratch.saliencySum.assign(count, 0.0);
    scratch.area.assign(count, 0);
    scratch.sides.assign(count, 0);
    scratch.adjacency.clear();
    enum Side { Left = 1, Right = 2, Top = 4, Bottom = 8 };
    for (int y = 0; y < labels.rows; ++y) {
        const int* row = labels.ptr<int>(y);
        const int* below = y + 1 < labels.rows ? labels.ptr<int>(y + 1) : nullptr;
        const float* s = saliency.ptr<float>(y);
        for (int x = 0; x < labels.cols; ++x) {
            const int k = row[x];
            scratch.saliencySum[k] += s[x];
            ++scratch.area[k];
            if (x + 1 < labels.cols && row[x + 1] != k)
                scratch.adjacency.emplace_back(std::min(k, row[x + 1]), std::max(k, row[x + 1]));
            if (below && below[x] != k)
                scratch.adjacency.emplace_back(std::min(k, below[x]), std::max(k, below[x]));
        }
    }
    const auto markSide = [&](int x, int y, int side) { scratch.sides[labels.at<int>(y, x)] |= side; };
    if (roi.x == 0)
        for (int y = 0; y < labels.rows; ++y)
            markSide(0, y, Left);
    if (roi.x + roi.width == imageSize.width)
        for (int y = 0; y < labels.rows; ++y)
            markSide(labels.cols - 1, y, Right);
    if (roi.y == 0)
        for (int x = 0; x < labels.cols; ++x)
            markSide(x, 0, Top);
    if (roi.y + roi.height == imageSize.height)
        for (int x = 0; x < labels.cols; ++x)
            markSide(x, labels.rows - 1, Bottom);

    std::sort(scratch.adjacency.begin(), scratch.adjacency.end());
    scratch.adjacency.erase(std::unique(scratch.adjacency.begin(), scratch.adjacency.end()),
                            scratch.adjacency.end());
    scratch.neighbourSaliency.assign(count, 0.0);
    scratch.neighbourCount.assign(count, 0);
    const auto meanSaliency = [&](int k) { return scratch.saliencySum[k] / std::max(1, scratch.area[k]); };
    for (const auto& [a, b] : scratch.adjacency) {
        scratch.neighbourSaliency[a] += meanSaliency(b);
        scratch.neighbourSaliency[b] += meanSaliency(a);
        ++scratch.neighbourCount[a];
        ++scratch.neighbourCount[b];
    }
    const int largest = count > 0 ? *std::max_element(scratch.area.begin(), scratch.area.end()) : 1;
    scratch.isHand.assign(count, 0);
    for (int k = 0; k < count; ++k) {
        const int neighbours = scratch.neighbourCount[k];
        const double neighbourMean = neighbours > 0 ? scratch.neighbourSaliency[k] / neighbours : 0.0;
        const double alpha = neighbours == 1 ? 0.25 : 0.5;
        const double beta = neighbours == 1 ? 0.5 : 0.25;
        const double gamma = 0.25;
        const int sides = __builtin_popcount(static_cast<unsigned>(scratch.sides[k]));
        const double confidence =
            std::exp(-std::max(sides - 1, 0)) * (alpha * meanSaliency(k) + beta * neighbourMean +
                                                 gamma * static_cast<double>(scratch.area[k]) / largest);
        scratch.isHand[k] = confidence > options.threshold;
    }
    mask.create(labels.size(), CV_8UC1);
    for (int y = 0; y < labels.rows; ++y) {
        const int* row = labels.ptr<int>(y);
        uchar* out = mask.ptr<uchar>(y);
        for (int x = 0; x < labels.cols; ++x)
            out[x] = scratch.isHand[row[x]] ? 255 : 0;
    }
}

}  // namespace everytouch::core

#include "core/mean_shift_segmentation.h"

#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace everytouch::core {

namespace {

int findRoot(std::vector<int>& parent, int i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

void unite(std::vector<int>& parent, std::vector<int>& size, int a, int b) {
    a = findRoot(parent, a);
    b = findRoot(parent, b);
    if (a == b)
        return;
    if (size[a] < size[b])
        std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
}

float colourDistanceSquared(const cv::Vec3b& a, const cv::Vec3b& b) {
    const float d0 = float(a[0]) - b[0], d1 = float(a[1]) - b[1], d2 = float(a[2]) - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

float colourDistanceSquared(const cv::Vec3f& a, const cv::Vec3f& b) {
    const cv::Vec3f d = a - b;
    return d.dot(d);
}

}  // namespace

std::optional<std::string> MeanShiftOptions::validate() const {
    if (spatialRadius < 1)
        return "spatialRadius: must be at least 1 pixel";
    if (!(colourRadius > 0.0) || !std::isfinite(colourRadius))
        return "colourRadius: must be a positive number of colour levels";
    if (minRegionPixels < 1)
        return "minRegionPixels: must be at least 1";
    return std::nullopt;
}

int segmentMeanShift(const cv::Mat& image, const MeanShiftOptions& options, MeanShiftScratch& scratch,
                     cv::Mat& labels) {
    CV_Assert(image.type() == CV_8UC3);
    cv::pyrMeanShiftFiltering(image, scratch.filtered, options.spatialRadius, options.colourRadius, 0);
    const cv::Mat& filtered = scratch.filtered;
    const int width = image.cols, height = image.rows, pixels = width * height;
    std::vector<int>& parent = scratch.parent;
    std::vector<int>& size = scratch.size;
    parent.resize(pixels);
    size.assign(pixels, 1);
    for (int i = 0; i < pixels; ++i)
        parent[i] = i;

    // Neighbours whose smoothed colours lie within hr share a region.
    const float radiusSquared = static_cast<float>(options.colourRadius * options.colourRadius);
    for (int y = 0; y < height; ++y) {
        const cv::Vec3b* row = filtered.ptr<cv::Vec3b>(y);
        const cv::Vec3b* below = y + 1 < height ? filtered.ptr<cv::Vec3b>(y + 1) : nullptr;
        for (int x = 0; x < width; ++x) {
            if (x + 1 < width && colourDistanceSquared(row[x], row[x + 1]) <= radiusSquared)
                unite(parent, size, y * width + x, y * width + x + 1);
            if (below && colourDistanceSquared(row[x], below[x]) <= radiusSquared)
                unite(parent, size, y * width + x, (y + 1) * width + x);
        }
    }

    // Regions smaller than M join the touching region of the nearest mean colour.
    std::vector<cv::Vec3f>& colourSum = scratch.colourSum;
    colourSum.assign(pixels, cv::Vec3f(0, 0, 0));
    for (int y = 0; y < height; ++y) {
        const cv::Vec3b* row = filtered.ptr<cv::Vec3b>(y);
        for (int x = 0; x < width; ++x)
            colourSum[findRoot(parent, y * width + x)] += cv::Vec3f(row[x]);
    }
    const auto mean = [&](int root) { return colourSum[root] / static_cast<float>(size[root]); };
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const int root = findRoot(parent, y * width + x);
            if (size[root] >= options.minRegionPixels)
                continue;
            int best = -1;
            float bestDistance = std::numeric_limits<float>::max();
            const int neighbours[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
            for (const auto& [nx, ny] : neighbours) {
                if (nx < 0 || ny < 0 || nx >= width || ny >= height)
                    continue;
                const int other = findRoot(parent, ny * width + nx);
                if (other == root)
                    continue;
                if (const float d = colourDistanceSquared(mean(root), mean(other)); d < bestDistance) {
                    bestDistance = d;
                    best = other;
                }
            }
            if (best < 0)
                continue;
            const cv::Vec3f sum = colourSum[root] + colourSum[best];
            unite(parent, size, root, best);
            colourSum[findRoot(parent, root)] = sum;
        }

    labels.create(height, width, CV_32SC1);
    std::vector<int>& compact = scratch.compact;
    compact.assign(pixels, -1);
    int count = 0;
    for (int y = 0; y < height; ++y) {
        int* out = labels.ptr<int>(y);
        for (int x = 0; x < width; ++x) {
            const int root = findRoot(parent, y * width + x);
            if (compact[root] < 0)
                compact[root] = count++;
            out[x] = compact[root];
        }
    }
    return count;
}

}  // namespace everytouch::core

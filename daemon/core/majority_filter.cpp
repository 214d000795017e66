#include "core/majority_filter.h"

#include <algorithm>
#include <stdexcept>

namespace everytouch::core {

void voteByMajority(cv::Mat& mask, cv::Rect region, int radius, MajorityScratch& scratch) {
    CV_Assert(mask.type() == CV_8UC1);
    if (radius < 0)
        throw std::invalid_argument("voteByMajority: the radius must not be negative");
    region &= cv::Rect(0, 0, mask.cols, mask.rows);
    if (region.empty() || radius == 0)
        return;
    // The window reaches `radius` beyond the region: the counts cover that margin too.
    const cv::Rect counted = cv::Rect(region.x - radius, region.y - radius, region.width + 2 * radius,
                                      region.height + 2 * radius) &
                             cv::Rect(0, 0, mask.cols, mask.rows);
    // Sized for the whole mask, so that regions of changing size allocate nothing.
    scratch.counts.create(mask.rows + 1, mask.cols + 1, CV_32SC1);
    std::fill_n(scratch.counts.ptr<int>(0), counted.width + 1, 0);
    for (int y = 0; y < counted.height; ++y) {
        const uchar* in = mask.ptr<uchar>(counted.y + y) + counted.x;
        const int* above = scratch.counts.ptr<int>(y);
        int* row = scratch.counts.ptr<int>(y + 1);
        row[0] = 0;
        int sum = 0;
        for (int x = 0; x < counted.width; ++x) {
            sum += in[x] != 0;
            row[x + 1] = above[x + 1] + sum;
        }
    }
    // Every window holds (2 radius + 1)^2 pixels, the ones beyond the image unset.
    const int side = 2 * radius + 1;
    const int majority = side * side / 2;
    for (int y = region.y; y < region.y + region.height; ++y) {
        const int top = std::max(y - radius, counted.y) - counted.y;
        const int bottom = std::min(y + radius + 1, counted.y + counted.height) - counted.y;
        const int* upper = scratch.counts.ptr<int>(top);
        const int* lower = scratch.counts.ptr<int>(bottom);
        uchar* out = mask.ptr<uchar>(y);
        for (int x = region.x; x < region.x + region.width; ++x) {
            const int left = std::max(x - radius, counted.x) - counted.x;
            const int right = std::min(x + radius + 1, counted.x + counted.width) - counted.x;
            const int set = lower[right] - lower[left] - upper[right] + upper[left];
            out[x] = set > majority ? 255 : 0;
        }
    }
}

}  // namespace everytouch::core

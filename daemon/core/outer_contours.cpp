#include "core/outer_contours.h"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace everytouch::core {

namespace {

// The eight neighbours in clockwise order as seen in the image (y down), starting east.
constexpr int kDx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int kDy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
constexpr int kWest = 4;

// First column at or after `x` in `row` whose byte is (`nonzero`) or is not, or `width`. Whole words of
// equal bytes are skipped at once: a hand covers a small part of the frame and a run inside it is long.
int skipTo(const std::uint8_t* row, int x, int width, bool nonzero) {
    const std::uint64_t skipped = nonzero ? 0 : ~std::uint64_t{0};
    while (x < width && (x & 7) != 0) {
        if ((row[x] != 0) == nonzero)
            return x;
        ++x;
    }
    // Background before a hand and the inside of a hand come in long runs: four words at a time there.
    while (x + 32 <= width) {
        std::uint64_t words[4];
        std::memcpy(words, row + x, sizeof words);
        const std::uint64_t any = words[0] | words[1] | words[2] | words[3];
        const std::uint64_t all = words[0] & words[1] & words[2] & words[3];
        if (nonzero ? any != 0 : all != ~std::uint64_t{0})
            break;
        x += 32;
    }
    while (x + 8 <= width) {
        std::uint64_t word;
        std::memcpy(&word, row + x, sizeof word);
        // Inside a region the bytes need not be 255, only nonzero: a word is skipped whole only when it is
        // all zero (looking for nonzero) or has no zero byte (looking for zero).
        const bool allSkipped =
            nonzero ? word == skipped : ((word - 0x0101010101010101ULL) & ~word & 0x8080808080808080ULL) == 0;
        if (!allSkipped)
            break;
        x += 8;
    }
    while (x < width && (row[x] != 0) != nonzero)
        ++x;
    return x;
}

// Follows the boundary that starts at `start`, whose west neighbour is outside the region, appending its
// pixels to `points` and marking them in `visited` (Moore neighbour tracing, stopped when the first step
// is about to repeat). Returns twice the signed area of the polygon through the pixel centres.
long traceBoundary(const cv::Mat& mask, cv::Point start, std::vector<cv::Point>& points, cv::Mat& visited) {
    const int width = mask.cols, height = mask.rows;
    auto inside = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < width && y < height && mask.ptr<std::uint8_t>(y)[x] != 0;
    };
    // The first neighbour inside, clockwise after direction `from`, which is outside; -1 for a lone pixel.
    auto next = [&](cv::Point at, int from) {
        for (int i = 1; i <= 8; ++i) {
            const int direction = (from + i) & 7;
            if (inside(at.x + kDx[direction], at.y + kDy[direction]))
                return direction;
        }
        return -1;
    };
    auto visit = [&](cv::Point p) {
        points.push_back(p);
        visited.ptr<std::uint8_t>(p.y)[p.x] = 1;
    };

    visit(start);
    const int firstDirection = next(start, kWest);
    if (firstDirection < 0)
        return 0;
    long doubleArea = 0;
    cv::Point at = start;
    int direction = firstDirection;
    for (;;) {
        const cv::Point to(at.x + kDx[direction], at.y + kDy[direction]);
        doubleArea += static_cast<long>(at.x) * to.y - static_cast<long>(to.x) * at.y;
        visit(to);
        // The pixel examined just before `to` is outside; seen from `to` it lies in this direction.
        const int outside = (direction + 6 - (direction & 1)) & 7;
        at = to;
        direction = next(at, outside);
        if (at == start && direction == firstDirection)
            break;
    }
    points.pop_back();  // the start, reached again
    return doubleArea;
}

}  // namespace

void findOuterContours(const cv::Mat& mask, double minArea, OuterContours& contours) {
    if (mask.type() != CV_8UC1)
        throw std::invalid_argument("hand mask: must be CV_8UC1");
    contours.points.clear();
    contours.contours.clear();
    if (contours.visited.size() != mask.size() || contours.visited.type() != CV_8UC1)
        contours.visited = cv::Mat::zeros(mask.size(), CV_8UC1);
    for (int y = 0; y < mask.rows; ++y) {
        const std::uint8_t* row = mask.ptr<std::uint8_t>(y);
        const std::uint8_t* seen = contours.visited.ptr<std::uint8_t>(y);
        for (int x = skipTo(row, 0, mask.cols, true); x < mask.cols;
             x = skipTo(row, skipTo(row, x, mask.cols, false), mask.cols, true)) {
            // `x` starts a run, so its west neighbour is outside: a boundary starts here unless one already
            // passed. The first pixel of a region in raster order starts its outer boundary; a later start is
            // the boundary of a hole, which runs the other way round.
            if (seen[x] != 0)
                continue;
            const int begin = static_cast<int>(contours.points.size());
            const double area =
                0.5 * static_cast<double>(traceBoundary(mask, {x, y}, contours.points, contours.visited));
            if (area >= minArea && area > 0.0)
                contours.contours.push_back({begin, static_cast<int>(contours.points.size()) - begin, area});
        }
    }
    for (const cv::Point& p : contours.points)
        contours.visited.ptr<std::uint8_t>(p.y)[p.x] = 0;
}

}  // namespace everytouch::core

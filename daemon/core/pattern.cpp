#include "core/pattern.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "core/codeword_search.h"

namespace everytouch::core {

namespace {

// Anchor ids are row-major positions in codedRegion.
struct AnchorGrid {
    int columns;
    int rows;
    int window;

    int count() const { return columns * rows; }
    int id(int x, int y) const { return (y - (window - 1)) * columns + (x - (window - 1)); }
    int x(int id) const { return id % columns + window - 1; }
    int y(int id) const { return id / columns + window - 1; }
    int chebyshev(int a, int b) const { return std::max(std::abs(x(a) - x(b)), std::abs(y(a) - y(b))); }
};

AnchorGrid anchorGrid(cv::Size size, int window) {
    return {size.width - window + 1, size.height - window + 1, window};
}

// Counts of conflicting pairs by distance, compared lexicographically from distance 0 up: fewer identical
// pairs first, then fewer pairs at distance 1, and so on. A repair step must make this strictly smaller, so a
// minimum distance once reached is never lost.
using ConflictCounts = std::array<int, kMaxCodewordSearchRadius + 1>;

class PatternRepair {
public:
    PatternRepair(cv::Mat& bits, const PatternOptions& options)
        : bits_(bits),
          grid_(anchorGrid(bits.size(), options.window)),
          neighbourRadius_(options.neighbourRadius),
          rng_(options.seed ^ 0x5DEECE66Dull) {}

    // Raises the minimum distance one level at a time: first no identical windows, then none at distance 1,
    // and so on. Lower levels are cheaper to search and their pairs the more harmful, and a level once
    // reached is kept by every later flip. Stops at minDistance or when the trial budget is spent.
    void run(int minDistance, long long trialBudget) {
        long long trials = 0;
        for (int radius = 0; radius < minDistance && trials < trialBudget; ++radius)
            repairLevel(radius, trialBudget, trials);
    }

private:
    void repairLevel(int radius, long long trialBudget, long long& trials) {
        const std::vector<std::uint64_t> codes = windowCodes(bits_, grid_.window);
        std::vector<char> conflicted(codes.size(), 0);
        forEachPairWithin(codes, grid_.window * grid_.window, radius, [&](int a, int b, int distance) {
            if (conflicting(a, b, distance))
                conflicted[a] = conflicted[b] = 1;
        });
        std::vector<int> queue;
        for (int id = 0; id < grid_.count(); ++id)
            if (conflicted[id])
                queue.push_back(id);
        if (queue.empty())
            return;
        table_.emplace(grid_.window * grid_.window, grid_.count(), radius);
        for (int id = 0; id < grid_.count(); ++id)
            table_->insert(id, codes[id]);
        std::vector<cv::Point> pixels;
        while (!queue.empty() && trials < trialBudget) {
            const int id = queue.back();
            queue.pop_back();
            if (!inConflict(id))
                continue;
            windowPixels(id, pixels);
            std::shuffle(pixels.begin(), pixels.end(), rng_);
            for (const cv::Point& pixel : pixels) {
                ++trials;
                const std::optional<ConflictCounts> left = flipIfBetter(pixel);
                if (!left)
                    continue;
                if (*left != ConflictCounts{})
                    forEachAffected(pixel, [&](int affected) {
                        if (inConflict(affected))
                            queue.push_back(affected);
                    });
                break;
            }
        }
    }

private:
    // Flips `pixel` and keeps the flip if it leaves fewer conflicts (ConflictCounts order); then returns the
    // conflicts left among the windows containing the pixel. The window being repaired is in conflict and
    // contains the pixel, so a flip that leaves none is better without counting the state before.
    std::optional<ConflictCounts> flipIfBetter(cv::Point pixel) {
        flip(pixel);
        const ConflictCounts after = affectedConflicts(pixel);
        if (after == ConflictCounts{})
            return after;
        flip(pixel);
        if (after < affectedConflicts(pixel)) {
            flip(pixel);
            return after;
        }
        return std::nullopt;
    }

    bool conflicting(int a, int b, int distance) const {
        return a != b && (distance == 0 || grid_.chebyshev(a, b) > neighbourRadius_);
    }

    bool inConflict(int id) const {
        bool found = false;
        table_->forEachWithin(table_->code(id), [&](int other, int distance) {
            found = found || conflicting(id, other, distance);
        });
        return found;
    }

    void windowPixels(int id, std::vector<cv::Point>& pixels) const {
        pixels.clear();
        for (int dy = 0; dy < grid_.window; ++dy)
            for (int dx = 0; dx < grid_.window; ++dx)
                pixels.emplace_back(grid_.x(id) - dx, grid_.y(id) - dy);
    }

    // Anchors whose window contains `pixel`.
    cv::Rect affectedAnchors(cv::Point pixel) const {
        const int x0 = std::max(pixel.x, grid_.window - 1);
        const int y0 = std::max(pixel.y, grid_.window - 1);
        const int x1 = std::min(pixel.x + grid_.window - 1, bits_.cols - 1);
        const int y1 = std::min(pixel.y + grid_.window - 1, bits_.rows - 1);
        return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
    }

    template <typename Visit>
    void forEachAffected(cv::Point pixel, Visit&& visit) const {
        const cv::Rect anchors = affectedAnchors(pixel);
        for (int y = anchors.y; y < anchors.y + anchors.height; ++y)
            for (int x = anchors.x; x < anchors.x + anchors.width; ++x)
                visit(grid_.id(x, y));
    }

    // Every conflicting pair with at least one anchor whose window contains `pixel`, each pair once.
    ConflictCounts affectedConflicts(cv::Point pixel) const {
        const cv::Rect anchors = affectedAnchors(pixel);
        ConflictCounts counts{};
        forEachAffected(pixel, [&](int id) {
            table_->forEachWithin(table_->code(id), [&](int other, int distance) {
                if (!conflicting(id, other, distance))
                    return;
                if (other < id && anchors.contains({grid_.x(other), grid_.y(other)}))
                    return;
                ++counts[distance];
            });
        });
        return counts;
    }

    void flip(cv::Point pixel) {
        bits_.at<uchar>(pixel) ^= 1;
        forEachAffected(pixel, [&](int id) {
            const int bit = (pixel.y - (grid_.y(id) - grid_.window + 1)) * grid_.window +
                            (pixel.x - (grid_.x(id) - grid_.window + 1));
            const std::uint64_t code = table_->code(id) ^ (std::uint64_t{1} << bit);
            table_->remove(id);
            table_->insert(id, code);
        });
    }

    cv::Mat& bits_;
    AnchorGrid grid_;
    int neighbourRadius_;
    std::optional<NearCodewordTable> table_;  // the codewords, searched to the radius of the current level
    std::mt19937_64 rng_;
};

}  // namespace

std::optional<std::string> PatternOptions::validate() const {
    if (window < 2 || window > 8)
        return "window: must be 2..8 (window*window bits must fit in 64), got " + std::to_string(window);
    if (size.width < window || size.height < window)
        return "size: must be at least window x window pixels";
    const double windows = static_cast<double>(size.width - window + 1) * (size.height - window + 1);
    if (window * window < 64 && std::ldexp(1.0, window * window) < windows)
        return "window: " + std::to_string(window * window) + " bits cannot label " +
               std::to_string(static_cast<long long>(windows)) + " windows uniquely";
    if (minDistance < 0 || minDistance > kMaxCodewordSearchRadius + 1)
        return "minDistance: must be 0.." + std::to_string(kMaxCodewordSearchRadius + 1);
    if (neighbourRadius < 0 || neighbourRadius >= window)
        return "neighbourRadius: must be 0..window-1";
    if (!(repairTrialsPerWindow >= 0) || !std::isfinite(repairTrialsPerWindow))
        return "repairTrialsPerWindow: must be a non-negative number";
    return std::nullopt;
}

cv::Mat generatePattern(const PatternOptions& options) {
    if (auto problem = options.validate())
        throw std::invalid_argument("PatternOptions: " + *problem);
    cv::Mat bits(options.size, CV_8UC1);
    std::mt19937_64 random(options.seed);
    std::uint64_t word = 0;
    int available = 0;
    for (int y = 0; y < bits.rows; ++y) {
        uchar* row = bits.ptr<uchar>(y);
        for (int x = 0; x < bits.cols; ++x) {
            if (available == 0) {
                word = random();
                available = 64;
            }
            row[x] = static_cast<uchar>(word & 1);
            word >>= 1;
            --available;
        }
    }
    if (options.minDistance > 0) {
        PatternRepair repair(bits, options);
        const double windows = static_cast<double>(anchorGrid(options.size, options.window).count());
        repair.run(options.minDistance, static_cast<long long>(options.repairTrialsPerWindow * windows));
    }
    return bits;
}

cv::Rect codedRegion(cv::Size patternSize, int window) {
    return {window - 1, window - 1, std::max(0, patternSize.width - window + 1),
            std::max(0, patternSize.height - window + 1)};
}

std::uint64_t codeAt(const cv::Mat& pattern, cv::Point anchor, int window) {
    CV_Assert(pattern.type() == CV_8UC1 && codedRegion(pattern.size(), window).contains(anchor));
    std::uint64_t code = 0;
    int bit = 0;
    for (int y = anchor.y - window + 1; y <= anchor.y; ++y) {
        const uchar* row = pattern.ptr<uchar>(y);
        for (int x = anchor.x - window + 1; x <= anchor.x; ++x, ++bit)
            code |= std::uint64_t{row[x] != 0} << bit;
    }
    return code;
}

std::vector<std::uint64_t> windowCodes(const cv::Mat& pattern, int window) {
    CV_Assert(pattern.type() == CV_8UC1 && window >= 1 && window <= 8);
    const AnchorGrid grid = anchorGrid(pattern.size(), window);
    if (grid.columns <= 0 || grid.rows <= 0)
        return {};
    // columnCodes[x]: the codeword of the window anchored at (x, y), once y has reached window - 1.
    std::vector<std::uint64_t> columnCodes(pattern.cols, 0);
    std::vector<std::uint64_t> codes(static_cast<std::size_t>(grid.count()));
    const int topShift = window * (window - 1);
    for (int y = 0; y < pattern.rows; ++y) {
        const uchar* row = pattern.ptr<uchar>(y);
        std::uint64_t bitsOfRow = 0;  // the `window` bits of row y ending at column x, oldest lowest
        for (int x = 0; x < pattern.cols; ++x) {
            bitsOfRow = (bitsOfRow >> 1) | (std::uint64_t{row[x] != 0} << (window - 1));
            // Shifting the code down by one row drops its top row and makes room for this one at the bottom.
            columnCodes[x] = (columnCodes[x] >> window) | (bitsOfRow << topShift);
            if (x >= window - 1 && y >= window - 1)
                codes[static_cast<std::size_t>(grid.id(x, y))] = columnCodes[x];
        }
    }
    return codes;
}

PatternAnalysis analyzePattern(const cv::Mat& pattern, int window, int neighbourRadius, int samples,
                               std::uint64_t seed) {
    CV_Assert(samples > 0);
    PatternAnalysis analysis;
    const std::vector<std::uint64_t> codes = windowCodes(pattern, window);
    const AnchorGrid grid = anchorGrid(pattern.size(), window);
    const int count = grid.count();
    analysis.windowCount = codes.size();
    // Every window needs a window that is not its neighbour.
    CV_Assert(grid.columns > 0 && grid.rows > 0 &&
              (grid.columns > neighbourRadius + 1 || grid.rows > neighbourRadius + 1));

    std::vector<std::uint64_t> sorted = codes;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        const bool sameAsPrevious = i > 0 && sorted[i] == sorted[i - 1];
        const bool sameAsNext = i + 1 < sorted.size() && sorted[i] == sorted[i + 1];
        analysis.repeatedWindows += sameAsPrevious || sameAsNext;
    }

    auto counted = [&](int a, int b, int distance) {
        return distance == 0 || grid.chebyshev(a, b) > neighbourRadius;
    };
    analysis.closePairs.assign(kMaxCodewordSearchRadius + 1, 0);
    forEachPairWithin(codes, window * window, kMaxCodewordSearchRadius, [&](int a, int b, int distance) {
        if (counted(a, b, distance))
            ++analysis.closePairs[distance];
    });
    const auto firstClose = std::find_if(analysis.closePairs.begin(), analysis.closePairs.end(),
                                         [](std::size_t pairs) { return pairs > 0; });
    // Distance between `id` and its closest counted window, by exhaustive search.
    auto nearestDistance = [&](int id) {
        int nearest = std::numeric_limits<int>::max();
        for (int other = 0; other < count; ++other) {
            const int distance = std::popcount(codes[id] ^ codes[other]);
            if (other != id && distance < nearest && counted(id, other, distance))
                nearest = distance;
        }
        return nearest;
    };
    if (firstClose != analysis.closePairs.end()) {
        analysis.minDistance = static_cast<int>(firstClose - analysis.closePairs.begin());
    } else {
        analysis.minDistance = std::numeric_limits<int>::max();
        for (int id = 0; id < count; ++id)
            analysis.minDistance = std::min(analysis.minDistance, nearestDistance(id));
    }

    std::mt19937_64 random(seed);
    std::uniform_int_distribution<int> anyWindow(0, count - 1);
    double pairDistanceSum = 0;
    double nearestDistanceSum = 0;
    for (int sample = 0; sample < samples; ++sample) {
        int a = anyWindow(random);
        int b = anyWindow(random);
        while (a == b || grid.chebyshev(a, b) <= neighbourRadius)
            b = anyWindow(random);
        pairDistanceSum += std::popcount(codes[a] ^ codes[b]);
        nearestDistanceSum += nearestDistance(a);
    }
    analysis.samples = samples;
    analysis.meanDistance = pairDistanceSum / samples;
    analysis.meanNearestDistance = nearestDistanceSum / samples;
    return analysis;
}

}  // namespace everytouch::core

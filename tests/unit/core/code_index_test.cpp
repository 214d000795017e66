#include "core/code_index.h"

#include <bit>
#include <random>
#include <unordered_set>

#include <gtest/gtest.h>

#include "core/pattern.h"

namespace everytouch::core {
namespace {

// A quarter panel keeps the tests quick; the index does not care about the size.
const cv::Mat& quarterPanelPattern() {
    static const cv::Mat pattern = [] {
        PatternOptions options;
        options.size = {320, 240};
        return generatePattern(options);
    }();
    return pattern;
}

TEST(CodeIndex, FindsEveryWindowByItsExactCodeword) {
    const cv::Mat& pattern = quarterPanelPattern();
    const CodeIndex index(pattern, 6);
    const cv::Rect anchors = codedRegion(pattern.size(), 6);
    EXPECT_EQ(index.size(), static_cast<std::size_t>(anchors.area()));
    EXPECT_EQ(index.window(), 6);
    for (int y = anchors.y; y < anchors.br().y; ++y)
        for (int x = anchors.x; x < anchors.br().x; ++x)
            ASSERT_EQ(index.find(codeAt(pattern, {x, y}, 6)), std::optional<cv::Point>(cv::Point(x, y)));
}

TEST(CodeIndex, ACodewordNoWindowHasIsNotFound) {
    const cv::Mat& pattern = quarterPanelPattern();
    const CodeIndex index(pattern, 6);
    const std::vector<std::uint64_t> codes = windowCodes(pattern, 6);
    const std::unordered_set<std::uint64_t> present(codes.begin(), codes.end());
    std::mt19937_64 random(3);
    int absent = 0;
    while (absent < 100) {
        const std::uint64_t code = random() & ((std::uint64_t{1} << 36) - 1);
        if (present.contains(code))
            continue;
        EXPECT_EQ(index.find(code), std::nullopt);
        ++absent;
    }
}

ObservedCode corrupted(std::uint64_t code, int wrong, int unknown, std::mt19937_64& random) {
    ObservedCode observed{code, (std::uint64_t{1} << 36) - 1};
    std::uint64_t changed = 0;
    while (std::popcount(changed) < wrong + unknown)
        changed |= std::uint64_t{1} << (random() % 36);
    for (int i = 0; i < unknown; ++i) {
        const std::uint64_t bit = std::uint64_t{1} << std::countr_zero(changed);
        observed.known &= ~bit;
        changed &= ~bit;
    }
    observed.bits = (observed.bits ^ changed) & observed.known;
    return observed;
}

// With every pair of windows at least 4 bits apart, an observation with e wrong and u unknown bits is closer
// to its own window than to any other when 2e + u < 4.
TEST(CodeIndex, MatchFindsTheWindowWhenTheMinimumDistanceGuaranteesIt) {
    const cv::Mat& pattern = quarterPanelPattern();
    const CodeIndex index(pattern, 6);
    const cv::Rect anchors = codedRegion(pattern.size(), 6);
    std::mt19937_64 random(5);
    for (auto [wrong, unknown] : {std::pair{0, 0}, {0, 3}, {1, 0}, {1, 1}}) {
        for (int trial = 0; trial < 500; ++trial) {
            const cv::Point anchor(anchors.x + static_cast<int>(random() % anchors.width),
                                   anchors.y + static_cast<int>(random() % anchors.height));
            const ObservedCode observed = corrupted(codeAt(pattern, anchor, 6), wrong, unknown, random);
            const std::optional<CodeMatch> match = index.match(observed, 3);
            ASSERT_TRUE(match) << wrong << " wrong, " << unknown << " unknown";
            EXPECT_EQ(match->position, anchor) << wrong << " wrong, " << unknown << " unknown";
            EXPECT_EQ(match->mismatches, wrong);
            EXPECT_GT(match->runnerUpMismatches, match->mismatches);
        }
    }
}

// Beyond the guarantee the search still returns a window at least as close as the true one, and that is the
// true one unless another window happens to lie as close to the observation: with k known bits, about
// size() * sum_{j<=e} C(k, j) / 2^k windows do (74 025 windows, k = 32: 0.009 for e = 2, 0.095 for e = 3).
TEST(CodeIndex, MatchFindsTheClosestWindowBeyondTheGuarantee) {
    const cv::Mat& pattern = quarterPanelPattern();
    const CodeIndex index(pattern, 6);
    const cv::Rect anchors = codedRegion(pattern.size(), 6);
    std::mt19937_64 random(6);
    for (auto [wrong, expectedRight] : {std::pair{2, 0.97}, {3, 0.85}}) {
        int right = 0;
        const int trials = 2000;
        for (int trial = 0; trial < trials; ++trial) {
            const cv::Point anchor(anchors.x + static_cast<int>(random() % anchors.width),
                                   anchors.y + static_cast<int>(random() % anchors.height));
            const ObservedCode observed = corrupted(codeAt(pattern, anchor, 6), wrong, 4, random);
            const std::optional<CodeMatch> match = index.match(observed, 3);
            ASSERT_TRUE(match);
            EXPECT_LE(match->mismatches, wrong);
            right += match->position == anchor;
        }
        EXPECT_GT(right, expectedRight * trials) << wrong << " wrong bits";
        EXPECT_NEAR(index.chanceMatches(32, wrong), wrong == 2 ? 0.0091 : 0.0946, 0.0001);
    }
}

TEST(CodeIndex, MatchRejectsObservationsFartherThanAllowed) {
    const cv::Mat& pattern = quarterPanelPattern();
    const CodeIndex index(pattern, 6);
    const cv::Point anchor(100, 200);
    ObservedCode observed{codeAt(pattern, anchor, 6) ^ 0xFFull,
                          (std::uint64_t{1} << 36) - 1};  // 8 wrong bits
    const std::optional<CodeMatch> match = index.match(observed, 3);
    if (match) {
        EXPECT_NE(match->position, anchor);
        EXPECT_LE(match->mismatches, 3);
    }
    const std::optional<CodeMatch> loose = index.match(observed, 8);
    ASSERT_TRUE(loose);
    EXPECT_LE(loose->mismatches, 8);
}

}  // namespace
}  // namespace everytouch::core

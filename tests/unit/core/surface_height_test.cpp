// The height a correlation curve supports, from the evidence alone.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "core/surface_height.h"

namespace everytouch::core {
namespace {

// Evidence over `pixels` pixels whose correlation with the code at each candidate height (1 mm apart, 0 to
// 48 mm) is `curve(height)`: unit variances, so the covariance is the correlation.
template <typename Curve>
HeightEvidence evidenceWith(double pixels, Curve curve) {
    HeightEvidence evidence;
    evidence.clear(49);
    evidence.pixels = pixels;
    evidence.subtractionVariance = 1.0;
    for (std::size_t h = 0; h < 49; ++h) {
        evidence.codeVariance[h] = 1.0;
        evidence.covariance[h] = curve(static_cast<double>(h));
    }
    return evidence;
}

double peak(double heightMm, double atMm, double value) {
    return value * std::exp(-0.5 * (heightMm - atMm) * (heightMm - atMm) / 16.0);
}

TEST(SurfaceHeight, OnePeakGivesItsHeight) {
    const SurfaceHeight height{HeightOptions{}};
    const HeightEstimate estimate =
        height.estimate(evidenceWith(200, [](double h) { return peak(h, 12, 0.5); }));
    ASSERT_TRUE(estimate.valid);
    EXPECT_NEAR(estimate.heightMm, 12.0, 0.2);
    EXPECT_NEAR(estimate.correlation, 0.5, 1e-9);
}

TEST(SurfaceHeight, APadReadBelowTheTableIsSaidSoNotPutOnTheTable) {
    // A fingertip's top 12 mm above its pad: its surface read at 12 mm puts the pad on the table, read at
    // 2 mm (the table's code on a region the segmentation took for skin) 10 mm below it, which no finger is.
    const SurfaceHeight height{HeightOptions{}};
    const auto fingertipWithPeakAt = [](double atMm) {
        HeightEvidence evidence = evidenceWith(200, [atMm](double h) { return peak(h, atMm, 0.5); });
        evidence.topAbovePadTimesPixels = 12.0 * evidence.pixels;
        return evidence;
    };
    const HeightEstimate resting = height.estimate(fingertipWithPeakAt(12));
    ASSERT_TRUE(resting.valid);
    EXPECT_NEAR(resting.padHeightMm, 0.0, 0.2);
    const HeightEstimate table = height.estimate(fingertipWithPeakAt(2));
    ASSERT_TRUE(table.valid);
    EXPECT_NEAR(table.padHeightMm, -10.0, 0.2);
}

TEST(SurfaceHeight, TwoPeaksAboutAsHighGiveNoHeight) {
    // Over 200 pixels chance correlations spread by 0.1: a second peak 0.05 lower is as likely the surface.
    const SurfaceHeight height{HeightOptions{}};
    EXPECT_FALSE(
        height.estimate(evidenceWith(200, [](double h) { return peak(h, 12, 0.5) + peak(h, 36, 0.45); }))
            .valid);
    // The same curves over 20 000 pixels: chance spreads by 0.01, and the higher peak stands out.
    const HeightEstimate sharp =
        height.estimate(evidenceWith(20000, [](double h) { return peak(h, 12, 0.5) + peak(h, 36, 0.45); }));
    ASSERT_TRUE(sharp.valid);
    EXPECT_NEAR(sharp.heightMm, 12.0, 0.5);
}

TEST(SurfaceHeight, APeakAtTheTopOfTheRangeOrWithinChanceGivesNoHeight) {
    const SurfaceHeight height{HeightOptions{}};
    EXPECT_FALSE(height.estimate(evidenceWith(200, [](double h) { return 0.01 * h; })).valid);
    EXPECT_FALSE(height.estimate(evidenceWith(200, [](double h) { return peak(h, 12, 0.25); })).valid);
}

TEST(SurfaceHeight, EvidenceWithoutAHeightStillLeansToTheSideOfItsBestMatch) {
    const SurfaceHeight height{HeightOptions{}};
    // Two peaks about as high give no height; the better one below 20 mm favours that side.
    const auto lowBetter = [](double h) { return peak(h, 8, 0.5) + peak(h, 30, 0.45); };
    ASSERT_FALSE(height.estimate(evidenceWith(200, lowBetter)).valid);
    EXPECT_TRUE(height.favoursPadUpTo(evidenceWith(200, lowBetter), 20.0));
    EXPECT_FALSE(height.favoursPadUpTo(
        evidenceWith(200, [](double h) { return peak(h, 8, 0.45) + peak(h, 30, 0.5); }), 20.0));
    // Nothing beyond chance (0.1 over 200 pixels): no side.
    EXPECT_FALSE(height.favoursPadUpTo(evidenceWith(200, [](double h) { return peak(h, 8, 0.25); }), 20.0));
}

// Evidence over five slopes (0, 0.5, ... 2 mm per mm, the default candidates) whose correlation at slope
// row k and height h is curve(k, h).
template <typename Curve>
HeightEvidence slopedEvidenceWith(double pixels, Curve curve) {
    HeightEvidence evidence;
    evidence.clear(5 * 49);
    evidence.pixels = pixels;
    evidence.subtractionVariance = 1.0;
    for (std::size_t k = 0; k < 5; ++k)
        for (std::size_t h = 0; h < 49; ++h) {
            evidence.codeVariance[k * 49 + h] = 1.0;
            evidence.covariance[k * 49 + h] = curve(static_cast<double>(k), static_cast<double>(h));
        }
    return evidence;
}

TEST(SurfaceHeight, AtAGivenSlopeTheHeightIsReadBetweenTheTwoNearestSlopes) {
    // As on a fingertip: a steeper finger fits the same code with its cap lower, 4 mm per slope step.
    const SurfaceHeight height{HeightOptions{}};
    const auto ridge = [](double k, double h) { return peak(h, 20.0 - 4.0 * k, 0.5 - 0.01 * k); };
    const HeightEvidence evidence = slopedEvidenceWith(400, ridge);
    const HeightEstimate best = height.estimate(evidence);
    ASSERT_TRUE(best.valid);
    EXPECT_NEAR(best.heightMm, 20.0, 0.2);  // the best correlation: slope 0
    const HeightEstimate between = height.estimate(evidence, 0.75);
    ASSERT_TRUE(between.valid);
    EXPECT_NEAR(between.heightMm, 14.0, 0.5);  // halfway between slope 0.5 (16 mm) and 1.0 (12 mm)
    const HeightEstimate steepest = height.estimate(evidence, 5.0);  // beyond the candidates: the last
    ASSERT_TRUE(steepest.valid);
    EXPECT_NEAR(steepest.heightMm, 4.0, 0.2);
}

TEST(SurfaceHeight, SlopeSupportAddsUpOverFramesAndNamesTheSlopeBetweenCandidates) {
    const SurfaceHeight height{HeightOptions{}};
    ASSERT_EQ(height.hypotheses(), 5 * height.heights());
    // One frame fits slope 1.0 best by chance; five others fit slopes 0.5 and 1.0 about equally, 0.5 a
    // little better.
    const auto frameAt = [&](std::array<double, 5> best) {
        SlopeSupport support;
        height.supportSlopes(slopedEvidenceWith(400,
                                                [&](double k, double h) {
                                                    return peak(h, 20.0 - 4.0 * k,
                                                                best[static_cast<std::size_t>(k)]);
                                                }),
                             support);
        return support;
    };
    const SlopeSupport chance = frameAt({0.30, 0.40, 0.50, 0.30, 0.20});
    EXPECT_NEAR(height.bestSlope(chance), 1.0, 0.25);
    // The log-likelihood of the slope's best height: pixels / 4 times its correlation squared.
    EXPECT_NEAR(chance.logLikelihood[2], 0.25 * 400 * 0.25, 1e-9);
    SlopeSupport track = chance;
    for (int frame = 0; frame < 5; ++frame)
        track.add(frameAt({0.30, 0.50, 0.45, 0.30, 0.20}), 1.0);
    const double slope = height.bestSlope(track);
    EXPECT_GT(slope, 0.5);
    EXPECT_LT(slope, 0.75);
    EXPECT_EQ(height.bestSlope(SlopeSupport{}), 0.0);
}

TEST(HeightOptions, MistakesAreNamed) {
    HeightOptions options;
    EXPECT_EQ(options.validate(), std::nullopt);
    options.distinctness = -1.0;
    EXPECT_EQ(options.validate().value_or("").rfind("distinctness:", 0), 0u);
}

}  // namespace
}  // namespace everytouch::core

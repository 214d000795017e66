// The height a correlation curve supports, from the evidence alone.
#include <gtest/gtest.h>

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

TEST(HeightOptions, MistakesAreNamed) {
    HeightOptions options;
    EXPECT_EQ(options.validate(), std::nullopt);
    options.distinctness = -1.0;
    EXPECT_EQ(options.validate().value_or("").rfind("distinctness:", 0), 0u);
}

}  // namespace
}  // namespace everytouch::core

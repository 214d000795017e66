#include "core/one_euro_filter.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace everytouch::core {
namespace {

constexpr double kDtS = 1.0 / 120.0;

// Millimetres as the unit: the tracker's settings at a scale of 1 px/mm.
OneEuroParameters millimetres(double positionNoiseMm = 0.5) {
    return {1.0, 1.0, 5.0, positionNoiseMm};
}

TEST(OneEuroFilter, TheFirstValuePassesAndResetStartsAgain) {
    OneEuroFilter filter;
    EXPECT_FALSE(filter.started());
    EXPECT_EQ(filter.filter({3, 4}, kDtS, millimetres()), Eigen::Vector2d(3, 4));
    EXPECT_TRUE(filter.velocity().isZero());
    filter.filter({5, 4}, kDtS, millimetres());
    EXPECT_NE(filter.value(), Eigen::Vector2d(5, 4));
    filter.reset();
    EXPECT_FALSE(filter.started());
    EXPECT_EQ(filter.filter({-1, 2}, kDtS, millimetres()), Eigen::Vector2d(-1, 2));
}

TEST(OneEuroFilter, AConstantValueStaysPut) {
    OneEuroFilter filter;
    for (int i = 0; i < 50; ++i)
        filter.filter({10, -3}, kDtS, millimetres());
    EXPECT_TRUE(filter.value().isApprox(Eigen::Vector2d(10, -3)));
    EXPECT_TRUE(filter.velocity().isZero());
}

// Noise alone pushes the speed estimate past jitterSpeed in about 1 % of frames, as its comment says.
TEST(OneEuroFilter, NoiseAloneRarelyExceedsTheJitterSpeed) {
    for (const double noise : {0.2, 0.5, 1.0}) {
        std::mt19937 random(11);
        std::normal_distribution<double> jitter(0.0, noise);
        OneEuroFilter filter;
        const double limit = OneEuroFilter::jitterSpeed(noise, kDtS, 5.0);
        int above = 0, frames = 0;
        for (int i = 0; i < 20000; ++i) {
            filter.filter({jitter(random), jitter(random)}, kDtS, millimetres(noise));
            if (i < 100)
                continue;
            ++frames;
            above += filter.velocity().norm() > limit;
        }
        const double fraction = static_cast<double>(above) / frames;
        EXPECT_GT(fraction, 0.001) << noise;
        EXPECT_LT(fraction, 0.03) << noise;
    }
}

TEST(OneEuroFilter, FollowsARampWithItsVelocity) {
    OneEuroFilter filter;
    const Eigen::Vector2d velocity(300.0, -400.0);  // 0.5 m/s diagonally
    Eigen::Vector2d truth(0, 0);
    for (int i = 0; i < 60; ++i) {
        filter.filter(truth, kDtS, millimetres());
        truth += velocity * kDtS;
    }
    // The velocity estimate feeds on the lag, so it runs a little ahead of the truth's.
    EXPECT_LT((filter.velocity() - velocity).norm(), 0.3 * velocity.norm());
    EXPECT_LT((filter.value() - (truth - velocity * kDtS)).norm(), 0.5);
}

}  // namespace
}  // namespace everytouch::core

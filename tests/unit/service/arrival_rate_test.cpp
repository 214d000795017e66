#include "service/arrival_rate.h"

#include <gtest/gtest.h>

namespace everytouch::service {
namespace {

using namespace std::chrono_literals;
using Clock = ArrivalRate::Clock;

TEST(ArrivalRate, JitterDoesNotBiasTheRate) {
    // 120 frames/s where every other frame comes 6 ms late: intervals alternate 14.3 and 2.3 ms.
    ArrivalRate rate;
    const Clock::time_point start{};
    for (int i = 0; i < 240; ++i)
        rate.add(start + std::chrono::microseconds(8333 * i + (i % 2 ? 6000 : 0)));
    EXPECT_NEAR(rate.perSecond(start + std::chrono::microseconds(8333 * 240)), 120.0, 1.0);
}

TEST(ArrivalRate, FollowsAChangeWithinTheWindowAndFallsToZeroWhenArrivalsStop) {
    ArrivalRate rate;
    Clock::time_point t{};
    for (int i = 0; i < 200; ++i)
        rate.add(t += 5ms);  // 200 per second
    for (int i = 0; i < 40; ++i)
        rate.add(t += 50ms);  // then 20 per second, for two seconds
    EXPECT_NEAR(rate.perSecond(t), 20.0, 0.01);
    EXPECT_EQ(rate.perSecond(t + 2s), 0.0);
}

TEST(ArrivalRate, NeedsTwoArrivals) {
    ArrivalRate rate;
    EXPECT_EQ(rate.perSecond(Clock::time_point{}), 0.0);
    rate.add(Clock::time_point{} + 1ms);
    EXPECT_EQ(rate.perSecond(Clock::time_point{} + 2ms), 0.0);
}

TEST(ArrivalRate, FasterThanItsRingItMeasuresOverTheRing) {
    ArrivalRate rate;
    Clock::time_point t{};
    for (int i = 0; i < 2000; ++i)
        rate.add(t += 1ms);  // 1000 per second, more than the ring holds in a second
    EXPECT_NEAR(rate.perSecond(t), 1000.0, 0.01);
}

}  // namespace
}  // namespace everytouch::service

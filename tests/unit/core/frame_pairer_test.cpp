#include "core/frame_pairer.h"

#include <gtest/gtest.h>

namespace everytouch::core {
namespace {

Frame frame(std::uint64_t index, Polarity polarity) {
    Frame f;
    f.index = index;
    f.timestampUs = static_cast<std::int64_t>(index) * 8333;
    f.polarity = polarity;
    f.image = cv::Mat(2, 2, CV_8UC1, cv::Scalar(static_cast<double>(index)));
    return f;
}

TEST(FramePairer, EveryFrameAfterTheFirstCompletesAPair) {
    FramePairer pairer;
    EXPECT_FALSE(pairer.push(frame(0, Polarity::Positive)));
    const auto first = pairer.push(frame(1, Polarity::Negative));
    ASSERT_TRUE(first);
    EXPECT_EQ(first->positive.index, 0u);
    EXPECT_EQ(first->negative.index, 1u);
    EXPECT_EQ(first->latest().index, 1u);
    const auto second = pairer.push(frame(2, Polarity::Positive));
    ASSERT_TRUE(second);
    EXPECT_EQ(second->positive.index, 2u);
    EXPECT_EQ(second->negative.index, 1u);
    EXPECT_EQ(second->latest().index, 2u);
}

TEST(FramePairer, RepeatedPolarityOrDroppedFrameRestartsPairing) {
    FramePairer pairer;
    pairer.push(frame(0, Polarity::Positive));
    EXPECT_FALSE(pairer.push(frame(1, Polarity::Positive)));
    EXPECT_FALSE(pairer.push(frame(3, Polarity::Negative)));  // frame 2 was dropped
    EXPECT_TRUE(pairer.push(frame(4, Polarity::Positive)));
}

}  // namespace
}  // namespace everytouch::core

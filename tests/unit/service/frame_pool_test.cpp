#include "service/frame_pool.h"

#include <gtest/gtest.h>

namespace everytouch::service {
namespace {

TEST(FramePool, KeepsAnImageNothingElseSharesAndGivesItsMemoryBack) {
    FramePool pool(2);
    EXPECT_TRUE(pool.take().empty());
    cv::Mat image(488, 648, CV_8UC3);
    const uchar* memory = image.data;
    pool.giveBack(std::move(image));
    EXPECT_EQ(pool.spares(), 1u);
    const cv::Mat spare = pool.take();
    EXPECT_EQ(spare.data, memory);
    EXPECT_EQ(pool.spares(), 0u);
}

TEST(FramePool, LetsGoOfSharedImagesRegionsAndWhatItHasNoRoomFor) {
    FramePool pool(2);
    cv::Mat shared(48, 64, CV_8UC1);
    const cv::Mat snapshot = shared;  // a copy of the header elsewhere: its holder may still read it
    pool.giveBack(std::move(shared));
    EXPECT_EQ(pool.spares(), 0u);

    cv::Mat whole(48, 64, CV_8UC1);
    cv::Mat region = whole(cv::Rect(8, 8, 16, 16)).clone()(cv::Rect(0, 0, 8, 8));
    pool.giveBack(std::move(region));
    EXPECT_EQ(pool.spares(), 0u);

    for (int i = 0; i < 3; ++i)
        pool.giveBack(cv::Mat(48, 64, CV_8UC1));
    EXPECT_EQ(pool.spares(), 2u);
}

}  // namespace
}  // namespace everytouch::service

#include <gtest/gtest.h>

#include "io/frame_source.h"

// How long a camera may send nothing before it counts as lost: soon enough that a pulled cable releases the
// contacts within half a second, late enough that a busy machine's pause is not taken for one.
namespace everytouch::io {
namespace {

TEST(CameraStall, TenFramePeriodsBetweenAThirdOfASecondAndFourTenths) {
    EXPECT_DOUBLE_EQ(cameraStallSeconds(120.0), 0.3);
    EXPECT_DOUBLE_EQ(cameraStallSeconds(60.0), 0.3);
    EXPECT_DOUBLE_EQ(cameraStallSeconds(30.0), 10.0 / 30.0);
    EXPECT_DOUBLE_EQ(cameraStallSeconds(20.0), 0.4);
    EXPECT_DOUBLE_EQ(cameraStallSeconds(10.0), 0.4);
}

TEST(CameraStall, ASlowCameraHasThreeFramePeriodsAndAnUnknownRateASecond) {
    EXPECT_DOUBLE_EQ(cameraStallSeconds(5.0), 0.6);
    EXPECT_DOUBLE_EQ(cameraStallSeconds(0.0), 1.0);
}

}  // namespace
}  // namespace everytouch::io

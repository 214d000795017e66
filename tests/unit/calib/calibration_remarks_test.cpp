#include "calibration_remarks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace everytouch::calib {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

TEST(CalibrationRemarks, AreWhatFollowsTheRmsClauseEachCapitalised) {
    EXPECT_THAT(remarksOf("calibrated; RMS reprojection error 0.05 px"), IsEmpty());
    EXPECT_THAT(remarksOf("calibrated; RMS reprojection error 0.05 px; the display lands on the table"),
                ElementsAre("The display lands on the table"));
    EXPECT_THAT(remarksOf("calibrated; RMS reprojection error 0.05 px; one; two"), ElementsAre("One", "Two"));
    EXPECT_THAT(remarksOf(""), IsEmpty());
}

}  // namespace
}  // namespace everytouch::calib

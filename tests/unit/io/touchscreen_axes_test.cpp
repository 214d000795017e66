#include "io/touchscreen_axes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/input_error.h"
#include "support/test_rig.h"

namespace everytouch::io {
namespace {

using ::testing::HasSubstr;

void expectSizeWithin(const TouchscreenAxes& axes, cv::Size2d expectedMm, double relative) {
    EXPECT_NEAR(axes.sizeMm().width, expectedMm.width, relative * expectedMm.width);
    EXPECT_NEAR(axes.sizeMm().height, expectedMm.height, relative * expectedMm.height);
}

TEST(TouchscreenAxes, ReportTheProjectedSizeOfThePaperRigWithinHalfAPercent) {
    const core::Calibration calibration = test::paperLikeCalibration();
    const TouchscreenAxes axes =
        TouchscreenAxes::forDisplay(calibration.displaySize, calibration.displaySizeMm());
    expectSizeWithin(axes, calibration.displaySizeMm(), 0.005);
    EXPECT_EQ(axes.maximumX + 1, calibration.displaySize.width * axes.unitsPerPixel);
    EXPECT_EQ(axes.maximumY + 1, calibration.displaySize.height * axes.unitsPerPixel);
}

TEST(TouchscreenAxes, SubdividePixelsOfALargeSparseTable) {
    // 1920 px over 600 mm is 3.2 px/mm: whole pixels per mm would make the size 640 mm, 7 % off.
    const TouchscreenAxes axes = TouchscreenAxes::forDisplay({1920, 1080}, {600.0, 337.5});
    EXPECT_EQ(axes.unitsPerPixel, 32);
    EXPECT_EQ(axes.resolutionX, 102);
    EXPECT_EQ(axes.resolutionY, 102);
    expectSizeWithin(axes, {600.0, 337.5}, 0.005);
}

TEST(TouchscreenAxes, UseWholePixelsWhenTheyAreFineEnough) {
    const TouchscreenAxes axes = TouchscreenAxes::forDisplay({4000, 3000}, {20.0, 15.0});
    EXPECT_EQ(axes.unitsPerPixel, 1);
    EXPECT_EQ(axes.maximumX, 3999);
    EXPECT_EQ(axes.resolutionX, 200);
}

TEST(TouchscreenAxes, KeepDifferentScalesPerAxis) {
    const TouchscreenAxes axes = TouchscreenAxes::forDisplay({1000, 1000}, {500.0, 250.0});
    EXPECT_EQ(axes.unitsPerPixel, 50);
    EXPECT_EQ(axes.resolutionX, 100);
    EXPECT_EQ(axes.resolutionY, 200);
}

TEST(TouchscreenAxes, ConvertPixelsToClampedUnits) {
    const TouchscreenAxes axes = TouchscreenAxes::forDisplay({1000, 500}, {500.0, 250.0});
    EXPECT_EQ(axes.unitsX(10.26), 513);
    EXPECT_EQ(axes.unitsY(0.0), 0);
    EXPECT_EQ(axes.unitsX(-3.0), 0);
    EXPECT_EQ(axes.unitsX(1000.0), axes.maximumX);
    EXPECT_EQ(axes.unitsY(1e12), axes.maximumY);
}

TEST(TouchscreenAxes, RejectUnusableSizesNamingTheCalibrationField) {
    try {
        TouchscreenAxes::forDisplay({0, 960}, {300.0, 200.0});
        FAIL() << "an empty display was accepted";
    } catch (const InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr("display_size"));
    }
    EXPECT_THROW(TouchscreenAxes::forDisplay({1280, 960}, {std::nan(""), 200.0}), InputError);
    EXPECT_THROW(TouchscreenAxes::forDisplay({1280, 960}, {300.0, -1.0}), InputError);
    EXPECT_THROW(TouchscreenAxes::forDisplay({1280, 960}, {1e9, 1e9}), InputError);
}

}  // namespace
}  // namespace everytouch::io

#include "service/calibration_store.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/calibration_file.h"
#include "support/file_contents.h"
#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch::service {
namespace {

using ::testing::HasSubstr;

TEST(CalibrationStore, WithoutAFileTheRigsOwnCalibrationIsActive) {
    CalibrationStore store("", test::paperLikeCalibration());
    EXPECT_FALSE(store.load());
    ASSERT_TRUE(store.active());
    EXPECT_EQ(store.active()->cameraSize, test::paperLikeCalibration().cameraSize);
    EXPECT_FALSE(store.keepsFile());
    EXPECT_THROW(store.save(), std::logic_error);
}

TEST(CalibrationStore, AConfiguredFileThatIsNotThereMeansUncalibrated) {
    test::TempDir dir;
    CalibrationStore store(dir / "calibration.yml", test::paperLikeCalibration());
    EXPECT_FALSE(store.load());
    EXPECT_FALSE(store.active());
    EXPECT_THROW(store.save(), std::logic_error);
}

TEST(CalibrationStore, LoadsSavesAndForgets) {
    test::TempDir dir;
    core::Calibration calibration = test::paperLikeCalibration();
    io::writeCalibrationFile(dir / "calibration.yml", calibration);
    CalibrationStore store(dir / "calibration.yml", std::nullopt);
    EXPECT_FALSE(store.load());
    ASSERT_TRUE(store.active());

    calibration.displayToProjector(0, 2) = 12.5;
    store.activate(calibration);
    store.save();
    EXPECT_DOUBLE_EQ(io::readCalibrationFile(dir / "calibration.yml").displayToProjector(0, 2), 12.5);

    store.forget();
    EXPECT_FALSE(store.active());
    EXPECT_TRUE(std::filesystem::exists(dir / "calibration.yml"));
}

TEST(CalibrationStore, ACorruptFileIsReportedAndLeftAlone) {
    test::TempDir dir;
    std::ofstream(dir / "calibration.yml")
        << "%YAML:1.0\n---\nformat: everytouch-calibration\nversion: 1\ncamera_size: [1]\n";
    const std::string before = test::fileContents(dir / "calibration.yml");
    CalibrationStore store(dir / "calibration.yml", test::paperLikeCalibration());
    const std::optional<std::string> problem = store.load();
    ASSERT_TRUE(problem);
    EXPECT_THAT(*problem, HasSubstr("calibration.yml"));
    EXPECT_THAT(*problem, HasSubstr("camera_size"));
    EXPECT_FALSE(store.active());
    EXPECT_EQ(test::fileContents(dir / "calibration.yml"), before);
}

}  // namespace
}  // namespace everytouch::service

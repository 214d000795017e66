#include "sim/sim_options.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace everytouch::sim {
namespace {

using ::testing::HasSubstr;

TEST(SimOptions, DefaultsAreValid) {
    EXPECT_EQ(SimParameters().validate(), std::nullopt);
}

TEST(SimOptions, SetsNumbersVectorsSizesAndChoices) {
    SimParameters p;
    EXPECT_EQ(applyOption(p, "seed", "42"), std::nullopt);
    EXPECT_EQ(applyOption(p, "read_noise", "20.5"), std::nullopt);
    EXPECT_EQ(applyOption(p, "camera_position", "1:-2:300"), std::nullopt);
    EXPECT_EQ(applyOption(p, "camera_size", "320x240"), std::nullopt);
    EXPECT_EQ(applyOption(p, "surface", "artifacts"), std::nullopt);
    EXPECT_EQ(applyOption(p, "camera", "mono"), std::nullopt);
    EXPECT_EQ(applyOption(p, "exposure_ms", "3.5"), std::nullopt);
    EXPECT_EQ(p.seed, 42u);
    EXPECT_DOUBLE_EQ(p.readNoiseElectrons, 20.5);
    EXPECT_EQ(p.cameraPosition, Eigen::Vector3d(1, -2, 300));
    EXPECT_EQ(p.cameraSize, cv::Size(320, 240));
    EXPECT_EQ(p.surface, SurfaceKind::Artifacts);
    EXPECT_EQ(p.cameraColour, CameraColour::Mono);
    EXPECT_EQ(p.exposureMs, 3.5);
    EXPECT_EQ(applyOption(p, "exposure_ms", "auto"), std::nullopt);
    EXPECT_EQ(p.exposureMs, std::nullopt);
}

TEST(SimOptions, LightPresetsSetTheAmbientLevels) {
    SimParameters p;
    ASSERT_EQ(applyOption(p, "light", "dark"), std::nullopt);
    const double dark = p.ambientLux;
    ASSERT_EQ(applyOption(p, "light", "change"), std::nullopt);
    EXPECT_GT(p.ambientLux, dark);
    EXPECT_EQ(p.ambientChangeLux, dark);
    ASSERT_EQ(applyOption(p, "light", "normal"), std::nullopt);
    EXPECT_EQ(p.ambientChangeLux, std::nullopt);
}

TEST(SimOptions, ProblemsNameWhatIsWrong) {
    SimParameters p;
    EXPECT_THAT(applyOption(p, "colour", "red").value_or(""), HasSubstr("unknown key; known keys: seed"));
    EXPECT_THAT(applyOption(p, "seed", "-3").value_or(""), HasSubstr("non-negative integer"));
    EXPECT_THAT(applyOption(p, "surface", "wood").value_or(""), HasSubstr("gray, yellow, artifacts"));
    EXPECT_THAT(applyOption(p, "camera_position", "1:2").value_or(""), HasSubstr("three numbers"));
    EXPECT_THAT(applyOption(p, "camera_size", "640").value_or(""), HasSubstr("WIDTHxHEIGHT"));
    EXPECT_THAT(applyOption(p, "read_noise", "lots").value_or(""), HasSubstr("expected a number"));
}

TEST(SimOptions, ValidateNamesTheSpecKey) {
    SimParameters p;
    p.delta = 0;
    EXPECT_THAT(p.validate().value_or(""), HasSubstr("delta"));
    p = SimParameters();
    p.readNoiseElectrons = -1;
    EXPECT_THAT(p.validate().value_or(""), HasSubstr("read_noise"));
    p = SimParameters();
    p.exposureMs = 20.0;  // longer than a 120 Hz frame
    EXPECT_THAT(p.validate().value_or(""), HasSubstr("exposure_ms"));
}

TEST(SimOptions, EveryDocumentedKeyIsAccepted) {
    for (const OptionKey& key : optionKeys()) {
        SimParameters p;
        const std::optional<std::string> problem = applyOption(p, key.name, "");
        // An empty value is never valid, but the key must be known.
        ASSERT_TRUE(problem.has_value()) << key.name;
        EXPECT_THAT(*problem, ::testing::Not(HasSubstr("unknown key"))) << key.name;
    }
}

}  // namespace
}  // namespace everytouch::sim

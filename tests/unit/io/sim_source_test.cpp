#include "io/sim_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "core/camera_model.h"
#include "io/input_error.h"
#include "sim/sim_options.h"
#include "sim/simulator.h"
#include "support/temp_dir.h"

namespace everytouch::io {
namespace {

using ::testing::HasSubstr;

std::string errorOf(const std::string& spec) {
    try {
        SimSource source(RigSpec::parse(spec), false);
    } catch (const InputError& error) {
        return error.what();
    }
    return "no error";
}

TEST(SimSource, DeliversAlternatingFramesAtTheCameraRateUntilTheDurationEnds) {
    SimSource source(RigSpec::parse("sim:grid35,seed=4,duration=0.05"), false);
    std::vector<core::Frame> frames;
    while (std::optional<core::Frame> frame = source.next())
        frames.push_back(*frame);
    ASSERT_EQ(frames.size(), 6u);  // 0.05 s at 120 Hz
    for (size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].index, i);
        EXPECT_EQ(frames[i].polarity, i % 2 ? core::Polarity::Negative : core::Polarity::Positive);
        EXPECT_NEAR(frames[i].timestampUs, i * 1e6 / 120.0, 0.5);
        EXPECT_EQ(frames[i].image.type(), CV_8UC3);
        EXPECT_EQ(frames[i].image.size(), cv::Size(648, 488));
    }
    const std::optional<RigDescription> rig = source.rig();
    ASSERT_TRUE(rig);
    EXPECT_EQ(rig->calibration.validate(), std::nullopt);
    EXPECT_EQ(rig->pattern.size(), rig->calibration.projectorSize);
    EXPECT_EQ(rig->delta, 10);
    EXPECT_EQ(rig->frameRate, 120.0);
}

TEST(SimSource, ReportsTheTruthOfThePresentedFingers) {
    SimSource source(RigSpec::parse("sim:drag,seed=2,start=1.9"), false);  // in the first drag, finger down
    const std::optional<core::Frame> frame = source.next();
    ASSERT_TRUE(frame);
    const std::optional<std::vector<core::FingerTruth>> truth = source.truth();
    ASSERT_TRUE(truth);
    ASSERT_EQ(truth->size(), 1u);  // the pointing index finger
    EXPECT_EQ(truth->front().frameIndex, frame->index);
    EXPECT_EQ(truth->front().id, 1u);
    EXPECT_EQ(truth->front().heightMm, 0.0);
    EXPECT_GT(truth->front().x, 0.0);
    EXPECT_LT(truth->front().x, 640.0);
}

TEST(SimSource, HandMaskIsTheRenderersAndCoversTheTouchingFingers) {
    // The first tap of grid35 touches between 1.57 and 1.77 s and lasts at least 0.18 s, whatever the seed.
    const RigSpec spec = RigSpec::parse("sim:grid35,seed=3,start=1.6,duration=0.2");
    SimSource source(spec, false);
    ASSERT_TRUE(source.truthMask());
    EXPECT_TRUE(source.truthMask()->empty()) << "no frame yet";

    // The same rig rendered on its own.
    sim::SimParameters parameters;
    parameters.scenario = spec.target;
    for (const auto& [key, value] : spec.options)
        ASSERT_EQ(sim::applyOption(parameters, key, value), std::nullopt) << key;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));

    const core::Calibration calibration = source.rig()->calibration;
    const Eigen::Matrix3d displayToCamera = calibration.cameraToDisplayHomography().inverse();
    const core::CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const cv::Rect image(cv::Point(0, 0), calibration.cameraSize);
    int touches = 0;
    while (const std::optional<core::Frame> frame = source.next()) {
        const std::optional<cv::Mat> mask = source.truthMask();
        ASSERT_TRUE(mask);
        ASSERT_EQ(mask->type(), CV_8UC1);
        ASSERT_EQ(mask->size(), calibration.cameraSize);
        core::Frame alone;
        sim::FrameTruth truth;
        simulator.render(frame->index, alone, truth);
        EXPECT_EQ(cv::norm(*mask, truth.handMask, cv::NORM_INF), 0.0) << "frame " << frame->index;
        EXPECT_EQ(cv::countNonZero(*mask == 0) + cv::countNonZero(*mask == 255),
                  static_cast<int>(mask->total()));
        // A touching finger seen from above covers its own contact point.
        const std::optional<std::vector<core::FingerTruth>> fingers = source.truth();
        ASSERT_TRUE(fingers);
        for (const core::FingerTruth& finger : *fingers) {
            if (finger.heightMm != 0.0)
                continue;
            const Eigen::Vector2d undistorted =
                (displayToCamera * Eigen::Vector3d(finger.x, finger.y, 1.0)).hnormalized();
            const Eigen::Vector2d raw = camera.distortPixel(undistorted);
            const cv::Point contact(static_cast<int>(raw.x()), static_cast<int>(raw.y()));
            ASSERT_TRUE(image.contains(contact));
            EXPECT_GT(cv::countNonZero((*mask)(cv::Rect(contact - cv::Point(4, 4), cv::Size(9, 9)) & image)),
                      0)
                << "frame " << frame->index << " finger " << finger.id;
            ++touches;
        }
    }
    EXPECT_GT(touches, 0);
}

TEST(SimSource, StartsIntoTheSession) {
    SimSource source(RigSpec::parse("sim:idle,start=1,duration=0.02"), false);
    std::vector<std::uint64_t> indices;
    while (std::optional<core::Frame> frame = source.next()) {
        EXPECT_EQ(frame->timestampUs, static_cast<std::int64_t>(std::llround(frame->index * 1e6 / 120.0)));
        indices.push_back(frame->index);
    }
    EXPECT_EQ(indices, (std::vector<std::uint64_t>{120, 121, 122}));
}

TEST(SimSource, FingersOutsideTheDisplayAreNotInTheTruth) {
    SimSource source(RigSpec::parse("sim:grid35"), false);  // the hand comes from beyond the display's edge
    ASSERT_TRUE(source.next());
    ASSERT_TRUE(source.truth());
    EXPECT_TRUE(source.truth()->empty());
}

TEST(SimSource, IdleSceneHasTruthWithoutFingers) {
    SimSource source(RigSpec::parse("sim:idle"), false);
    ASSERT_TRUE(source.next());
    ASSERT_TRUE(source.truth());
    EXPECT_TRUE(source.truth()->empty());
}

TEST(SimSource, PacesInRealTimeUnlessFast) {
    SimSource source(RigSpec::parse("sim:idle,duration=0.1"), true);
    const auto start = std::chrono::steady_clock::now();
    int frames = 0;
    while (source.next())
        ++frames;
    EXPECT_EQ(frames, 12);
    EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::microseconds(11 * 8333));
}

TEST(SimSource, ShowsAnImageFileAsContent) {
    test::TempDir dir;
    const std::string file = (dir / "red.png").string();
    ASSERT_TRUE(cv::imwrite(file, cv::Mat(60, 80, CV_8UC3, cv::Scalar(0, 0, 255))));
    SimSource source(RigSpec::parse("sim:idle,light=dark,content=" + file), false);
    const std::optional<core::Frame> frame = source.next();
    ASSERT_TRUE(frame);
    // The middle of the display is red.
    const cv::Scalar mean = cv::mean(frame->image(cv::Rect(300, 220, 40, 40)));
    EXPECT_GT(mean[2], 2.0 * mean[1]);
}

TEST(SimSource, AStalledCameraSkipsItsFramesAndAResizedOneDeliversItsCentreQuarter) {
    // At 120 Hz: frames 0-5 come, 6-11 (0.05-0.1 s) never do, 12-17 come; 18-20 have the wrong size.
    SimSource source(
        RigSpec::parse("sim:grid35,seed=4,duration=0.175,stall=0.05,stall_s=0.05,wrong_size=0.15,"
                       "wrong_size_s=0.025"),
        false);
    std::vector<std::uint64_t> indices;
    std::vector<std::uint64_t> smaller;
    while (const std::optional<core::Frame> frame = source.next()) {
        indices.push_back(frame->index);
        if (frame->image.size() != cv::Size(648, 488)) {
            EXPECT_EQ(frame->image.size(), cv::Size(324, 244));
            smaller.push_back(frame->index);
        }
    }
    EXPECT_EQ(indices, (std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5, 12, 13, 14, 15, 16, 17, 18, 19, 20}));
    EXPECT_EQ(smaller, (std::vector<std::uint64_t>{18, 19, 20}));
}

TEST(SimSource, WritesAFrameIntoTheMemoryItIsOffered) {
    SimSource source(RigSpec::parse("sim:grid35,seed=4,duration=0.05"), false);
    std::optional<core::Frame> first = source.next();
    ASSERT_TRUE(first);
    const uchar* memory = first->image.data;
    const std::optional<core::Frame> second = source.next(std::move(first->image));
    ASSERT_TRUE(second);
    EXPECT_EQ(second->image.data, memory);
    EXPECT_EQ(second->index, 1u);
}

TEST(SimSource, BadSpecsAreInputErrorsNamingTheKey) {
    EXPECT_THAT(errorOf("sim:demo,stall=-1"), HasSubstr("stall: must be a number of seconds >= 0"));
    EXPECT_THAT(errorOf("sim:demo,wrong_size_s=0"), HasSubstr("wrong_size_s: must be a positive number"));
    EXPECT_THAT(errorOf("sim:juggle"), HasSubstr("unknown scenario \"juggle\""));
    EXPECT_THAT(errorOf("sim:demo,noise=3"), HasSubstr("--rig sim:demo,noise=3: noise: unknown key"));
    EXPECT_THAT(errorOf("sim:demo,seed=x"), HasSubstr("seed: expected a non-negative integer"));
    EXPECT_THAT(errorOf("sim:demo,delta=500"), HasSubstr("delta: must be in 1..127"));
    EXPECT_THAT(errorOf("sim:demo,content=/nonexistent.png"),
                HasSubstr("content: \"/nonexistent.png\" is neither a procedural kind"));
}

}  // namespace
}  // namespace everytouch::io

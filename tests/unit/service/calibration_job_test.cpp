#include "service/calibration_job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_rig.h"

namespace everytouch::service {
namespace {

using ::testing::HasSubstr;

struct ProgressEvent {
    std::string step;
    double fraction;
    std::string message;
};

std::vector<core::FramePair> pairsNumbered(std::size_t count, std::uint64_t first) {
    std::vector<core::FramePair> pairs(count);
    for (std::size_t i = 0; i < count; ++i) {
        pairs[i].positive.index = first + 2 * i;
        pairs[i].negative.index = first + 2 * i + 1;
    }
    return pairs;
}

// Steps whose estimators shift the display by their step number, so the test can see which results were
// chained through; each leaves a one-pixel scene of its shift and notes the scene the step before left (-1
// for none).
CalibrationStep shiftingStep(const std::string& name, double shift, double rmsPx,
                             std::vector<std::size_t>& pairsSeen, std::vector<int>* scenesSeen = nullptr) {
    return {name, name + " description",
            [name, shift, rmsPx, &pairsSeen, scenesSeen](const StepContext& context) -> EstimateResult {
                if (scenesSeen)
                    scenesSeen->push_back(
                        context.previousScene.empty() ? -1 : context.previousScene.at<uchar>(0, 0));
                context.show(cv::Mat(context.projectorSize, CV_8UC1, cv::Scalar(255)));
                context.progress(0.0, name + " prompt");
                const std::optional<std::vector<core::FramePair>> pairs =
                    context.capture(context.options.pairsPerStep);
                if (!pairs)
                    return core::Failure{"no frames"};
                pairsSeen.push_back(pairs->size());
                context.progress(0.5, name + " estimating");
                Estimate estimate{context.current.value_or(test::paperLikeCalibration()), rmsPx,
                                  cv::Mat(1, 1, CV_8UC1, cv::Scalar(shift))};
                estimate.calibration.displayToProjector(0, 2) += shift;
                return estimate;
            }};
}

TEST(CalibrationJob, KnowsItsSteps) {
    ASSERT_TRUE(calibrationSteps("full"));
    EXPECT_EQ(calibrationSteps("full")->size(), 2u);
    EXPECT_EQ(calibrationSteps("full")->front().name, "projector");
    EXPECT_EQ(calibrationSteps("table")->front().name, "table");
    EXPECT_FALSE(calibrationSteps("everything"));
}

TEST(CalibrationJob, OptionsAreRangeChecked) {
    EXPECT_FALSE(CalibrationOptions().validate());
    CalibrationOptions options;
    options.pairsPerStep = 0;
    EXPECT_THAT(options.validate().value_or(""), HasSubstr("frames"));
    options = CalibrationOptions();
    options.cardHeightMm = -1;
    EXPECT_THAT(options.validate().value_or(""), HasSubstr("card_height_mm"));
    options.cardHeightMm = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(options.validate());
    options = CalibrationOptions();
    options.views = 2;
    EXPECT_THAT(options.validate().value_or(""), HasSubstr("views: must be from 3 to 20"));
    options = CalibrationOptions();
    options.viewTimeoutS = 0.5;
    EXPECT_THAT(options.validate().value_or(""), HasSubstr("view_timeout_s: must be from 1 to 3600 s"));
}

TEST(CalibrationJob, RunsStepsInOrderChainingTheirResults) {
    std::vector<std::size_t> pairsSeen;
    std::vector<int> scenesSeen;
    const std::vector<CalibrationStep> steps = {shiftingStep("first", 1.0, 0.2, pairsSeen, &scenesSeen),
                                                shiftingStep("second", 10.0, 0.4, pairsSeen, &scenesSeen)};
    CalibrationOptions options;
    options.pairsPerStep = 3;
    std::uint64_t nextIndex = 0;
    std::vector<std::size_t> requested;
    std::vector<ProgressEvent> progress;
    std::vector<cv::Size> shown;
    const CalibrationOutcome outcome = runCalibration(
        steps, options, std::nullopt, cv::Size(640, 480),
        [&](std::size_t pairs) {
            requested.push_back(pairs);
            nextIndex += 2 * pairs;
            return std::optional(pairsNumbered(pairs, nextIndex));
        },
        [&](const cv::Mat& image) { shown.push_back(image.size()); },
        [&](const std::string& step, double fraction, const std::string& message) {
            progress.push_back({step, fraction, message});
        });
    ASSERT_TRUE(outcome.ok) << outcome.message;
    EXPECT_EQ(requested, (std::vector<std::size_t>{3, 3}));
    EXPECT_EQ(pairsSeen, (std::vector<std::size_t>{3, 3}));
    EXPECT_EQ(scenesSeen, (std::vector<int>{-1, 1}));
    EXPECT_EQ(shown, (std::vector<cv::Size>{{640, 480}, {640, 480}}));
    ASSERT_TRUE(outcome.calibration);
    EXPECT_DOUBLE_EQ(outcome.calibration->displayToProjector(0, 2), 11.0);
    EXPECT_DOUBLE_EQ(outcome.rmsPx, 0.4);
    ASSERT_FALSE(progress.empty());
    EXPECT_EQ(progress.front().step, "first");
    EXPECT_EQ(progress.front().message, "first prompt");
    EXPECT_DOUBLE_EQ(progress.front().fraction, 0.0);
    EXPECT_DOUBLE_EQ(progress.back().fraction, 1.0);
    for (std::size_t i = 1; i < progress.size(); ++i)
        EXPECT_GE(progress[i].fraction, progress[i - 1].fraction);
}

TEST(CalibrationJob, AFailingStepStopsTheJobWithoutACalibration) {
    std::vector<std::size_t> pairsSeen;
    CalibrationStep failing = shiftingStep("first", 1.0, 0.2, pairsSeen);
    failing.run = [](const StepContext&) -> EstimateResult { return core::Failure{"no chessboard in view"}; };
    const std::vector<CalibrationStep> steps = {failing, shiftingStep("second", 10.0, 0.4, pairsSeen)};
    const CalibrationOutcome outcome = runCalibration(
        steps, CalibrationOptions(), test::paperLikeCalibration(), cv::Size(640, 480),
        [](std::size_t pairs) { return std::optional(pairsNumbered(pairs, 0)); }, [](const cv::Mat&) {},
        [](const std::string&, double, const std::string&) {});
    EXPECT_FALSE(outcome.ok);
    EXPECT_FALSE(outcome.calibration);
    EXPECT_THAT(outcome.message, HasSubstr("first step failed: no chessboard in view"));
    EXPECT_TRUE(pairsSeen.empty());
}

TEST(CalibrationJob, NoFramesIsAFailure) {
    std::vector<std::size_t> pairsSeen;
    const CalibrationOutcome outcome = runCalibration(
        {shiftingStep("only", 1.0, 0.1, pairsSeen)}, CalibrationOptions(), std::nullopt, cv::Size(640, 480),
        [](std::size_t) { return std::optional<std::vector<core::FramePair>>(); }, [](const cv::Mat&) {},
        [](const std::string&, double, const std::string&) {});
    EXPECT_FALSE(outcome.ok);
    EXPECT_THAT(outcome.message, HasSubstr("the only step failed: no frames"));
    EXPECT_TRUE(pairsSeen.empty());
}

}  // namespace
}  // namespace everytouch::service

// The frames' order read from the code's sign, on rendered frames: a camera that starts on the O - P frame
// or loses a frame without a gap in its count.
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include <gtest/gtest.h>

#include "core/code_image.h"
#include "core/hand_segmentation.h"
#include "core/polarity_lock.h"
#include "core/touch_pipeline.h"
#include "sim/simulator.h"
#include "support/simulated_rig_settings.h"

namespace everytouch::core {
namespace {

// grid35 with its default seed: the index finger rests on a circle from frame 205 to 243.
constexpr std::uint64_t kFirst = 180;
constexpr std::uint64_t kEnd = 262;
constexpr std::uint64_t kTouchFrom = 212;
constexpr std::uint64_t kTouchTo = 240;

struct Rendered {
    sim::SimParameters parameters;
    std::optional<sim::Simulator> simulator;
    std::vector<Frame> frames;  // from kFirst, labelled as the simulated projector showed them
};

Rendered render(std::uint64_t end) {
    Rendered r;
    r.parameters.scenario = "grid35";
    r.simulator.emplace(r.parameters, sim::rigPattern(r.parameters));
    sim::FrameTruth truth;
    for (std::uint64_t index = kFirst; index < end; ++index)
        r.simulator->render(index, r.frames.emplace_back(), truth);
    return r;
}

// The whole stretch, for the pipeline; its first three frames, for the lock alone.
const Rendered& rendered() {
    static const Rendered scene = render(kEnd);
    return scene;
}
const Rendered& firstFrames() {
    static const Rendered scene = render(kFirst + 3);
    return scene;
}

FramePair pairOf(const Frame& older, const Frame& newer) {
    return older.polarity == Polarity::Positive ? FramePair{older, newer} : FramePair{newer, older};
}

class PolarityLockTest : public ::testing::Test {
protected:
    void SetUp() override {
        const sim::Simulator& simulator = *firstFrames().simulator;
        segmenter.setRig(simulator.calibration(), simulator.pattern());
        lock.setRig(segmenter.tableCode(), segmenter.judgedRegion());
    }
    bool relock(const FramePair& pair) {
        computeSubtractionAndTexture(pair, subtraction, texture);
        return lock.relock(subtraction);
    }
    HandSegmenter segmenter{SegmentationOptions{}};
    PolarityLock lock;
    cv::Mat subtraction, texture;
};

TEST_F(PolarityLockTest, KeepsTheOrderTheCodeConfirms) {
    const std::vector<Frame>& frames = firstFrames().frames;
    EXPECT_FALSE(relock(pairOf(frames[0], frames[1])));
    EXPECT_FALSE(lock.swapped());
    EXPECT_GT(lock.correlation(), PolarityLock::kSignificance * lock.chance());
    EXPECT_GT(lock.correlation(), 0.2);
    EXPECT_EQ(lock.swaps(), 0u);
}

TEST_F(PolarityLockTest, SwapsAPairMadeTheWrongWayRound) {
    const std::vector<Frame>& frames = firstFrames().frames;
    const FramePair wrong = swappedPair(pairOf(frames[0], frames[1]));
    EXPECT_TRUE(relock(wrong));
    EXPECT_TRUE(lock.swapped());
    EXPECT_LT(lock.correlation(), -PolarityLock::kSignificance * lock.chance());
    // Taken the other way, the pair confirms the new order.
    EXPECT_FALSE(relock(swappedPair(wrong)));
    EXPECT_TRUE(lock.swapped());
    EXPECT_EQ(lock.swaps(), 1u);
}

TEST_F(PolarityLockTest, APairWithoutCodeChangesNothing) {
    const std::vector<Frame>& frames = firstFrames().frames;
    // Two frames of the same polarity (a refresh the projector repeated): the code cancels.
    EXPECT_FALSE(relock(FramePair{frames[2], frames[0]}));
    EXPECT_LT(std::abs(lock.correlation()), PolarityLock::kSignificance * lock.chance());
    EXPECT_FALSE(relock(swappedPair(FramePair{frames[2], frames[0]})));
    EXPECT_FALSE(lock.swapped());
    subtraction.setTo(0);
    EXPECT_FALSE(lock.relock(subtraction));
    EXPECT_FALSE(lock.swapped());
}

// Labels the frames as a camera that counts them does: by their place among those delivered, starting
// with `first`.
std::vector<Frame> asCounted(std::vector<Frame> frames, Polarity first) {
    Polarity polarity = first;
    for (std::size_t i = 0; i < frames.size(); ++i, polarity = opposite(polarity)) {
        frames[i].index = i;
        frames[i].polarity = polarity;
    }
    return frames;
}

TEST(TouchPipelinePolarity, ACameraThatStartedOnTheOtherFrameSeesTheSameTouches) {
    const Rendered& scene = rendered();
    const PipelineSettings settings = test::simulatedRigSettings(*scene.simulator);
    const std::vector<Frame> right = asCounted(scene.frames, scene.frames[0].polarity);
    const std::vector<Frame> wrong = asCounted(scene.frames, opposite(scene.frames[0].polarity));
    TouchPipeline labelledRight, labelledWrong;
    int touchingPairs = 0;
    std::uint64_t swaps = 0;
    for (std::size_t i = 1; i < right.size(); ++i) {
        const PipelineResult& expected = labelledRight.process(pairOf(right[i - 1], right[i]), settings);
        const PipelineResult& actual = labelledWrong.process(pairOf(wrong[i - 1], wrong[i]), settings);
        EXPECT_FALSE(expected.framesSwapped);
        ASSERT_TRUE(actual.framesSwapped) << "pair " << i;
        swaps = actual.polaritySwaps;
        ASSERT_EQ(actual.contacts.size(), expected.contacts.size()) << "pair " << i;
        for (std::size_t c = 0; c < expected.contacts.size(); ++c) {
            EXPECT_EQ(actual.contacts[c], expected.contacts[c]) << "pair " << i;
            touchingPairs += expected.contacts[c].touching;
        }
    }
    EXPECT_GT(touchingPairs, 20) << "the test needs a touch";
    EXPECT_EQ(swaps, 1u) << "once, on the first pair";
}

// The ids touching in each pair from kTouchFrom to kTouchTo (rendered frame numbers).
std::vector<std::vector<std::uint32_t>> touchingIds(const std::vector<Frame>& delivered,
                                                    const std::vector<std::uint64_t>& renderedIndex,
                                                    std::uint64_t* swaps) {
    const PipelineSettings settings = test::simulatedRigSettings(*rendered().simulator);
    TouchPipeline pipeline;
    std::vector<std::vector<std::uint32_t>> touching;
    for (std::size_t i = 1; i < delivered.size(); ++i) {
        const PipelineResult& result = pipeline.process(pairOf(delivered[i - 1], delivered[i]), settings);
        *swaps = result.polaritySwaps;
        if (renderedIndex[i] < kTouchFrom || renderedIndex[i] > kTouchTo)
            continue;
        std::vector<std::uint32_t>& ids = touching.emplace_back();
        for (const Contact& contact : result.contacts)
            if (contact.touching)
                ids.push_back(contact.id);
    }
    return touching;
}

TEST(TouchPipelinePolarity, AFrameLostWithoutAGapDoesNotLiftATouch) {
    // The camera loses one frame while the finger rests and counts on as if it had not: from then on its
    // labels say the opposite of what the projector showed. The pair across the loss shows no code.
    const Rendered& scene = rendered();
    std::vector<std::uint64_t> allIndices, keptIndices;
    std::vector<Frame> kept;
    for (std::size_t i = 0; i < scene.frames.size(); ++i) {
        allIndices.push_back(kFirst + i);
        if (kFirst + i == 225)
            continue;
        kept.push_back(scene.frames[i]);
        keptIndices.push_back(kFirst + i);
    }
    std::uint64_t swaps = 0;
    const auto baseline = touchingIds(asCounted(scene.frames, scene.frames[0].polarity), allIndices, &swaps);
    ASSERT_EQ(swaps, 0u);
    for (const auto& ids : baseline)
        ASSERT_EQ(ids.size(), 1u) << "the finger should touch throughout without the loss";
    const auto touching = touchingIds(asCounted(kept, scene.frames[0].polarity), keptIndices, &swaps);
    EXPECT_EQ(swaps, 1u);
    for (const auto& ids : touching) {
        ASSERT_EQ(ids.size(), 1u);
        EXPECT_EQ(ids.front(), baseline.front().front()) << "the contact keeps its id";
    }
}

}  // namespace
}  // namespace everytouch::core

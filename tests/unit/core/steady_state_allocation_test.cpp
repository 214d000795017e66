// Detection allocates nothing per frame pair once it has seen the first pairs: every allocation is counted
// (tests/support/allocation_counter) while the pipeline processes rendered frames of hands at work.
#include <gtest/gtest.h>

#include "core/touch_pipeline.h"
#include "sim/simulator.h"
#include "support/allocation_counter.h"

namespace everytouch::core {
namespace {

std::vector<FramePair> renderPairs(sim::Simulator& simulator, double startS, int count) {
    std::vector<FramePair> pairs;
    auto index = static_cast<std::uint64_t>(startS * simulator.parameters().frameRate);
    sim::FrameTruth truth;
    for (int i = 0; i < count; ++i, ++index) {
        // Each new frame with the previous one, as the daemon pairs them.
        Frame older, newer;
        simulator.render(index, older, truth);
        simulator.render(index + 1, newer, truth);
        const bool olderPositive = older.polarity == Polarity::Positive;
        pairs.push_back(FramePair{olderPositive ? older : newer, olderPositive ? newer : older});
    }
    return pairs;
}

TEST(SteadyStateAllocation, ThePipelineAllocatesNothingPerPairOnceWarm) {
    cv::setNumThreads(1);  // OpenCV's thread pool would allocate on its own threads' behalf
    sim::SimParameters parameters;
    parameters.scenario = "multitouch";
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    // Two hands and ten fingers spreading: the most fingertips, the largest regions.
    const std::vector<FramePair> pairs = renderPairs(simulator, 17.0, 12);
    TouchPipeline pipeline;
    const PipelineSettings settings{simulator.calibration(), simulator.pattern(), 0.0};
    std::size_t fingertips = 0;
    // Warm: the code's blur is measured once the calibration's check has read the code (16 tiles, one a
    // pair: in the second round), and the third segments every pair with it, as the measured round does.
    for (int round = 0; round < 3; ++round) {
        pipeline.reset();  // the same pairs again: time starts over
        for (const FramePair& pair : pairs)
            fingertips += pipeline.process(pair, settings).fingertips.size();
    }
    ASSERT_GT(fingertips, 0u) << "the test needs fingertips in view";

    pipeline.reset();
    const std::uint64_t before = test::allocationCount();
    for (const FramePair& pair : pairs)
        pipeline.process(pair, settings);
    EXPECT_EQ(test::allocationCount() - before, 0u)
        << "allocations while processing " << pairs.size() << " pairs";
}

TEST(SteadyStateAllocation, AStillSceneAllocatesNothingEither) {
    cv::setNumThreads(1);
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    // The table before the hand comes in: after the first pairs the segmentation is skipped.
    const std::vector<FramePair> pairs = renderPairs(simulator, 0.1, 12);
    TouchPipeline pipeline;
    const PipelineSettings settings{simulator.calibration(), simulator.pattern(), 0.0};
    for (int round = 0; round < 2; ++round) {
        pipeline.reset();
        for (const FramePair& pair : pairs)
            pipeline.process(pair, settings);
    }

    pipeline.reset();
    int still = 0;
    const std::uint64_t before = test::allocationCount();
    for (const FramePair& pair : pairs)
        still += pipeline.process(pair, settings).sceneStill ? 1 : 0;
    EXPECT_EQ(test::allocationCount() - before, 0u)
        << "allocations while processing " << pairs.size() << " pairs";
    EXPECT_GT(still, 0) << "the test needs pairs of a still scene";
}

}  // namespace
}  // namespace everytouch::core

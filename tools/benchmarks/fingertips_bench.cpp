// Cost of finding the fingertips on a hand mask (648x488) on one core: one hand, two hands, none. The masks
// are the simulator's truth, rendered before timing.
#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "core/fingertips.h"
#include "sim/simulator.h"

namespace {

using namespace everytouch;

// Runs the fingertips on the hand masks of `count` frames from `startS` seconds on, 0.1 s apart, in turn.
void findOnScenario(benchmark::State& state, const char* scenario, double startS, int count) {
    cv::setNumThreads(1);
    sim::SimParameters p;
    p.scenario = scenario;
    cv::Mat pattern(p.projectorSize, CV_8UC1);
    cv::RNG(1).fill(pattern, cv::RNG::UNIFORM, 0, 2);
    sim::Simulator simulator(p, pattern);
    std::vector<cv::Mat> masks;
    core::Frame frame;
    sim::FrameTruth truth;
    for (int i = 0; i < count; ++i) {
        simulator.render(static_cast<std::uint64_t>((startS + 0.1 * i) * p.frameRate), frame, truth);
        masks.push_back(truth.handMask.clone());
    }
    const core::FingertipOptions options = core::rigFingertipOptions(simulator.calibration());
    core::FingertipScratch scratch;
    core::Fingertips fingertips;
    size_t next = 0, found = 0;
    for (auto _ : state) {
        core::findFingertips(masks[next], options, scratch, fingertips);
        found += fingertips.size();
        next = (next + 1) % masks.size();
    }
    state.counters["fingertips"] =
        benchmark::Counter(static_cast<double>(found), benchmark::Counter::kAvgIterations);
}

void BM_FingertipsOneHand(benchmark::State& state) {
    findOnScenario(state, "grid35", 2.0, 20);  // a pointing hand with its forearm, tapping
}
BENCHMARK(BM_FingertipsOneHand)->Unit(benchmark::kMicrosecond);

void BM_FingertipsTwoHands(benchmark::State& state) {
    findOnScenario(state, "multitouch", 16.5, 20);  // ten fingers spreading
}
BENCHMARK(BM_FingertipsTwoHands)->Unit(benchmark::kMicrosecond);

void BM_FingertipsNoHand(benchmark::State& state) {
    findOnScenario(state, "idle", 1.0, 1);
}
BENCHMARK(BM_FingertipsNoHand)->Unit(benchmark::kMicrosecond);

}  // namespace

// Cost of one simulated camera frame (648x488) on one core, by scenario and sensor, and of a content change.
#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "sim/content.h"
#include "sim/simulator.h"

namespace {

using namespace everytouch;

cv::Mat benchPattern(cv::Size size) {
    cv::Mat pattern(size, CV_8UC1);
    cv::RNG rng(1);
    rng.fill(pattern, cv::RNG::UNIFORM, 0, 2);
    return pattern;
}

// Renders consecutive frames of a scenario from `startS` seconds on, as the daemon does.
void renderScenario(benchmark::State& state, const char* scenario, sim::CameraColour colour, double startS) {
    cv::setNumThreads(1);
    sim::SimParameters p;
    p.scenario = scenario;
    p.cameraColour = colour;
    sim::Simulator simulator(p, benchPattern(p.projectorSize));
    core::Frame frame;
    sim::FrameTruth truth;
    auto index = static_cast<std::uint64_t>(startS * p.frameRate);
    simulator.render(index, frame, truth);  // content shown, buffers allocated
    for (auto _ : state) {
        simulator.render(++index, frame, truth);
        benchmark::DoNotOptimize(frame.image.data);
    }
}

void BM_RenderGrid35(benchmark::State& state) {
    renderScenario(state, "grid35", sim::CameraColour::Bayer, 1.0);
}
BENCHMARK(BM_RenderGrid35)->Unit(benchmark::kMillisecond);

void BM_RenderMultitouchTwoHands(benchmark::State& state) {
    renderScenario(state, "multitouch", sim::CameraColour::Bayer, 16.0);
}
BENCHMARK(BM_RenderMultitouchTwoHands)->Unit(benchmark::kMillisecond);

void BM_RenderPalm(benchmark::State& state) {
    renderScenario(state, "palm", sim::CameraColour::Bayer, 2.0);
}
BENCHMARK(BM_RenderPalm)->Unit(benchmark::kMillisecond);

void BM_RenderIdle(benchmark::State& state) {
    renderScenario(state, "idle", sim::CameraColour::Bayer, 1.0);
}
BENCHMARK(BM_RenderIdle)->Unit(benchmark::kMillisecond);

void BM_RenderGrid35Rgb(benchmark::State& state) {
    renderScenario(state, "grid35", sim::CameraColour::Rgb, 1.0);
}
BENCHMARK(BM_RenderGrid35Rgb)->Unit(benchmark::kMillisecond);

void BM_RenderGrid35Mono(benchmark::State& state) {
    renderScenario(state, "grid35", sim::CameraColour::Mono, 1.0);
}
BENCHMARK(BM_RenderGrid35Mono)->Unit(benchmark::kMillisecond);

// A new content image: both projected images' light on the table and on skin, precomputed.
void BM_ContentChange(benchmark::State& state) {
    cv::setNumThreads(1);
    sim::SimParameters p;
    sim::Simulator simulator(p, benchPattern(p.projectorSize));
    sim::Renderer renderer(p, simulator.calibration(), simulator.pattern());
    const cv::Mat content = sim::renderContent(sim::ContentKind::Photo, p.displaySize, 1, 0);
    for (auto _ : state)
        renderer.setContent(content);
}
BENCHMARK(BM_ContentChange)->Unit(benchmark::kMillisecond);

}  // namespace

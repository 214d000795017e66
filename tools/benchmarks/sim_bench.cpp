// Cost of one simulated camera frame (648x488) on one core, by scenario and sensor, and of a content change.
#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "core/projector_chessboard.h"
#include "sim/calibration_scenarios.h"
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

// The pair calibration: the board with the card held still in its first tilt, the chessboard projected.
void BM_RenderBoardHeld(benchmark::State& state) {
    cv::setNumThreads(1);
    sim::SimParameters p;
    p.scenario = "pair-calibration";
    sim::Simulator simulator(p, benchPattern(p.projectorSize));
    cv::Mat chessboard;
    core::renderProjectorChessboard(sim::calibrationChessboard(), p.projectorSize, chessboard);
    simulator.projectImage(chessboard);
    const auto& scenario = dynamic_cast<const sim::PairCalibrationScenario&>(simulator.scenario());
    core::Frame frame;
    sim::FrameTruth truth;
    const auto first = static_cast<std::uint64_t>(scenario.holdStart(1) * p.frameRate);
    const auto frames =
        static_cast<std::uint64_t>(0.9 * sim::PairCalibrationScenario::kHoldSeconds * p.frameRate);
    simulator.render(first, frame, truth);  // the pose's precomputation
    std::uint64_t k = 0;
    for (auto _ : state) {
        simulator.render(first + (++k % frames), frame, truth);
        benchmark::DoNotOptimize(frame.image.data);
    }
}
BENCHMARK(BM_RenderBoardHeld)->Unit(benchmark::kMillisecond);

// The board moving between two tilts: the scene is ray cast again every frame (one sample per pixel).
void BM_RenderBoardMoving(benchmark::State& state) {
    cv::setNumThreads(1);
    sim::SimParameters p;
    p.scenario = "pair-calibration";
    sim::Simulator simulator(p, benchPattern(p.projectorSize));
    cv::Mat chessboard;
    core::renderProjectorChessboard(sim::calibrationChessboard(), p.projectorSize, chessboard);
    simulator.projectImage(chessboard);  // the user begins when the dialogue shows it
    const auto& scenario = dynamic_cast<const sim::PairCalibrationScenario&>(simulator.scenario());
    core::Frame frame;
    sim::FrameTruth truth;
    const auto first = static_cast<std::uint64_t>((scenario.holdEnd(1) + 0.05) * p.frameRate);
    const auto frames =
        static_cast<std::uint64_t>(0.9 * sim::PairCalibrationScenario::kMoveSeconds * p.frameRate);
    std::uint64_t k = 0;
    simulator.render(first, frame, truth);
    for (auto _ : state) {
        simulator.render(first + (++k % frames), frame, truth);
        benchmark::DoNotOptimize(frame.image.data);
    }
}
BENCHMARK(BM_RenderBoardMoving)->Unit(benchmark::kMillisecond);

// A new still pose of the props: the scene ray cast in full and the light of both projected images on it.
void BM_PropsChange(benchmark::State& state) {
    cv::setNumThreads(1);
    sim::SimParameters p;
    p.scenario = "pair-calibration";
    sim::Simulator simulator(p, benchPattern(p.projectorSize));
    const auto& scenario = dynamic_cast<const sim::PairCalibrationScenario&>(simulator.scenario());
    sim::Renderer renderer(p, simulator.calibration(), simulator.pattern());
    renderer.setContent(sim::renderContent(sim::ContentKind::White, p.displaySize, 1, 0));
    const std::vector<sim::Props> poses = scenario.stillProps();
    std::size_t k = 0;
    for (auto _ : state)
        renderer.setProps(poses[1 + (++k % (poses.size() - 1))]);
}
BENCHMARK(BM_PropsChange)->Unit(benchmark::kMillisecond);

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

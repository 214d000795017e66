// Cost of detection per frame pair on one core, 648x488 (the simulated rig's defaults): segmentation with
// fingertips, with one hand in view and with none; the paper's segmentation as published (stock mean shift
// over the whole frame) for comparison; the height of one fingertip; the whole pipeline. Each benchmark
// reports the median and the 99th percentile of its iterations as counters (ms).
#include <algorithm>
#include <chrono>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/calibration_correction.h"
#include "core/code_blur.h"
#include "core/code_evidence.h"
#include "core/code_image.h"
#include "core/fingertips.h"
#include "core/hand_segmentation.h"
#include "core/polarity_lock.h"
#include "core/registration_check.h"
#include "core/surface_height.h"
#include "core/touch_pipeline.h"
#include "sim/simulator.h"

namespace {

using namespace everytouch;
using Clock = std::chrono::steady_clock;

// A few consecutive pairs of a scenario, rendered once and shared by the benchmarks.
struct Scene {
    sim::SimParameters parameters;
    core::Calibration calibration;
    cv::Mat pattern;
    std::vector<core::FramePair> pairs;
};

Scene renderScene(const char* scenario, double startS, int pairs) {
    Scene scene;
    scene.parameters.scenario = scenario;
    sim::Simulator simulator(scene.parameters, sim::rigPattern(scene.parameters));
    scene.calibration = simulator.calibration();
    scene.pattern = simulator.pattern();
    auto index = static_cast<std::uint64_t>(startS * scene.parameters.frameRate) & ~std::uint64_t{1};
    sim::FrameTruth truth;
    for (int i = 0; i < pairs; ++i, index += 2) {
        core::FramePair pair;
        simulator.render(index, pair.positive, truth);
        simulator.render(index + 1, pair.negative, truth);
        scene.pairs.push_back(std::move(pair));
    }
    return scene;
}

// grid35 at 1.9 s: one hand with its forearm, the index finger pointing and held still; at 2.3 s on its way
// to the next circle; idle: nothing but content.
const Scene& oneHand() {
    static const Scene scene = renderScene("grid35", 1.9, 8);
    return scene;
}
const Scene& movingHand() {
    static const Scene scene = renderScene("grid35", 2.3, 8);
    return scene;
}
const Scene& noHand() {
    static const Scene scene = renderScene("idle", 1.0, 8);
    return scene;
}

class Timings {
public:
    void add(Clock::duration d) { ms_.push_back(std::chrono::duration<double, std::milli>(d).count()); }
    void report(benchmark::State& state) {
        std::sort(ms_.begin(), ms_.end());
        if (ms_.empty())
            return;
        state.counters["median_ms"] = ms_[ms_.size() / 2];
        state.counters["p99_ms"] = ms_[static_cast<std::size_t>(0.99 * static_cast<double>(ms_.size() - 1))];
    }

private:
    std::vector<double> ms_;
};

void segmentAndFindFingertips(benchmark::State& state, const Scene& scene, core::SegmentationMethod method) {
    cv::setNumThreads(1);
    core::SegmentationOptions options;
    options.method = method;
    core::HandSegmenter segmenter(options);
    segmenter.setRig(scene.calibration, scene.pattern);
    core::FingertipOptions fingertipOptions;
    fingertipOptions.fingerWidthPx = 16.0 * segmenter.pixelsPerMm();
    core::FingertipScratch scratch;
    core::Fingertips fingertips;
    std::vector<cv::Mat> textures(scene.pairs.size()), subtractions(scene.pairs.size());
    for (std::size_t i = 0; i < scene.pairs.size(); ++i)
        core::computeSubtractionAndTexture(scene.pairs[i], subtractions[i], textures[i]);
    cv::Mat mask;
    for (std::size_t k = 0; k < scene.pairs.size(); ++k) {  // the buffers sized
        segmenter.segment(textures[k], subtractions[k], mask);
        core::findFingertips(mask, fingertipOptions, scratch, fingertips);
    }
    Timings timings;
    std::size_t i = 0, found = 0, handPixels = 0;
    for (auto _ : state) {
        const auto start = Clock::now();
        segmenter.segment(textures[i], subtractions[i], mask);
        core::findFingertips(mask, fingertipOptions, scratch, fingertips);
        timings.add(Clock::now() - start);
        found += fingertips.size();
        handPixels += static_cast<std::size_t>(cv::countNonZero(mask));
        i = (i + 1) % scene.pairs.size();
    }
    timings.report(state);
    state.counters["fingertips"] = static_cast<double>(found) / static_cast<double>(state.iterations());
    state.counters["hand_px"] = static_cast<double>(handPixels) / static_cast<double>(state.iterations());
}

void BM_SegmentationAndFingertipsOneHand(benchmark::State& state) {
    segmentAndFindFingertips(state, oneHand(), core::SegmentationMethod::Code);
}
BENCHMARK(BM_SegmentationAndFingertipsOneHand)->Unit(benchmark::kMillisecond);

void BM_SegmentationAndFingertipsNoHand(benchmark::State& state) {
    segmentAndFindFingertips(state, noHand(), core::SegmentationMethod::Code);
}
BENCHMARK(BM_SegmentationAndFingertipsNoHand)->Unit(benchmark::kMillisecond);

void BM_PaperSegmentationOneHand(benchmark::State& state) {
    segmentAndFindFingertips(state, oneHand(), core::SegmentationMethod::Paper);
}
BENCHMARK(BM_PaperSegmentationOneHand)->Unit(benchmark::kMillisecond)->Iterations(8);

// The paper's method done straightforwardly: stock mean shift over the whole frame, nothing else.
void BM_PaperMeanShiftWholeFrame(benchmark::State& state) {
    cv::setNumThreads(1);
    const Scene& scene = oneHand();
    cv::Mat subtraction, texture, filtered;
    core::computeSubtractionAndTexture(scene.pairs.front(), subtraction, texture);
    Timings timings;
    for (auto _ : state) {
        const auto start = Clock::now();
        cv::pyrMeanShiftFiltering(texture, filtered, 7, 10, 1);
        timings.add(Clock::now() - start);
    }
    timings.report(state);
}
BENCHMARK(BM_PaperMeanShiftWholeFrame)->Unit(benchmark::kMillisecond)->Iterations(8);

void BM_HeightOfOneFingertip(benchmark::State& state) {
    const Scene& scene = oneHand();
    core::SegmentationOptions segmentationOptions;
    core::HandSegmenter segmenter(segmentationOptions);
    segmenter.setRig(scene.calibration, scene.pattern);
    core::SurfaceHeight height(core::DetectionOptions{}.height);
    height.setRig(scene.calibration, scene.pattern);
    cv::Mat subtraction, texture, mask;
    core::computeSubtractionAndTexture(scene.pairs.front(), subtraction, texture);
    segmenter.segment(texture, subtraction, mask);
    core::FingertipOptions fingertipOptions;
    fingertipOptions.fingerWidthPx = 16.0 * segmenter.pixelsPerMm();
    core::FingertipScratch scratch;
    core::Fingertips fingertips;
    core::findFingertips(mask, fingertipOptions, scratch, fingertips);
    if (fingertips.empty()) {
        state.SkipWithError("no fingertip found in the scene");
        return;
    }
    core::HeightEvidence evidence;
    Timings timings;
    for (auto _ : state) {
        const auto start = Clock::now();
        const core::Fingertip& tip = fingertips.front();
        height.measureFingertip(scene.pairs.front(), mask, tip.tip, tip.direction, tip.widthPx, evidence);
        benchmark::DoNotOptimize(height.estimate(evidence));
        timings.add(Clock::now() - start);
    }
    timings.report(state);
}
BENCHMARK(BM_HeightOfOneFingertip)->Unit(benchmark::kMicrosecond);

// The check of the frames' order on every pair: S correlated with the table's code along sampled rows.
void BM_PolarityCheck(benchmark::State& state) {
    const Scene& scene = oneHand();
    core::HandSegmenter segmenter{core::SegmentationOptions{}};
    segmenter.setRig(scene.calibration, scene.pattern);
    core::PolarityLock lock;
    lock.setRig(segmenter.tableCode(), segmenter.judgedRegion());
    cv::Mat subtraction, texture;
    core::computeSubtractionAndTexture(scene.pairs.front(), subtraction, texture);
    for (auto _ : state)
        benchmark::DoNotOptimize(lock.relock(subtraction));
    state.counters["correlation"] = lock.correlation();
}
BENCHMARK(BM_PolarityCheck)->Unit(benchmark::kMicrosecond);

// The code's evidence over every block of the frame: the first step of the segmentation, whatever is in view.
void BM_CodeEvidence(benchmark::State& state) {
    const Scene& scene = oneHand();
    core::HandSegmenter segmenter{core::SegmentationOptions{}};
    segmenter.setRig(scene.calibration, scene.pattern);
    core::CodeEvidence evidence;
    cv::Mat subtraction, texture;
    core::computeSubtractionAndTexture(scene.pairs.front(), subtraction, texture);
    for (auto _ : state) {
        core::measureCodeEvidence(subtraction, segmenter.tableCode(), evidence);
        benchmark::DoNotOptimize(evidence.narrow.correlation.data);
    }
}
BENCHMARK(BM_CodeEvidence)->Unit(benchmark::kMicrosecond);

// The code's blur, read once per rig from the first pair that shows the code.
void BM_CodeBlur(benchmark::State& state) {
    cv::setNumThreads(1);
    const Scene& scene = oneHand();
    core::HandSegmenter segmenter{core::SegmentationOptions{}};
    segmenter.setRig(scene.calibration, scene.pattern);
    core::CodeBlurMeter meter;
    meter.setRig(scene.calibration, scene.pattern, segmenter.judgedRegion());
    cv::Mat subtraction, texture;
    core::computeSubtractionAndTexture(scene.pairs.front(), subtraction, texture);
    double blur = 0.0;
    for (auto _ : state)
        blur = meter.measure(subtraction).value_or(-1.0);
    state.counters["blur_px"] = blur;
}
BENCHMARK(BM_CodeBlur)->Unit(benchmark::kMillisecond);

// The one-hand scene's first pair as the calibration's check sees it: S, the hand's mask, the check set up.
struct CheckedPair {
    core::RegistrationCheck registration;
    cv::Mat subtraction, mask;
};

CheckedPair checkedPair(const Scene& scene) {
    core::HandSegmenter segmenter{core::SegmentationOptions{}};
    segmenter.setRig(scene.calibration, scene.pattern);
    CheckedPair checked;
    checked.registration.setRig(scene.calibration, scene.pattern, segmenter.judgedRegion(), 0.5);
    cv::Mat texture;
    core::computeSubtractionAndTexture(scene.pairs.front(), checked.subtraction, texture);
    segmenter.segment(texture, checked.subtraction, checked.mask);
    return checked;
}

// The calibration's check: one tile of the table per pair (the hand's tiles passed over), as the pipeline
// runs it.
void BM_RegistrationCheck(benchmark::State& state) {
    cv::setNumThreads(1);
    const Scene& scene = oneHand();
    CheckedPair checked = checkedPair(scene);
    core::RegistrationCheck& registration = checked.registration;
    const cv::Mat& subtraction = checked.subtraction;
    const cv::Mat& mask = checked.mask;
    Timings timings;
    std::int64_t timestampUs = 0;
    for (auto _ : state) {
        const auto start = Clock::now();
        registration.update(subtraction, mask, ++timestampUs);
        timings.add(Clock::now() - start);
    }
    timings.report(state);
    state.counters["tiles"] = registration.tileCount();
    state.counters["error_px"] = registration.errorPx().value_or(-1.0);
}
BENCHMARK(BM_RegistrationCheck)->Unit(benchmark::kMicrosecond);

// One round of the calibration's correction over 16 tiles of a calibration that holds: the move fitted,
// nothing to correct (the pipeline runs it once every 16 pairs).
void BM_CalibrationCorrectorRound(benchmark::State& state) {
    cv::setNumThreads(1);
    const Scene& scene = oneHand();
    CheckedPair checked = checkedPair(scene);
    core::RegistrationCheck& registration = checked.registration;
    const cv::Mat& subtraction = checked.subtraction;
    const cv::Mat& mask = checked.mask;
    std::int64_t timestampUs = 0;
    while (static_cast<int>(registration.latest().size()) < core::RegistrationOptions{}.tilesPerEstimate)
        registration.update(subtraction, mask, ++timestampUs);
    core::CalibrationCorrector corrector;
    corrector.setRig(scene.calibration, core::RegistrationOptions{}.tilesPerEstimate);
    Timings timings;
    std::uint64_t measured = 0;
    for (auto _ : state) {
        measured += static_cast<std::uint64_t>(core::RegistrationOptions{}.tilesPerEstimate);
        const auto start = Clock::now();
        benchmark::DoNotOptimize(corrector.update(measured, registration.latest()));
        timings.add(Clock::now() - start);
    }
    timings.report(state);
}
BENCHMARK(BM_CalibrationCorrectorRound)->Unit(benchmark::kMicrosecond);

void runPipeline(benchmark::State& state, const Scene& scene) {
    cv::setNumThreads(1);
    core::TouchPipeline pipeline;
    const core::PipelineSettings settings{scene.calibration, scene.pattern, 0.0};
    // The scene's pairs over and over, their timestamps moved on each round as a camera's would be.
    std::vector<core::FramePair> pairs = scene.pairs;
    const std::int64_t roundUs =
        pairs.back().latest().timestampUs - pairs.front().latest().timestampUs + 16667;
    const auto nextRound = [&] {
        for (core::FramePair& pair : pairs) {
            pair.positive.timestampUs += roundUs;
            pair.negative.timestampUs += roundUs;
        }
    };
    for (const core::FramePair& pair : pairs)  // the rig prepared, the buffers sized
        pipeline.process(pair, settings);
    nextRound();
    Timings timings;
    std::size_t i = 0;
    for (auto _ : state) {
        const auto start = Clock::now();
        benchmark::DoNotOptimize(pipeline.process(pairs[i], settings).contacts.size());
        timings.add(Clock::now() - start);
        if (++i == pairs.size()) {
            i = 0;
            nextRound();
        }
    }
    timings.report(state);
}

// A hand that moves: every pair is segmented.
void BM_TouchPipelineOneHand(benchmark::State& state) {
    runPipeline(state, movingHand());
}
BENCHMARK(BM_TouchPipelineOneHand)->Unit(benchmark::kMillisecond);

// A hand held still: its fingertips are found again in every pair.
void BM_TouchPipelineStillHand(benchmark::State& state) {
    runPipeline(state, oneHand());
}
BENCHMARK(BM_TouchPipelineStillHand)->Unit(benchmark::kMillisecond);

// The table with nobody at it: the scene stands still, and the segmentation need not run again.
void BM_TouchPipelineNoHand(benchmark::State& state) {
    runPipeline(state, noHand());
}
BENCHMARK(BM_TouchPipelineNoHand)->Unit(benchmark::kMillisecond);

}  // namespace

// Structured-light costs on one core: pattern generation (once per start), and per camera frame pair at
// 648x488: S and T, binarisation, the full-frame decode and the per-fingertip decode.
#include <map>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_image.h"
#include "core/code_index.h"
#include "core/code_sampling.h"
#include "core/embedding.h"
#include "core/frame.h"
#include "core/geometry.h"
#include "core/pattern.h"

namespace {

using namespace everytouch;

// The default pattern, generated once for the frame benchmarks.
const cv::Mat& benchPattern() {
    static const cv::Mat pattern = core::generatePattern({});
    return pattern;
}

// Projector pixels -> camera pixels: about one camera pixel per projector pixel, slightly rotated and tilted.
Eigen::Matrix3d benchHomography() {
    Eigen::Matrix3d h;
    h << 0.98, -0.05, 14, 0.04, 0.97, 10, 1e-5, 2e-5, 1;
    return h;
}

// A frame pair of the embedded code on a light surface: random content, delta 10, albedo 0.7, noise 2 DN.
const core::FramePair& benchPair(int type) {
    static std::map<int, core::FramePair> pairs;
    if (auto it = pairs.find(type); it != pairs.end())
        return it->second;
    cv::Mat content(480, 640, CV_8UC3);
    cv::RNG rng(1);
    rng.fill(content, cv::RNG::UNIFORM, 0, 256);
    cv::Mat positive, negative;
    core::embedCode(content, benchPattern(), 10, positive, negative);
    cv::Matx33d h;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            h(r, c) = benchHomography()(r, c);
    core::FramePair pair;
    for (auto [shown, frame] : {std::pair{&positive, &pair.positive}, {&negative, &pair.negative}}) {
        cv::Mat camera, noise(488, 648, CV_32FC3);
        cv::warpPerspective(*shown, camera, h, {648, 488}, cv::INTER_AREA);
        camera.convertTo(camera, CV_32FC3, 0.7 * 0.75, 20);
        rng.fill(noise, cv::RNG::NORMAL, 0, 2);
        camera += noise;
        if (type == CV_8UC1)
            cv::cvtColor(camera, camera, cv::COLOR_BGR2GRAY);
        camera.convertTo(frame->image, type);
    }
    pair.negative.polarity = core::Polarity::Negative;
    pair.negative.index = 1;
    return pairs.emplace(type, pair).first->second;
}

const cv::Mat& benchCodeImage() {
    static const cv::Mat codeImage = [] {
        cv::Mat subtraction, texture, localMean, bits;
        core::computeSubtractionAndTexture(benchPair(CV_8UC3), subtraction, texture);
        core::BinarizationOptions options;
        core::binarizeSubtraction(subtraction, 3, options, localMean, bits);
        return bits;
    }();
    return codeImage;
}

void BM_GeneratePattern640x480(benchmark::State& state) {
    cv::setNumThreads(1);
    core::PatternOptions options;
    for (auto _ : state) {
        benchmark::DoNotOptimize(core::generatePattern(options));
        ++options.seed;
    }
}
BENCHMARK(BM_GeneratePattern640x480)->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_EmbedCode640x480(benchmark::State& state) {
    cv::setNumThreads(1);
    cv::Mat content(480, 640, CV_8UC3), positive, negative;
    cv::randu(content, 0, 256);
    const cv::Mat& pattern = benchPattern();
    for (auto _ : state)
        core::embedCode(content, pattern, 10, positive, negative);
}
BENCHMARK(BM_EmbedCode640x480)->Unit(benchmark::kMicrosecond);

void BM_SubtractionAndTexture648x488(benchmark::State& state) {
    cv::setNumThreads(1);
    const core::FramePair& pair = benchPair(static_cast<int>(state.range(0)));
    cv::Mat subtraction, texture;
    for (auto _ : state)
        core::computeSubtractionAndTexture(pair, subtraction, texture);
}
BENCHMARK(BM_SubtractionAndTexture648x488)->Arg(CV_8UC1)->Arg(CV_8UC3)->Unit(benchmark::kMicrosecond);

void BM_Binarize648x488(benchmark::State& state) {
    cv::setNumThreads(1);
    cv::Mat subtraction, texture, localMean, codeImage;
    core::computeSubtractionAndTexture(benchPair(CV_8UC3), subtraction, texture);
    const core::BinarizationOptions options;
    for (auto _ : state)
        core::binarizeSubtraction(subtraction, 3, options, localMean, codeImage);
}
BENCHMARK(BM_Binarize648x488)->Unit(benchmark::kMicrosecond);

// Every projector window's observed code through the homography (eq. 17-18 for all 635 x 475 windows at once)
// and its Hamming distance to the pattern.
void BM_MatchAllWindows640x480(benchmark::State& state) {
    cv::setNumThreads(1);
    const cv::Mat& codeImage = benchCodeImage();
    core::WindowAgreement agreement;
    for (auto _ : state)
        core::matchAllWindows(codeImage, benchHomography(), benchPattern(), 6, agreement);
}
BENCHMARK(BM_MatchAllWindows640x480)->Unit(benchmark::kMicrosecond);

// One fingertip: F_P = H_PC F_C, expected code, observed code (36 bits through H_PC^-1), Hamming distance.
void BM_DecodeAtFingertip(benchmark::State& state) {
    const cv::Mat& codeImage = benchCodeImage();
    const Eigen::Matrix3d cameraToProjector = benchHomography().inverse();
    const cv::Rect anchors = core::codedRegion(benchPattern().size(), 6);
    Eigen::Vector2d fingertip(300.3, 200.7);
    int distance = 0;
    for (auto _ : state) {
        const core::CodeSample sample = core::sampleCodeAtCamera(codeImage, cameraToProjector, fingertip, 6);
        if (anchors.contains(sample.anchor))
            distance +=
                core::hammingDistance(core::codeAt(benchPattern(), sample.anchor, 6), sample.observed);
        fingertip.x() = fingertip.x() < 500 ? fingertip.x() + 1 : 100;
    }
    benchmark::DoNotOptimize(distance);
}
BENCHMARK(BM_DecodeAtFingertip);

void BM_BuildCodeIndex640x480(benchmark::State& state) {
    for (auto _ : state)
        benchmark::DoNotOptimize(core::CodeIndex(benchPattern(), 6));
}
BENCHMARK(BM_BuildCodeIndex640x480)->Unit(benchmark::kMillisecond);

// A camera patch decoded through the index alone: a window's code with two wrong and four unknown bits.
void BM_CodeIndexMatch(benchmark::State& state) {
    static const core::CodeIndex index(benchPattern(), 6);
    cv::RNG rng(2);
    std::vector<core::ObservedCode> observations;
    const cv::Rect anchors = core::codedRegion(benchPattern().size(), 6);
    for (int i = 0; i < 256; ++i) {
        const cv::Point anchor(anchors.x + rng.uniform(0, anchors.width),
                               anchors.y + rng.uniform(0, anchors.height));
        core::ObservedCode observed{core::codeAt(benchPattern(), anchor, 6), (std::uint64_t{1} << 36) - 1};
        for (int k = 0; k < 2; ++k)
            observed.bits ^= std::uint64_t{1} << rng.uniform(0, 36);
        for (int k = 0; k < 4; ++k)
            observed.known &= ~(std::uint64_t{1} << rng.uniform(0, 36));
        observed.bits &= observed.known;
        observations.push_back(observed);
    }
    std::size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(index.match(observations[i++ % observations.size()], 3));
}
BENCHMARK(BM_CodeIndexMatch);

// Homography-free decode of one camera point: 3 x 3 sampling phases, each looked up in the index.
void BM_LocateCode(benchmark::State& state) {
    static const core::CodeIndex index(benchPattern(), 6);
    const cv::Mat& codeImage = benchCodeImage();
    const Eigen::Matrix3d cameraToProjector = benchHomography().inverse();
    Eigen::Vector2d point(300.3, 200.7);
    for (auto _ : state) {
        benchmark::DoNotOptimize(core::locateCode(codeImage, index, cameraToProjector, point));
        point.x() = point.x() < 500 ? point.x() + 1 : 100;
    }
}
BENCHMARK(BM_LocateCode);

}  // namespace

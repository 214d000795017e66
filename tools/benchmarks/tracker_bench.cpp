// The tracker's cost per frame: assignment, touch state and filtering for every finger.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "core/contact_tracker.h"

namespace {

using everytouch::core::FingerObservation;

constexpr double kPxPerMm = 1280.0 / 276.5;  // the paper-like rig
constexpr std::int64_t kFrameUs = 8333;      // 120 Hz
constexpr int kFrames = 1200;

// `fingers` fingertips circling once in kFrames frames (so the sequence repeats seamlessly) with 0.5 mm of
// jitter, heights wandering across the 3 mm touch height so that touches begin and end.
std::vector<std::vector<FingerObservation>> circlingFingers(int fingers) {
    std::mt19937 random(1);
    std::normal_distribution<double> jitter(0.0, 0.5);
    std::vector<std::vector<FingerObservation>> frames(kFrames);
    for (int f = 0; f < kFrames; ++f) {
        for (int i = 0; i < fingers; ++i) {
            const double angle = 2.0 * std::numbers::pi *
                                 (static_cast<double>(i) / fingers + static_cast<double>(f) / kFrames);
            const Eigen::Vector2d mm(140.0 + 70.0 * std::cos(angle) + jitter(random),
                                     125.0 + 70.0 * std::sin(angle) + jitter(random));
            const double height = 3.0 + 4.0 * std::sin(2.0 * std::numbers::pi * 4.0 * f / kFrames + i);
            frames[f].push_back({mm * kPxPerMm, height, 0.5, false});
        }
    }
    return frames;
}

void BM_ContactTrackerUpdate(benchmark::State& state) {
    const auto frames = circlingFingers(static_cast<int>(state.range(0)));
    everytouch::core::ContactTracker tracker{everytouch::core::TrackerOptions{}};
    everytouch::core::Contacts contacts;
    std::int64_t timeUs = 0;
    int frame = 0;
    for (auto _ : state) {
        timeUs += kFrameUs;
        tracker.update(timeUs, frames[frame], 3.0, kPxPerMm, contacts);
        benchmark::DoNotOptimize(contacts.data());
        frame = (frame + 1) % kFrames;
    }
}
BENCHMARK(BM_ContactTrackerUpdate)->Arg(2)->Arg(10);

}  // namespace

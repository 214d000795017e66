// A camera frame's way out of the stream's buffer: one copy, with the colour conversion it needs.
#include <vector>

#include <benchmark/benchmark.h>

#include "io/camera_pixels.h"

namespace {

using everytouch::io::CameraPixels;

void BM_ConvertCameraPixels648x488(benchmark::State& state) {
    const auto pixels = static_cast<CameraPixels>(state.range(0));
    const cv::Size size(648, 488);
    std::vector<std::uint8_t> buffer(everytouch::io::cameraPixelsBytes(size, pixels));
    for (std::size_t i = 0; i < buffer.size(); ++i)
        buffer[i] = static_cast<std::uint8_t>(i * 7 + i / 648);
    cv::Mat image;
    for (auto _ : state) {
        everytouch::io::convertCameraPixels(buffer.data(), size, pixels, image);
        benchmark::DoNotOptimize(image.data);
    }
    state.SetLabel(std::string(everytouch::io::cameraPixelsName(pixels)));
}
BENCHMARK(BM_ConvertCameraPixels648x488)
    ->Arg(static_cast<int>(CameraPixels::Mono8))
    ->Arg(static_cast<int>(CameraPixels::Rgb8))
    ->Arg(static_cast<int>(CameraPixels::BayerRg8))
    ->Unit(benchmark::kMicrosecond);

}  // namespace

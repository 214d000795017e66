// A camera frame's way out of the stream's buffer: one copy, with the colour conversion it needs.
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>

#include "io/camera_pixels.h"
#include "io/v4l2_pixels.h"

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

// A V4L2 camera's frame into ours: GREY copied, YUYV to BGR, MJPG decoded (a camera frame of smooth content
// with texture, compressed at quality 90 as a webcam might).
void BM_ConvertV4l2Pixels648x488(benchmark::State& state) {
    using everytouch::io::V4l2Pixels;
    const auto pixels = static_cast<V4l2Pixels>(state.range(0));
    const cv::Size size(648, 488);
    std::vector<std::uint8_t> buffer;
    std::size_t bytesPerLine = 0;
    if (pixels == V4l2Pixels::Mjpeg) {
        cv::Mat scene(size, CV_8UC3);
        for (int y = 0; y < size.height; ++y)
            for (int x = 0; x < size.width; ++x)
                scene.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(x / 3 + (x * y) % 17),
                                                      static_cast<uchar>(y / 2 + (x + 3 * y) % 13),
                                                      static_cast<uchar>(120 + (x ^ y) % 31));
        cv::imencode(".jpg", scene, buffer, {cv::IMWRITE_JPEG_QUALITY, 90});
    } else {
        bytesPerLine = static_cast<std::size_t>(size.width) * (pixels == V4l2Pixels::Grey ? 1 : 2);
        buffer.resize(bytesPerLine * static_cast<std::size_t>(size.height));
        for (std::size_t i = 0; i < buffer.size(); ++i)
            buffer[i] = static_cast<std::uint8_t>(i * 7 + i / 648);
    }
    cv::Mat image;
    for (auto _ : state) {
        if (!everytouch::io::convertV4l2Pixels(buffer.data(), buffer.size(), size, bytesPerLine, pixels,
                                               image))
            state.SkipWithError("the frame did not convert");
        benchmark::DoNotOptimize(image.data);
    }
    state.SetLabel(everytouch::io::fourCcName(everytouch::io::v4l2FourCc(pixels)));
}
BENCHMARK(BM_ConvertV4l2Pixels648x488)
    ->Arg(static_cast<int>(everytouch::io::V4l2Pixels::Grey))
    ->Arg(static_cast<int>(everytouch::io::V4l2Pixels::Yuyv))
    ->Arg(static_cast<int>(everytouch::io::V4l2Pixels::Mjpeg))
    ->Unit(benchmark::kMicrosecond);

}  // namespace

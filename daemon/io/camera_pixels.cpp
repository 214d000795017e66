#include "io/camera_pixels.h"

#include <algorithm>
#include <array>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace everytouch::io {

namespace {

constexpr std::array<std::pair<CameraPixels, std::string_view>, 7> kNames = {{
    {CameraPixels::Mono8, "Mono8"},
    {CameraPixels::Rgb8, "RGB8"},
    {CameraPixels::Bgr8, "BGR8"},
    {CameraPixels::BayerRg8, "BayerRG8"},
    {CameraPixels::BayerBg8, "BayerBG8"},
    {CameraPixels::BayerGr8, "BayerGR8"},
    {CameraPixels::BayerGb8, "BayerGB8"},
}};

// OpenCV names a Bayer conversion after the second row's second and third pixels, GenICam after the first
// row's first two: GenICam's RG is OpenCV's BG, and so on.
int bayerConversion(CameraPixels pixels) {
    switch (pixels) {
        case CameraPixels::BayerRg8:
            return cv::COLOR_BayerBG2BGR;
        case CameraPixels::BayerBg8:
            return cv::COLOR_BayerRG2BGR;
        case CameraPixels::BayerGr8:
            return cv::COLOR_BayerGB2BGR;
        case CameraPixels::BayerGb8:
            return cv::COLOR_BayerGR2BGR;
        default:
            return -1;
    }
}

}  // namespace

std::string_view cameraPixelsName(CameraPixels pixels) {
    for (const auto& [value, name] : kNames)
        if (value == pixels)
            return name;
    return "?";
}

std::optional<CameraPixels> parseCameraPixels(std::string_view name) {
    for (const auto& [value, known] : kNames)
        if (known == name)
            return value;
    return std::nullopt;
}

std::string cameraPixelsNames() {
    std::string names;
    for (const auto& [value, name] : kNames)
        names += (names.empty() ? "" : ", ") + std::string(name);
    return names;
}

std::optional<CameraPixels> preferredCameraPixels(const std::vector<std::string>& offered) {
    constexpr std::array kPreference = {
        CameraPixels::BayerRg8, CameraPixels::BayerBg8, CameraPixels::BayerGr8, CameraPixels::BayerGb8,
        CameraPixels::Bgr8,     CameraPixels::Rgb8,     CameraPixels::Mono8};
    for (CameraPixels pixels : kPreference)
        if (std::find(offered.begin(), offered.end(), cameraPixelsName(pixels)) != offered.end())
            return pixels;
    return std::nullopt;
}

std::size_t cameraPixelsBytes(cv::Size size, CameraPixels pixels) {
    const std::size_t channels = pixels == CameraPixels::Rgb8 || pixels == CameraPixels::Bgr8 ? 3 : 1;
    return static_cast<std::size_t>(size.area()) * channels;
}

void convertCameraPixels(const std::uint8_t* data, cv::Size size, CameraPixels pixels, cv::Mat& image) {
    // The camera's buffer is only read: the header never writes through.
    auto* bytes = const_cast<std::uint8_t*>(data);
    switch (pixels) {
        case CameraPixels::Mono8:
            cv::Mat(size, CV_8UC1, bytes).copyTo(image);
            return;
        case CameraPixels::Bgr8:
            cv::Mat(size, CV_8UC3, bytes).copyTo(image);
            return;
        case CameraPixels::Rgb8:
            cv::cvtColor(cv::Mat(size, CV_8UC3, bytes), image, cv::COLOR_RGB2BGR);
            return;
        default:
            cv::cvtColor(cv::Mat(size, CV_8UC1, bytes), image, bayerConversion(pixels));
            return;
    }
}

}  // namespace everytouch::io

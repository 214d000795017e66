#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::io {

// The 8-bit GenICam pixel formats a camera frame can arrive in, and how each becomes a frame of ours: gray
// (CV_8UC1) for Mono8, BGR (CV_8UC3) for the colour ones. Bayer mosaics are interpolated with OpenCV.
enum class CameraPixels { Mono8, Rgb8, Bgr8, BayerRg8, BayerBg8, BayerGr8, BayerGb8 };

// The GenICam name ("Mono8", "BayerRG8", ...); parseCameraPixels is its inverse.
std::string_view cameraPixelsName(CameraPixels pixels);
std::optional<CameraPixels> parseCameraPixels(std::string_view name);
// Every name parseCameraPixels accepts, comma-separated, for messages.
std::string cameraPixelsNames();

// Which of the formats a camera offers to use when none is configured: a Bayer mosaic first (colour at one
// byte a pixel, so that a GigE link carries 120 Hz at VGA), then packed colour, then gray. Nothing when the
// camera offers none of ours.
std::optional<CameraPixels> preferredCameraPixels(const std::vector<std::string>& offered);

// Converts one camera image of `size` in `pixels` (rows packed, no padding) into `image` (reallocated only
// when its size or type changes).
void convertCameraPixels(const std::uint8_t* data, cv::Size size, CameraPixels pixels, cv::Mat& image);

// Bytes of one image of `size` in `pixels`.
std::size_t cameraPixelsBytes(cv::Size size, CameraPixels pixels);

}  // namespace everytouch::io

#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "io/camera_pixels.h"

namespace everytouch::io {

// The V4L2 pixel formats a camera frame can arrive in, and how each becomes a frame of ours: gray (CV_8UC1)
// for GREY, BGR (CV_8UC3) for YUYV and MJPEG.
enum class V4l2Pixels { Grey, Yuyv, Mjpeg };

std::uint32_t v4l2FourCc(V4l2Pixels pixels);
// A four-character code as V4L2 prints it ("YUYV", "MJPG").
std::string fourCcName(std::uint32_t fourCc);

// Which of the formats a camera offers (four-character codes) to use: uncompressed colour first, then gray,
// then Motion JPEG, whose compression blurs the faint code that detection reads. `asked` is [Camera]
// PixelFormat=: Mono8 asks for GREY; the other GenICam formats have no V4L2 counterpart that everytouchd
// reads. Nothing when none fits.
std::optional<V4l2Pixels> preferredV4l2Pixels(const std::vector<std::uint32_t>& offered,
                                              std::optional<CameraPixels> asked);

// Converts one frame of `size` (rows `bytesPerLine` apart; for MJPEG the compressed bytes) into `image`
// (reallocated only when its size or type changes, except for MJPEG, which OpenCV decodes into a new
// image). False when `bytes` do not hold the frame or the JPEG data do not decode to `size`: a frame the
// camera or the link damaged.
bool convertV4l2Pixels(const std::uint8_t* data, std::size_t bytes, cv::Size size, std::size_t bytesPerLine,
                       V4l2Pixels pixels, cv::Mat& image);

}  // namespace everytouch::io

#include "io/v4l2_pixels.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <array>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace everytouch::io {

std::uint32_t v4l2FourCc(V4l2Pixels pixels) {
    switch (pixels) {
        case V4l2Pixels::Grey:
            return V4L2_PIX_FMT_GREY;
        case V4l2Pixels::Yuyv:
            return V4L2_PIX_FMT_YUYV;
        case V4l2Pixels::Mjpeg:
            return V4L2_PIX_FMT_MJPEG;
    }
    return 0;
}

std::string fourCcName(std::uint32_t fourCc) {
    std::string name;
    for (int shift = 0; shift < 32; shift += 8) {
        const char c = static_cast<char>((fourCc >> shift) & 0xff);
        name += c >= 0x20 && c < 0x7f ? c : '?';
    }
    // V4L2 pads short names with spaces ("Y16 ").
    name.erase(name.find_last_not_of(' ') + 1);
    return name;
}

std::optional<V4l2Pixels> preferredV4l2Pixels(const std::vector<std::uint32_t>& offered,
                                              std::optional<CameraPixels> asked) {
    const auto isOffered = [&](V4l2Pixels pixels) {
        return std::find(offered.begin(), offered.end(), v4l2FourCc(pixels)) != offered.end();
    };
    if (asked) {
        if (*asked == CameraPixels::Mono8 && isOffered(V4l2Pixels::Grey))
            return V4l2Pixels::Grey;
        return std::nullopt;
    }
    for (V4l2Pixels pixels : {V4l2Pixels::Yuyv, V4l2Pixels::Grey, V4l2Pixels::Mjpeg})
        if (isOffered(pixels))
            return pixels;
    return std::nullopt;
}

bool convertV4l2Pixels(const std::uint8_t* data, std::size_t bytes, cv::Size size, std::size_t bytesPerLine,
                       V4l2Pixels pixels, cv::Mat& image) {
    if (data == nullptr || size.width <= 0 || size.height <= 0)
        return false;
    // The camera's buffer is only read: the headers never write through.
    auto* raw = const_cast<std::uint8_t*>(data);
    switch (pixels) {
        case V4l2Pixels::Grey:
        case V4l2Pixels::Yuyv: {
            const std::size_t rowBytes =
                static_cast<std::size_t>(size.width) * (pixels == V4l2Pixels::Grey ? 1 : 2);
            if (bytesPerLine < rowBytes ||
                bytes < bytesPerLine * static_cast<std::size_t>(size.height - 1) + rowBytes)
                return false;
            if (pixels == V4l2Pixels::Grey)
                cv::Mat(size, CV_8UC1, raw, bytesPerLine).copyTo(image);
            else
                cv::cvtColor(cv::Mat(size, CV_8UC2, raw, bytesPerLine), image, cv::COLOR_YUV2BGR_YUYV);
            return true;
        }
        case V4l2Pixels::Mjpeg: {
            if (bytes == 0)
                return false;
            cv::Mat decoded;
            try {
                decoded = cv::imdecode(
                    cv::Mat(1, static_cast<int>(std::min<std::size_t>(bytes, INT32_MAX)), CV_8UC1, raw),
                    cv::IMREAD_COLOR);
            } catch (const cv::Exception&) {
                return false;
            }
            if (decoded.size() != size || decoded.type() != CV_8UC3)
                return false;
            image = decoded;
            return true;
        }
    }
    return false;
}

}  // namespace everytouch::io

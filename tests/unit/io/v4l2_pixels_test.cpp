#include "io/v4l2_pixels.h"

#include <linux/videodev2.h>

#include <gtest/gtest.h>

#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace everytouch::io {
namespace {

// Packs two pixels per four bytes, Y0 U Y1 V, rows `bytesPerLine` apart.
std::vector<std::uint8_t> yuyv(cv::Size size, std::size_t bytesPerLine, int (*luma)(int x, int y), int u,
                               int v) {
    std::vector<std::uint8_t> bytes(bytesPerLine * size.height, 0);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; x += 2) {
            std::uint8_t* p = bytes.data() + y * bytesPerLine + 2 * x;
            p[0] = static_cast<std::uint8_t>(luma(x, y));
            p[1] = static_cast<std::uint8_t>(u);
            p[2] = static_cast<std::uint8_t>(luma(x + 1, y));
            p[3] = static_cast<std::uint8_t>(v);
        }
    return bytes;
}

TEST(V4l2Pixels, YuyvBecomesBgrWithVideoRangeLuma) {
    const cv::Size size(8, 4);
    // Video range: luma 16 is black, 235 white; chroma 128 is no colour.
    const auto bytes = yuyv(
        size, 20, [](int x, int) { return x < 4 ? 16 : 235; }, 128, 128);
    cv::Mat image;
    ASSERT_TRUE(convertV4l2Pixels(bytes.data(), bytes.size(), size, 20, V4l2Pixels::Yuyv, image));
    ASSERT_EQ(image.type(), CV_8UC3);
    ASSERT_EQ(image.size(), size);
    EXPECT_EQ(image.at<cv::Vec3b>(2, 1), cv::Vec3b(0, 0, 0));
    EXPECT_EQ(image.at<cv::Vec3b>(2, 6), cv::Vec3b(255, 255, 255));

    // V (red difference) above neutral: red, not blue.
    const auto reddish = yuyv(
        size, 16, [](int, int) { return 120; }, 128, 200);
    ASSERT_TRUE(convertV4l2Pixels(reddish.data(), reddish.size(), size, 16, V4l2Pixels::Yuyv, image));
    const cv::Vec3b pixel = image.at<cv::Vec3b>(1, 3);
    EXPECT_GT(pixel[2], pixel[0] + 100);
}

TEST(V4l2Pixels, GreyRowsAreCopiedWithoutTheirPadding) {
    const cv::Size size(5, 3);
    const std::size_t bytesPerLine = 8;
    std::vector<std::uint8_t> bytes(bytesPerLine * size.height, 99);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            bytes[y * bytesPerLine + x] = static_cast<std::uint8_t>(10 * y + x);
    cv::Mat image;
    ASSERT_TRUE(convertV4l2Pixels(bytes.data(), bytes.size(), size, bytesPerLine, V4l2Pixels::Grey, image));
    ASSERT_EQ(image.type(), CV_8UC1);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            EXPECT_EQ(image.at<std::uint8_t>(y, x), 10 * y + x);
}

TEST(V4l2Pixels, AShortOrDamagedFrameIsRefused) {
    const cv::Size size(8, 4);
    const std::vector<std::uint8_t> bytes(8 * 4, 128);
    cv::Mat image;
    EXPECT_FALSE(convertV4l2Pixels(bytes.data(), bytes.size() - 1, size, 8, V4l2Pixels::Grey, image));
    EXPECT_FALSE(convertV4l2Pixels(bytes.data(), bytes.size(), size, 4, V4l2Pixels::Grey, image));
    EXPECT_FALSE(convertV4l2Pixels(bytes.data(), bytes.size(), size, 16, V4l2Pixels::Yuyv, image));
    EXPECT_FALSE(convertV4l2Pixels(nullptr, 0, size, 8, V4l2Pixels::Grey, image));
    EXPECT_FALSE(convertV4l2Pixels(bytes.data(), bytes.size(), size, 0, V4l2Pixels::Mjpeg, image));
}

TEST(V4l2Pixels, MotionJpegIsDecodedToBgrOfTheFramesSize) {
    cv::Mat colour(48, 64, CV_8UC3);
    for (int y = 0; y < colour.rows; ++y)
        for (int x = 0; x < colour.cols; ++x)
            colour.at<cv::Vec3b>(y, x) =
                cv::Vec3b(static_cast<uchar>(40 + 2 * x), static_cast<uchar>(200 - 2 * y),
                          static_cast<uchar>(120 + x + y));
    std::vector<std::uint8_t> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", colour, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
    cv::Mat image;
    ASSERT_TRUE(convertV4l2Pixels(jpeg.data(), jpeg.size(), colour.size(), 0, V4l2Pixels::Mjpeg, image));
    ASSERT_EQ(image.type(), CV_8UC3);
    EXPECT_LT(cv::norm(image, colour, cv::NORM_L1) / (colour.total() * 3), 3.0);
    // The camera said 640x480 but the data hold 64x48; and data that are no JPEG at all.
    EXPECT_FALSE(
        convertV4l2Pixels(jpeg.data(), jpeg.size(), cv::Size(640, 480), 0, V4l2Pixels::Mjpeg, image));
    const std::vector<std::uint8_t> noise(2000, 0x5a);
    EXPECT_FALSE(convertV4l2Pixels(noise.data(), noise.size(), colour.size(), 0, V4l2Pixels::Mjpeg, image));
}

TEST(V4l2Pixels, UncompressedColourIsPreferredThenGreyThenMotionJpeg) {
    EXPECT_EQ(preferredV4l2Pixels({V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_YUYV}, std::nullopt),
              V4l2Pixels::Yuyv);
    EXPECT_EQ(preferredV4l2Pixels({V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_GREY}, std::nullopt), V4l2Pixels::Grey);
    EXPECT_EQ(preferredV4l2Pixels({V4L2_PIX_FMT_H264, V4L2_PIX_FMT_MJPEG}, std::nullopt), V4l2Pixels::Mjpeg);
    EXPECT_EQ(preferredV4l2Pixels({V4L2_PIX_FMT_RGB565, V4L2_PIX_FMT_H264}, std::nullopt), std::nullopt);
    // [Camera] PixelFormat=Mono8 asks for GREY; the other GenICam formats name nothing a V4L2 camera gives.
    EXPECT_EQ(preferredV4l2Pixels({V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_GREY}, CameraPixels::Mono8),
              V4l2Pixels::Grey);
    EXPECT_EQ(preferredV4l2Pixels({V4L2_PIX_FMT_YUYV}, CameraPixels::Mono8), std::nullopt);
    EXPECT_EQ(preferredV4l2Pixels({V4L2_PIX_FMT_YUYV}, CameraPixels::BayerRg8), std::nullopt);
}

TEST(V4l2Pixels, FourCharacterCodesAreNamedAsV4l2PrintsThem) {
    EXPECT_EQ(fourCcName(V4L2_PIX_FMT_MJPEG), "MJPG");
    EXPECT_EQ(fourCcName(V4L2_PIX_FMT_YUYV), "YUYV");
    EXPECT_EQ(fourCcName(V4L2_PIX_FMT_Y16), "Y16");
    EXPECT_EQ(fourCcName(0x01020304), "????");
}

}  // namespace
}  // namespace everytouch::io

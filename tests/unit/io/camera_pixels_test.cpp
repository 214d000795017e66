#include "io/camera_pixels.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "support/bayer_mosaic.h"

namespace everytouch::io {
namespace {

// A smooth colour image: every channel different, changing slowly enough for any demosaicing to follow.
cv::Mat colourRamp(cv::Size size) {
    cv::Mat image(size, CV_8UC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            image.at<cv::Vec3b>(y, x) =
                cv::Vec3b(static_cast<uchar>(40 + x / 4), static_cast<uchar>(200 - y / 3),
                          static_cast<uchar>(120 + (x + y) / 8));
    return image;
}

double meanDifferenceInside(const cv::Mat& a, const cv::Mat& b) {
    const cv::Rect inside(4, 4, a.cols - 8, a.rows - 8);
    cv::Mat difference;
    cv::absdiff(a(inside), b(inside), difference);
    const cv::Scalar mean = cv::mean(difference);
    return (mean[0] + mean[1] + mean[2]) / 3.0;
}

TEST(CameraPixels, EveryBayerMosaicBecomesTheColoursItWasTakenFrom) {
    const cv::Mat colour = colourRamp(cv::Size(160, 120));
    for (CameraPixels pixels :
         {CameraPixels::BayerRg8, CameraPixels::BayerBg8, CameraPixels::BayerGr8, CameraPixels::BayerGb8}) {
        const cv::Mat mosaic = test::bayerMosaic(colour, std::string(cameraPixelsName(pixels)));
        cv::Mat image;
        convertCameraPixels(mosaic.data, mosaic.size(), pixels, image);
        ASSERT_EQ(image.type(), CV_8UC3);
        EXPECT_LT(meanDifferenceInside(image, colour), 2.0) << cameraPixelsName(pixels);
    }
}

TEST(CameraPixels, PackedColourIsReorderedToBgrAndGrayIsCopied) {
    const cv::Mat colour = colourRamp(cv::Size(64, 48));
    cv::Mat rgb, image;
    cv::cvtColor(colour, rgb, cv::COLOR_BGR2RGB);
    convertCameraPixels(rgb.data, rgb.size(), CameraPixels::Rgb8, image);
    EXPECT_EQ(cv::norm(image, colour, cv::NORM_INF), 0.0);
    convertCameraPixels(colour.data, colour.size(), CameraPixels::Bgr8, image);
    EXPECT_EQ(cv::norm(image, colour, cv::NORM_INF), 0.0);
    cv::Mat gray;
    cv::cvtColor(colour, gray, cv::COLOR_BGR2GRAY);
    convertCameraPixels(gray.data, gray.size(), CameraPixels::Mono8, image);
    ASSERT_EQ(image.type(), CV_8UC1);
    EXPECT_EQ(cv::norm(image, gray, cv::NORM_INF), 0.0);
    EXPECT_EQ(cameraPixelsBytes(cv::Size(64, 48), CameraPixels::Rgb8), 64u * 48u * 3u);
    EXPECT_EQ(cameraPixelsBytes(cv::Size(64, 48), CameraPixels::BayerGb8), 64u * 48u);
}

TEST(CameraPixels, AMosaicIsPreferredThenPackedColourThenGray) {
    EXPECT_EQ(preferredCameraPixels({"Mono8", "RGB8", "BayerGR8", "Mono16"}), CameraPixels::BayerGr8);
    EXPECT_EQ(preferredCameraPixels({"Mono8", "RGB8"}), CameraPixels::Rgb8);
    EXPECT_EQ(preferredCameraPixels({"Mono16", "Mono8"}), CameraPixels::Mono8);
    EXPECT_EQ(preferredCameraPixels({"Mono16", "YUV422_8"}), std::nullopt);
}

TEST(CameraPixels, NamesAreGenICamsBothWays) {
    for (CameraPixels pixels :
         {CameraPixels::Mono8, CameraPixels::Rgb8, CameraPixels::Bgr8, CameraPixels::BayerRg8,
          CameraPixels::BayerBg8, CameraPixels::BayerGr8, CameraPixels::BayerGb8})
        EXPECT_EQ(parseCameraPixels(cameraPixelsName(pixels)), pixels);
    EXPECT_EQ(cameraPixelsName(CameraPixels::BayerRg8), "BayerRG8");
    EXPECT_EQ(parseCameraPixels("mono8"), std::nullopt);
    EXPECT_EQ(cameraPixelsNames(), "Mono8, RGB8, BGR8, BayerRG8, BayerBG8, BayerGR8, BayerGB8");
}

}  // namespace
}  // namespace everytouch::io

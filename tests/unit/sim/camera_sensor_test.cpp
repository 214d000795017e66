// Photometric statistics of the simulated camera against its model (photon transfer): the temporal noise
// variance grows linearly with the signal (shot noise) on top of read noise and quantisation, the mean is
// linear in the light, and the full well clips.
#include "sim/camera_sensor.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim/rig_geometry.h"

namespace everytouch::sim {
namespace {

struct Statistics {
    double mean;      // DN
    double variance;  // temporal, DN^2
};

// Two exposures of a uniform scene; the variance of their difference halved is free of fixed-pattern noise.
Statistics measure(CameraSensor& sensor, const SimParameters& p, double lux, double exposureMs) {
    const cv::Mat radiance(p.cameraSize, CV_32FC3, cv::Scalar::all(lux));
    cv::Mat first, second;
    sensor.expose(radiance, exposureMs, 101, first);
    sensor.expose(radiance, exposureMs, 202, second);
    const cv::Rect centre(p.cameraSize.width / 2 - 100, p.cameraSize.height / 2 - 100, 200, 200);
    cv::Mat a, b;
    first(centre).convertTo(a, CV_64F);
    second(centre).convertTo(b, CV_64F);
    cv::Scalar mean, deviation;
    cv::meanStdDev(a - b, mean, deviation);
    return {cv::mean(a)[0], deviation[0] * deviation[0] / 2.0};
}

TEST(CameraSensor, NoiseVarianceFollowsShotReadAndQuantisationNoise) {
    SimParameters p;
    p.cameraColour = CameraColour::Mono;
    p.vignettingPower = 0.0;
    CameraSensor sensor(p, rigCalibration(p));
    const double exposure = 5.0;
    double dnPerLux = 0.0;
    for (int c = 0; c < 3; ++c)
        dnPerLux += sensor.dnPerLux(c, exposure);
    const double g = sensor.dnPerElectron();
    for (double level : {8.0, 30.0, 80.0, 150.0, 220.0}) {
        const Statistics s = measure(sensor, p, level / dnPerLux, exposure);
        EXPECT_NEAR(s.mean - p.blackLevelDn, level, 0.02 * level + 0.6) << "linearity at " << level << " DN";
        const double electrons = (s.mean - p.blackLevelDn) / g;
        const double expected =
            g * g * (electrons + p.readNoiseElectrons * p.readNoiseElectrons) + 1.0 / 12.0;
        EXPECT_NEAR(s.variance, expected, 0.08 * expected) << "at " << level << " DN";
    }
}

TEST(CameraSensor, GainScalesSignalAndNoise) {
    SimParameters p;
    p.cameraColour = CameraColour::Mono;
    p.vignettingPower = 0.0;
    p.gainDb = 12.0;
    CameraSensor sensor(p, rigCalibration(p));
    EXPECT_NEAR(sensor.dnPerElectron(), 255.0 / p.fullWellElectrons * std::pow(10.0, 0.6), 1e-9);
    double dnPerLux = 0.0;
    for (int c = 0; c < 3; ++c)
        dnPerLux += sensor.dnPerLux(c, 4.0);
    const Statistics s = measure(sensor, p, 100.0 / dnPerLux, 4.0);
    const double g = sensor.dnPerElectron();
    const double expected =
        g * (s.mean - p.blackLevelDn) + g * g * p.readNoiseElectrons * p.readNoiseElectrons + 1.0 / 12.0;
    EXPECT_NEAR(s.variance, expected, 0.08 * expected);
}

TEST(CameraSensor, SaturatesAtTheFullWell) {
    SimParameters p;
    p.cameraColour = CameraColour::Mono;
    CameraSensor sensor(p, rigCalibration(p));
    const cv::Mat radiance(p.cameraSize, CV_32FC3, cv::Scalar::all(1e6));
    cv::Mat image;
    sensor.expose(radiance, 5.0, 1, image);
    EXPECT_EQ(cv::countNonZero(image != 255), 0);
}

TEST(CameraSensor, BayerSensorRecoversColours) {
    SimParameters p;
    p.vignettingPower = 0.0;
    CameraSensor sensor(p, rigCalibration(p));
    const double exposure = 5.0;
    const cv::Scalar redBgr(0, 0, 150.0 / sensor.dnPerLux(2, exposure));
    cv::Mat image;
    sensor.expose(cv::Mat(p.cameraSize, CV_32FC3, redBgr), exposure, 1, image);
    ASSERT_EQ(image.type(), CV_8UC3);
    const cv::Scalar mean = cv::mean(image(cv::Rect(200, 150, 200, 150)));
    EXPECT_NEAR(mean[2], 150.0 + p.blackLevelDn, 4.0);
    EXPECT_LT(mean[0], 4.0);
    EXPECT_LT(mean[1], 4.0);
    // White balance: white light gives equal values on the three channels.
    double white = 0.0;
    sensor.expose(cv::Mat(p.cameraSize, CV_32FC3, cv::Scalar::all(120.0 / sensor.dnPerLux(1, exposure))),
                  exposure, 2, image);
    const cv::Scalar grey = cv::mean(image(cv::Rect(200, 150, 200, 150)));
    for (int c = 0; c < 3; ++c)
        white += grey[c] / 3.0;
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(grey[c], white, 2.0);
}

TEST(CameraSensor, SameSeedSameNoise) {
    SimParameters p;
    CameraSensor sensor(p, rigCalibration(p));
    const cv::Mat radiance(p.cameraSize, CV_32FC3, cv::Scalar::all(40.0));
    cv::Mat a, b, c;
    sensor.expose(radiance, 4.0, 7, a);
    sensor.expose(radiance, 4.0, 8, b);
    sensor.expose(radiance, 4.0, 7, c);
    EXPECT_EQ(cv::norm(a, c, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(a, b, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace everytouch::sim

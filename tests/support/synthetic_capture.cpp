#include "support/synthetic_capture.h"

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/embedding.h"
#include "core/pattern.h"
#include "support/test_rig.h"

namespace everytouch::test {

namespace {

core::Frame expose(const SyntheticScene& scene, const cv::Mat& shown, const cv::Matx33d& projectorToSamples,
                   cv::RNG& rng) {
    const int ss = scene.supersampling;
    cv::Mat light, samples, camera;
    shown.convertTo(light, CV_32FC3);
    // Nearest-neighbour lookup keeps each projector pixel a sharp, uniformly lit square.
    cv::warpPerspective(light, samples, projectorToSamples,
                        {scene.cameraSize.width * ss, scene.cameraSize.height * ss}, cv::INTER_NEAREST,
                        cv::BORDER_CONSTANT, cv::Scalar::all(0));
    cv::resize(samples, camera, scene.cameraSize, 0, 0, cv::INTER_AREA);
    camera = camera * scene.gain + cv::Scalar::all(scene.ambientDn);
    camera = camera.mul(scene.albedo);
    if (scene.grayCamera)
        cv::transform(camera, camera, cv::Matx13f(1.0f / 3, 1.0f / 3, 1.0f / 3));
    cv::Mat noise(camera.size(), camera.type());
    rng.fill(noise, cv::RNG::NORMAL, 0.0, scene.noiseSigmaDn);
    camera += noise;
    core::Frame frame;
    camera.convertTo(frame.image, scene.grayCamera ? CV_8UC1 : CV_8UC3);  // rounds and saturates
    return frame;
}

}  // namespace

const cv::Mat& defaultPattern() {
    static const cv::Mat pattern = core::generatePattern({});
    return pattern;
}

core::FramePair renderCapture(const SyntheticScene& scene) {
    CV_Assert(scene.pattern.type() == CV_8UC1 && scene.content.type() == CV_8UC3 &&
              scene.pattern.size() == scene.content.size());
    CV_Assert(scene.albedo.type() == CV_32FC3 && scene.albedo.size() == scene.cameraSize);
    CV_Assert(scene.supersampling >= 1);
    cv::Mat positive, negative;
    core::embedCode(scene.content, scene.pattern, scene.delta, positive, negative);

    // Camera pixel (u, v) is centred on integer coordinates; its samples (U, V) sit at u = (U + 0.5) / ss -
    // 0.5.
    const double ss = scene.supersampling;
    Eigen::Matrix3d cameraToSamples;
    cameraToSamples << ss, 0, (ss - 1) / 2, 0, ss, (ss - 1) / 2, 0, 0, 1;
    const Eigen::Matrix3d h = cameraToSamples * scene.projectorToCamera;
    cv::Matx33d projectorToSamples;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            projectorToSamples(r, c) = h(r, c);

    cv::RNG rng(scene.seed);
    core::FramePair pair;
    pair.positive = expose(scene, positive, projectorToSamples, rng);
    pair.positive.polarity = core::Polarity::Positive;
    pair.positive.index = 0;
    pair.negative = expose(scene, negative, projectorToSamples, rng);
    pair.negative.polarity = core::Polarity::Negative;
    pair.negative.index = 1;
    pair.negative.timestampUs = 8333;
    return pair;
}

cv::Mat testContent(cv::Size size, std::uint64_t seed) {
    cv::Mat content(size, CV_8UC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            content.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(255 * x / size.width),
                                                    static_cast<uchar>(255 * y / size.height), 128);
    const int w = size.width;
    const int h = size.height;
    cv::rectangle(content, cv::Rect(0, 0, w / 4, h / 3), cv::Scalar::all(0), cv::FILLED);
    cv::rectangle(content, cv::Rect(w / 4, 0, w / 4, h / 3), cv::Scalar::all(255), cv::FILLED);
    cv::rectangle(content, cv::Rect(w / 2, 0, w / 6, h / 3), cv::Scalar(0, 0, 255), cv::FILLED);
    cv::rectangle(content, cv::Rect(2 * w / 3, 0, w / 6, h / 3), cv::Scalar(0, 255, 0), cv::FILLED);
    cv::rectangle(content, cv::Rect(5 * w / 6, 0, w - 5 * w / 6, h / 3), cv::Scalar(255, 0, 0), cv::FILLED);
    // Text-like fine texture and photographic noise.
    cv::Mat texture = content(cv::Rect(0, 2 * h / 3, w / 2, h - 2 * h / 3));
    for (int y = 0; y < texture.rows; ++y)
        for (int x = 0; x < texture.cols; ++x)
            if ((x / 2 + y / 3) % 2 == 0)
                texture.at<cv::Vec3b>(y, x) = cv::Vec3b(20, 20, 20);
    cv::RNG rng(seed);
    rng.fill(content(cv::Rect(w / 2, 2 * h / 3, w / 2, h - 2 * h / 3)), cv::RNG::UNIFORM, 0, 256);
    return content;
}

cv::Mat testAlbedo(cv::Size size) {
    cv::Mat albedo(size, CV_32FC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const float level = 0.725f + 0.175f * static_cast<float>(std::sin(x / 97.0) * std::cos(y / 71.0));
            albedo.at<cv::Vec3f>(y, x) = cv::Vec3f::all(level);
        }
    // A yellowish sheet: blue is mostly absorbed.
    cv::Mat yellow = albedo(cv::Rect(size.width / 2, size.height / 2, size.width / 4, size.height / 4));
    yellow.forEach<cv::Vec3f>([](cv::Vec3f& a, const int*) { a[0] *= 0.3f; });
    cv::circle(albedo, {size.width / 4, size.height / 2}, size.height / 10, cv::Scalar::all(0.25),
               cv::FILLED);
    return albedo;
}

core::Calibration paperLikeCalibrationWithLens(double focalLengthMm) {
    core::Calibration calibration = paperLikeCalibration();
    const double focalPx = focalLengthMm / 0.0074;
    calibration.cameraMatrix(0, 0) = focalPx;
    calibration.cameraMatrix(1, 1) = focalPx;
    return calibration;
}

}  // namespace everytouch::test

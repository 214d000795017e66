#include "sim/camera_sensor.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace everytouch::sim {

namespace {

// Luminance-like weights of a monochrome sensor for B, G, R light.
constexpr float kMonoWeights[3] = {0.11f, 0.59f, 0.30f};

}  // namespace

CameraSensor::CameraSensor(const SimParameters& p, const core::Calibration& calibration)
    : colour_(p.cameraColour),
      dnPerElectron_(255.0 / p.fullWellElectrons * std::pow(10.0, p.gainDb / 20.0)),
      fullWell_(p.fullWellElectrons),
      readNoise_(p.readNoiseElectrons),
      blackLevel_(p.blackLevelDn) {
    const cv::Size size = p.cameraSize;
    const double focal = calibration.cameraMatrix(0, 0);
    const double cx = calibration.cameraMatrix(0, 2), cy = calibration.cameraMatrix(1, 2);
    // Photo-response non-uniformity is a property of the sensor: fixed by the seed, not by the frame.
    cv::Mat prnu(size, CV_32F);
    cv::RNG rng(p.seed * 0x2545F4914F6CDD1Dull + 3);
    rng.fill(prnu, cv::RNG::NORMAL, 1.0, p.prnu);
    const double responseBgr[3] = {p.channelResponse.z(), p.channelResponse.y(), p.channelResponse.x()};
    // White balance: digital gains that make white equal on all channels, as the camera's setting does.
    double balanceBgr[3];
    for (int c = 0; c < 3; ++c) {
        monoWeights_[c] = static_cast<float>(kMonoWeights[c] * responseBgr[c]);
        balanceBgr[c] =
            colour_ == CameraColour::Mono || responseBgr[c] <= 0.0 ? 1.0 : responseBgr[1] / responseBgr[c];
        centreGain_[c] = p.sensitivity / 1000.0 *
                         (colour_ == CameraColour::Mono ? monoWeights_[c] : responseBgr[c]) * dnPerElectron_ *
                         balanceBgr[c];
    }
    const bool mosaic = colour_ != CameraColour::Rgb;
    const int channels = mosaic ? 1 : 3;
    chargeGain_.create(size, CV_MAKETYPE(CV_32F, channels));
    dnGain_.create(size, CV_MAKETYPE(CV_32F, channels));
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const double tangent = std::hypot(x - cx, y - cy) / focal;
            const double cosine = 1.0 / std::sqrt(1.0 + tangent * tangent);
            const double base =
                p.sensitivity / 1000.0 * std::pow(cosine, p.vignettingPower) * prnu.at<float>(y, x);
            if (mosaic) {
                const int channel = mosaicChannel(x, y);
                const bool mono = colour_ == CameraColour::Mono;
                chargeGain_.at<float>(y, x) = static_cast<float>(mono ? base : base * responseBgr[channel]);
                dnGain_.at<float>(y, x) =
                    static_cast<float>(dnPerElectron_ * (mono ? 1.0 : balanceBgr[channel]));
            } else {
                for (int c = 0; c < 3; ++c) {
                    chargeGain_.at<cv::Vec3f>(y, x)[c] = static_cast<float>(base * responseBgr[c]);
                    dnGain_.at<cv::Vec3f>(y, x)[c] = static_cast<float>(dnPerElectron_ * balanceBgr[c]);
                }
            }
        }
}

double CameraSensor::dnPerLux(int channel, double exposureMs) const {
    return centreGain_[channel] * exposureMs;
}

void CameraSensor::expose(const cv::Mat& radiance, double exposureMs, std::uint64_t noiseSeed,
                          cv::Mat& image) {
    CV_Assert(radiance.type() == CV_32FC3 && radiance.size() == chargeGain_.size());
    const cv::Size size = radiance.size();
    const bool mosaic = colour_ != CameraColour::Rgb;
    const int values = mosaic ? size.width : 3 * size.width;
    noise_.create(size, chargeGain_.type());
    cv::RNG rng(noiseSeed);
    rng.fill(noise_, cv::RNG::NORMAL, 0.0, 1.0);
    raw_.create(size, CV_MAKETYPE(CV_8U, mosaic ? 1 : 3));
    filtered_.create(1, values, CV_32F);
    const float exposure = static_cast<float>(exposureMs), fullWell = static_cast<float>(fullWell_);
    const float read2 = static_cast<float>(readNoise_ * readNoise_), black = static_cast<float>(blackLevel_);
    for (int y = 0; y < size.height; ++y) {
        // The light each pixel's colour filter lets through.
        const float* in = radiance.ptr<float>(y);
        float* light = filtered_.ptr<float>();
        if (colour_ == CameraColour::Mono) {
            for (int x = 0; x < size.width; ++x)
                light[x] = monoWeights_[0] * in[3 * x] + monoWeights_[1] * in[3 * x + 1] +
                           monoWeights_[2] * in[3 * x + 2];
        } else if (colour_ == CameraColour::Bayer) {
            const int even = mosaicChannel(0, y), odd = mosaicChannel(1, y);
            for (int x = 0; x < size.width; ++x)
                light[x] = in[3 * x + (x % 2 ? odd : even)];
        } else {
            std::copy(in, in + values, light);
        }
        // Charge: signal, shot noise (Poisson, as a Gaussian of the same variance) and read noise, then the
        // full well; digital value: gain and white balance, black level, 8-bit rounding and clipping.
        const float* gain = chargeGain_.ptr<float>(y);
        const float* toDn = dnGain_.ptr<float>(y);
        const float* noise = noise_.ptr<float>(y);
        uchar* out = raw_.ptr<uchar>(y);
        for (int i = 0; i < values; ++i) {
            const float charge = std::max(0.0f, light[i] * gain[i] * exposure);
            const float noisy = std::clamp(charge + std::sqrt(charge + read2) * noise[i], 0.0f, fullWell);
            out[i] = cv::saturate_cast<uchar>(noisy * toDn[i] + black);
        }
    }
    if (colour_ == CameraColour::Bayer)
        cv::cvtColor(raw_, image, cv::COLOR_BayerBG2BGR);
    else
        raw_.copyTo(image);
}

}  // namespace everytouch::sim

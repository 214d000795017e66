#pragma once

#include <cstdint>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "sim/sim_parameters.h"

namespace everytouch::sim {

// The camera behind the lens: vignetting, colour filters, exposure, shot and read noise, gain, black level,
// saturation, 8-bit quantisation and, for a Bayer sensor, demosaicing.
class CameraSensor {
public:
    CameraSensor(const SimParameters& parameters, const core::Calibration& calibration);

    // radiance: CV_32FC3 (BGR), camera size, illuminance x albedo in lux as the scene sends it to each pixel.
    // image: receives CV_8UC3 (BGR) for Bayer and RGB sensors, CV_8UC1 for a monochrome one.
    // The noise is drawn from `noiseSeed` alone, so a frame is reproducible.
    void expose(const cv::Mat& radiance, double exposureMs, std::uint64_t noiseSeed, cv::Mat& image);

    // Mean digital value (white-balanced, before black level and clipping) per lux of radiance on channel c
    // (0 B, 1 G, 2 R) at the image centre for the exposure: what metering and tests use.
    double dnPerLux(int channel, double exposureMs) const;
    double dnPerElectron() const { return dnPerElectron_; }
    double blackLevelDn() const { return blackLevel_; }

    // Channel behind the colour filter of pixel (x, y) of an RGGB Bayer sensor: 0 B, 1 G, 2 R.
    static int mosaicChannel(int x, int y) {
        return y % 2 == 0 ? (x % 2 == 0 ? 2 : 1) : (x % 2 == 0 ? 1 : 0);
    }

private:
    CameraColour colour_;
    cv::Mat
        chargeGain_;  // electrons per lux-millisecond of each pixel (or channel): vignetting, PRNU, filter
    cv::Mat dnGain_;  // DN per electron of each pixel (or channel): gain and white balance
    double dnPerElectron_;
    double fullWell_, readNoise_, blackLevel_;
    double centreGain_[3];  // white-balanced DN per lux-millisecond at the image centre
    float monoWeights_[3];  // a monochrome pixel's response to B, G, R light
    // Per-frame buffers.
    cv::Mat filtered_, noise_, raw_;
};

}  // namespace everytouch::sim

#pragma once

#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

#include "core/frame.h"

namespace everytouch::core {

// Value of a camera pixel in a code image: the code bit the camera saw there, or none.
inline constexpr uchar kZeroBit = 0;
inline constexpr uchar kOneBit = 1;
inline constexpr uchar kUnknownBit = 255;

// Paper eq. 7 and the content seen by people, from a pair of 8-bit frames of equal size and type (gray or
// BGR):
//   subtraction S = max over channels (C+ - C-)   CV_16SC1
//   texture     T = (C+ + C-) / 2, rounded         the frames' type
// Outputs are reallocated only when the frame size or type changes.
void computeSubtractionAndTexture(const FramePair& pair, cv::Mat& subtraction, cv::Mat& texture);

// How S becomes code bits. On a camera pixel lit by a 1-bit, S ~ 2 delta * gain * albedo (the projector's 2
// delta scaled by the camera's response and the surface's reflectance; ambient light and the content cancel
// in the difference); on a 0-bit S ~ 0 + noise. The amplitude A changes with the surface under the code, but
// about half of the bits around any pixel are ones, so the local mean of S sits halfway between the two
// levels wherever the surface is: it is the threshold, and twice its height above the 0-level is A. A pixel
// is read when the two levels, A apart, are told apart reliably there; otherwise its bit is unknown.
struct BinarizationOptions {
    // Side (camera pixels, odd) of the square over which S is averaged for the threshold: it must hold enough
    // code bits that about half are ones (9x9 camera pixels cover 30 or more projector pixels on rigs where
    // the camera resolves the panel), and be small next to changes of albedo.
    int neighbourhood = 9;
    // Camera noise per frame, DN. The difference of two frames carries sqrt(2) times it (sigma_d), plus 8-bit
    // quantisation's 1/sqrt(12) DN per frame.
    double noiseSigmaDn = 2.0;
    // The local amplitude A must exceed this many sigma_d for any bit to be read; below, the surface is
    // shadowed, black or saturated, or the code too faint for the noise.
    double minAmplitudeSigmas = 2.0;
    // A pixel is unknown when the probability that its bit is wrong, given its S, A and sigma_d (two Gaussian
    // levels A apart), exceeds this: such a bit tells a match from a mismatch too weakly to be counted.
    double maxErrorProbability = 0.25;
    // A pixel whose S lies within this fraction of A from the threshold is unknown whatever the noise: such a
    // camera pixel straddles projector pixels of both values (lens blur, resampling).
    double mixtureMargin = 0.1;
    // S this many sigma_d below the 0-level cannot come from the code: the scene changed between the two
    // frames (motion, flicker); unknown.
    double motionSigmas = 3.0;

    std::optional<std::string> validate() const;
};

// Classifies every pixel of S (CV_16SC1, from frames with `frameChannels` channels: 1 or 3) into kZeroBit,
// kOneBit or kUnknownBit. With 3 channels the 0-level of S is the mean of the largest of three noise samples,
// 0.85 sigma_d, not 0. localMean: receives the local threshold (CV_32FC1); codeImage: receives the bits
// (CV_8UC1). Both are reallocated only when the size changes. Throws std::invalid_argument when
// options.validate() fails.
void binarizeSubtraction(const cv::Mat& subtraction, int frameChannels, const BinarizationOptions& options,
                         cv::Mat& localMean, cv::Mat& codeImage);

}  // namespace everytouch::core

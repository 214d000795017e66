#include "core/code_image.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace everytouch::core {

namespace {

template <int Channels>
void subtractAndAverage(const cv::Mat& positive, const cv::Mat& negative, cv::Mat& subtraction,
                        cv::Mat& texture) {
    for (int y = 0; y < positive.rows; ++y) {
        const uchar* plus = positive.ptr<uchar>(y);
        const uchar* minus = negative.ptr<uchar>(y);
        short* s = subtraction.ptr<short>(y);
        uchar* t = texture.ptr<uchar>(y);
        for (int x = 0; x < positive.cols; ++x) {
            int largest = plus[0] - minus[0];
            for (int c = 0; c < Channels; ++c) {
                largest = std::max(largest, plus[c] - minus[c]);
                t[c] = static_cast<uchar>((plus[c] + minus[c] + 1) >> 1);
            }
            s[x] = static_cast<short>(largest);
            plus += Channels;
            minus += Channels;
            t += Channels;
        }
    }
}

}  // namespace

void computeSubtractionAndTexture(const FramePair& pair, cv::Mat& subtraction, cv::Mat& texture) {
    const cv::Mat& positive = pair.positive.image;
    const cv::Mat& negative = pair.negative.image;
    CV_Assert(positive.type() == CV_8UC1 || positive.type() == CV_8UC3);
    CV_Assert(negative.type() == positive.type() && negative.size() == positive.size());
    subtraction.create(positive.size(), CV_16SC1);
    texture.create(positive.size(), positive.type());
    if (positive.channels() == 1)
        subtractAndAverage<1>(positive, negative, subtraction, texture);
    else
        subtractAndAverage<3>(positive, negative, subtraction, texture);
}

std::optional<std::string> BinarizationOptions::validate() const {
    if (neighbourhood < 3 || neighbourhood % 2 == 0)
        return "neighbourhood: must be an odd number of pixels, at least 3";
    if (!(noiseSigmaDn >= 0) || !std::isfinite(noiseSigmaDn))
        return "noiseSigmaDn: must be a non-negative number";
    if (!(minAmplitudeSigmas >= 0) || !std::isfinite(minAmplitudeSigmas))
        return "minAmplitudeSigmas: must be a non-negative number";
    if (!(maxErrorProbability > 0 && maxErrorProbability <= 0.5))
        return "maxErrorProbability: must be in (0, 0.5]";
    if (!(mixtureMargin >= 0 && mixtureMargin < 0.5))
        return "mixtureMargin: must be in [0, 0.5)";
    if (!(motionSigmas >= 0) || !std::isfinite(motionSigmas))
        return "motionSigmas: must be a non-negative number";
    return std::nullopt;
}

void binarizeSubtraction(const cv::Mat& subtraction, int frameChannels, const BinarizationOptions& options,
                         cv::Mat& localMean, cv::Mat& codeImage) {
    if (auto problem = options.validate())
        throw std::invalid_argument("BinarizationOptions: " + *problem);
    CV_Assert(subtraction.type() == CV_16SC1 && (frameChannels == 1 || frameChannels == 3));
    cv::boxFilter(subtraction, localMean, CV_32F, {options.neighbourhood, options.neighbourhood}, {-1, -1},
                  true, cv::BORDER_REFLECT);
    codeImage.create(subtraction.size(), CV_8UC1);

    const double frameVariance = options.noiseSigmaDn * options.noiseSigmaDn + 1.0 / 12.0;
    const float sigma = static_cast<float>(std::sqrt(2.0 * frameVariance));
    // Mean of the largest of three standard normal samples.
    constexpr float kMaxOfThreeNormals = 0.846284f;
    const float zeroLevel = frameChannels == 3 ? kMaxOfThreeNormals * sigma : 0.0f;
    const float minAmplitude = static_cast<float>(options.minAmplitudeSigmas) * sigma;
    const float lowest = zeroLevel - static_cast<float>(options.motionSigmas) * sigma;
    // Two levels A apart with noise sigma: a value x from the midpoint has log-likelihood ratio x A /
    // sigma^2, and the bit is wrong with probability 1 / (1 + exp(|x| A / sigma^2)).
    const float minLogRatio =
        static_cast<float>(std::log((1.0 - options.maxErrorProbability) / options.maxErrorProbability));
    const float noiseScale = minLogRatio * sigma * sigma;
    const float mixtureMargin = static_cast<float>(options.mixtureMargin);
    for (int y = 0; y < subtraction.rows; ++y) {
        const short* s = subtraction.ptr<short>(y);
        const float* threshold = localMean.ptr<float>(y);
        uchar* bit = codeImage.ptr<uchar>(y);
        for (int x = 0; x < subtraction.cols; ++x) {
            const float amplitude = 2.0f * (threshold[x] - zeroLevel);
            const float value = s[x];
            const float excess = value - threshold[x];
            const float distance = std::abs(excess);
            // distance * amplitude < noiseScale: the bit is wrong with a probability above the limit.
            const bool unreadable = amplitude <= 0.0f || amplitude < minAmplitude || value < lowest ||
                                    distance * amplitude < noiseScale || distance < mixtureMargin * amplitude;
            bit[x] = unreadable ? kUnknownBit : excess > 0 ? kOneBit : kZeroBit;
        }
    }
}

}  // namespace everytouch::core

#include "eval/background_subtraction.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>

#include <opencv2/core.hpp>

namespace everytouch::eval {

namespace {

constexpr int kLevelsPerBin = 8;
constexpr int kBins = 256 / kLevelsPerBin;
// Samples (pixel channels) a bin needs for its sigma to be known to a few per cent.
constexpr std::int64_t kMinSamplesPerBin = 1000;
constexpr double kKeptFraction = 0.95;

// sigma of a Gaussian over the RMS of its samples within the central `kKeptFraction`: the variance of a
// Gaussian truncated at +-q is sigma^2 (1 - 2 q phi(q) / P(|x| <= q)).
double trimmedRmsToSigma() {
    const double q = 1.959963984540054;  // P(|x| <= q) = 0.95
    const double density = std::exp(-0.5 * q * q) / std::sqrt(2.0 * std::numbers::pi);
    return 1.0 / std::sqrt(1.0 - 2.0 * q * density / kKeptFraction);
}

}  // namespace

std::optional<std::string> BackgroundOptions::validate() const {
    if (samples < 3)
        return "samples: at least 3 textures are needed for a median and a noise estimate";
    if (!(falsePixelsPerFrame > 0) || !std::isfinite(falsePixelsPerFrame))
        return "falsePixelsPerFrame: must be a positive number";
    return std::nullopt;
}

int noiseClass(int x, int y, cv::Size size) {
    if (x == 0 || y == 0 || x == size.width - 1 || y == size.height - 1)
        return 4;
    return (y % 2) * 2 + x % 2;
}

NoiseTable estimateTextureNoise(const std::vector<cv::Mat>& textures, int channel, int pixelClass) {
    if (textures.size() < 2)
        throw std::invalid_argument("texture noise: at least two textures are needed");
    const int channels = textures.front().channels();
    CV_Assert(channel >= 0 && channel < channels && pixelClass >= 0 && pixelClass < kNoiseClasses);
    std::vector<std::array<std::int64_t, 256>> histograms(kBins);
    for (auto& histogram : histograms)
        histogram.fill(0);
    for (std::size_t i = 0; i + 1 < textures.size(); ++i) {
        const cv::Mat& a = textures[i];
        const cv::Mat& b = textures[i + 1];
        CV_Assert(a.depth() == CV_8U && a.type() == b.type() && a.size() == b.size());
        for (int y = 0; y < a.rows; ++y) {
            const uchar* pa = a.ptr<uchar>(y);
            const uchar* pb = b.ptr<uchar>(y);
            for (int x = 0; x < a.cols; ++x) {
                if (noiseClass(x, y, a.size()) != pixelClass)
                    continue;
                const int i = x * channels + channel;
                const int level = (pa[i] + pb[i]) / 2;
                ++histograms[level / kLevelsPerBin][std::abs(pa[i] - pb[i])];
            }
        }
    }

    // Each bin with enough samples gives the variance at its centre level.
    std::vector<double> centres, variances;
    for (int bin = 0; bin < kBins; ++bin) {
        std::int64_t total = 0;
        for (std::int64_t count : histograms[bin])
            total += count;
        if (total < kMinSamplesPerBin)
            continue;
        const double kept = kKeptFraction * static_cast<double>(total);
        double taken = 0.0, sumSquares = 0.0;
        for (int d = 0; d < 256 && taken < kept; ++d) {
            const double count = std::min(static_cast<double>(histograms[bin][d]), kept - taken);
            taken += count;
            sumSquares += count * d * d;
        }
        const double differenceSigma = std::sqrt(sumSquares / kept) * trimmedRmsToSigma();
        centres.push_back(bin * kLevelsPerBin + (kLevelsPerBin - 1) / 2.0);
        variances.push_back(differenceSigma * differenceSigma / 2.0);
    }
    if (centres.empty())
        throw std::invalid_argument("texture noise: too few pixels to estimate it");
    // Between them the variance is linear in the level, as a sensor's is (shot noise grows with the signal,
    // read noise does not); beyond the first and the last it stays.
    const double roundingVariance = 1.0 / 12.0;
    NoiseTable sigma{};
    std::size_t upper = 0;
    for (int level = 0; level < 256; ++level) {
        while (upper < centres.size() && centres[upper] < level)
            ++upper;
        double variance;
        if (upper == 0)
            variance = variances.front();
        else if (upper == centres.size())
            variance = variances.back();
        else {
            const double fraction = (level - centres[upper - 1]) / (centres[upper] - centres[upper - 1]);
            variance = variances[upper - 1] * (1.0 - fraction) + variances[upper] * fraction;
        }
        sigma[level] = static_cast<float>(std::sqrt(std::max(variance, roundingVariance)));
    }
    return sigma;
}

double noiseThresholdSigmas(double falsePixelsPerFrame, int pixels, int channels) {
    // A pixel is marked when any channel is beyond the threshold; per channel the two-sided tail is then
    // 1 - (1 - p)^(1/channels) for a pixel probability p.
    const double pixelProbability = std::min(falsePixelsPerFrame / pixels, 0.5);
    const double channelTail = -std::expm1(std::log1p(-pixelProbability) / channels);
    // erfc(k / sqrt 2) = tail, solved by bisection (erfc decreases).
    double low = 0.0, high = 40.0;
    for (int iteration = 0; iteration < 200; ++iteration) {
        const double middle = 0.5 * (low + high);
        if (std::erfc(middle / std::numbers::sqrt2) > channelTail)
            low = middle;
        else
            high = middle;
    }
    return 0.5 * (low + high);
}

BackgroundSubtraction::BackgroundSubtraction(const std::vector<cv::Mat>& textures,
                                             const BackgroundOptions& options) {
    if (const auto problem = options.validate())
        throw std::invalid_argument("background subtraction: " + *problem);
    if (static_cast<int>(textures.size()) < options.samples)
        throw std::invalid_argument("background subtraction: " + std::to_string(options.samples) +
                                    " textures are needed, got " + std::to_string(textures.size()));
    const cv::Mat& first = textures.front();
    const int channels = first.channels();
    for (const cv::Mat& texture : textures)
        CV_Assert(texture.type() == first.type() && texture.size() == first.size() &&
                  texture.depth() == CV_8U);

    background_.create(first.size(), first.type());
    std::vector<uchar> values(textures.size());
    for (int y = 0; y < first.rows; ++y) {
        uchar* out = background_.ptr<uchar>(y);
        for (int x = 0; x < first.cols * channels; ++x) {
            for (std::size_t i = 0; i < textures.size(); ++i)
                values[i] = textures[i].ptr<uchar>(y)[x];
            auto middle = values.begin() + values.size() / 2;
            std::nth_element(values.begin(), middle, values.end());
            out[x] = *middle;
        }
    }

    for (int channel = 0; channel < channels; ++channel)
        for (int pixelClass = 0; pixelClass < kNoiseClasses; ++pixelClass)
            noiseSigmaDn_.push_back(estimateTextureNoise(textures, channel, pixelClass));
    thresholdSigmas_ =
        noiseThresholdSigmas(options.falsePixelsPerFrame, static_cast<int>(first.total()), channels);
    // The difference T - B carries the texture's noise and the median's (variance about pi / 2N of one
    // texture's).
    const double differenceScale =
        std::sqrt(1.0 + std::numbers::pi / (2.0 * static_cast<double>(textures.size())));
    thresholdDn_.create(first.size(), CV_32FC(channels));
    for (int y = 0; y < first.rows; ++y) {
        const uchar* level = background_.ptr<uchar>(y);
        float* threshold = thresholdDn_.ptr<float>(y);
        for (int x = 0; x < first.cols; ++x)
            for (int c = 0; c < channels; ++c) {
                const int i = x * channels + c;
                threshold[i] = static_cast<float>(thresholdSigmas_ * differenceScale *
                                                  noiseSigmaDn(c, noiseClass(x, y, first.size()))[level[i]]);
            }
    }
}

void BackgroundSubtraction::segment(const cv::Mat& texture, cv::Mat& mask) const {
    CV_Assert(texture.type() == background_.type() && texture.size() == background_.size());
    const int channels = texture.channels();
    mask.create(texture.size(), CV_8UC1);
    for (int y = 0; y < texture.rows; ++y) {
        const uchar* t = texture.ptr<uchar>(y);
        const uchar* b = background_.ptr<uchar>(y);
        const float* threshold = thresholdDn_.ptr<float>(y);
        uchar* out = mask.ptr<uchar>(y);
        for (int x = 0; x < texture.cols; ++x) {
            bool changed = false;
            for (int c = 0; c < channels; ++c) {
                const int i = x * channels + c;
                changed |= std::abs(t[i] - b[i]) > threshold[i];
            }
            out[x] = changed ? 255 : 0;
        }
    }
}

}  // namespace everytouch::eval

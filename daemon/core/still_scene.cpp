#include "core/still_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>

#include <opencv2/core/hal/intrin.hpp>

namespace everytouch::core {

namespace {

// The lower quartile of the absolute deviations of normally distributed values, in standard deviations: the
// noise is read from the quietest quarter of the blocks, so that up to three quarters of them may move.
constexpr double kLowerQuartileDeviationPerSigma = 0.3186393639643752;
// A band's noise is learned from at least this many block differences (its spread then to about 10 %).
constexpr std::size_t kMinSamples = 100;
// The noise is learned from every kLearningInterval-th pair: it changes with the light, over seconds.
constexpr int kLearningInterval = 8;
// Each estimate joins an exponential average with this weight before the lowest is kept: the lowest of many
// raw estimates would sit a few of their standard errors below the noise.
constexpr double kSmoothing = 0.2;

// Adds a row of pixels to the column sums of a block row (the sums hold up to 257 rows of 8-bit values).
void addRow(const uchar* row, std::uint16_t* sums, int n) {
    int i = 0;
#if CV_SIMD
    constexpr int kLanes = cv::v_uint8::nlanes;
    for (; i + kLanes <= n; i += kLanes) {
        cv::v_uint16 low, high;
        cv::v_expand(cv::vx_load(row + i), low, high);
        cv::v_store(sums + i, cv::vx_load(sums + i) + low);
        cv::v_store(sums + i + kLanes / 2, cv::vx_load(sums + i + kLanes / 2) + high);
    }
#endif
    for (; i < n; ++i)
        sums[i] = static_cast<std::uint16_t>(sums[i] + row[i]);
}

void addRow(const short* row, std::int32_t* sums, int n) {
    int i = 0;
#if CV_SIMD
    constexpr int kLanes = cv::v_int16::nlanes;
    for (; i + kLanes <= n; i += kLanes) {
        cv::v_int32 low, high;
        cv::v_expand(cv::vx_load(row + i), low, high);
        cv::v_store(sums + i, cv::vx_load(sums + i) + low);
        cv::v_store(sums + i + kLanes / 2, cv::vx_load(sums + i + kLanes / 2) + high);
    }
#endif
    for (; i < n; ++i)
        sums[i] += row[i];
}

// The block means of one block row from its column sums: Channels texture values, then the subtraction's.
template <int Channels>
void sumBlocks(const std::uint16_t* texture, const std::int32_t* subtraction, int blockPx, int blocks,
               float perPixel, float* out) {
    for (int bx = 0; bx < blocks; ++bx, out += Channels + 1) {
        std::uint32_t sums[Channels] = {};
        std::int32_t subtractionSum = 0;
        for (int k = 0; k < blockPx; ++k, texture += Channels) {
            for (int c = 0; c < Channels; ++c)
                sums[c] += texture[c];
            subtractionSum += *subtraction++;
        }
        for (int c = 0; c < Channels; ++c)
            out[c] = static_cast<float>(sums[c]) * perPixel;
        out[Channels] = static_cast<float>(subtractionSum) * perPixel;
    }
}

float quantile(std::vector<float>& values, double fraction) {
    const auto at =
        values.begin() + static_cast<std::ptrdiff_t>(fraction * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), at, values.end());
    return *at;
}

}  // namespace

void StillScene::setRegion(const cv::Rect& region, int blockPx) {
    CV_Assert(blockPx > 0 && blockPx <= 257);
    region_ = region;
    blockPx_ = blockPx;
    reset();
}

void StillScene::reset() {
    measuredPairs_ = 0;
    hasReference_ = false;
    for (auto& group : noise_)
        std::fill(std::begin(group), std::end(group), -1.0);
    for (auto& group : smoothedNoise_)
        std::fill(std::begin(group), std::end(group), -1.0);
}

double StillScene::textureNoise(double brightness) const {
    return std::max(noiseOf(0, std::clamp(static_cast<int>(brightness / kBandDn), 0, kBands - 1)), 0.0);
}

double StillScene::subtractionNoise(double brightness) const {
    return std::max(noiseOf(1, std::clamp(static_cast<int>(brightness / kBandDn), 0, kBands - 1)), 0.0);
}

double StillScene::noiseOf(int group, int band) const {
    if (noise_[group][band] >= 0.0)
        return noise_[group][band];
    double quietest = -1.0;
    for (double noise : noise_[group])
        if (noise >= 0.0 && (quietest < 0.0 || noise < quietest))
            quietest = noise;
    return quietest;
}

int StillScene::bandOf(const float* block) const {
    float sum = 0.0f;
    for (int c = 0; c < textureChannels_; ++c)
        sum += block[c];
    return std::clamp(static_cast<int>(sum / static_cast<float>(textureChannels_) / kBandDn), 0, kBands - 1);
}

void StillScene::measure(const cv::Mat& texture, const cv::Mat& subtraction) {
    CV_Assert(texture.type() == CV_8UC3 || texture.type() == CV_8UC1);
    CV_Assert(subtraction.type() == CV_16SC1 && subtraction.size() == texture.size());
    const cv::Rect region = region_ & cv::Rect(0, 0, texture.cols, texture.rows);
    const int channels = texture.channels();
    const int values = channels + 1;
    const int cols = region.width / blockPx_, rows = region.height / blockPx_;
    const std::size_t size = static_cast<std::size_t>(rows) * cols * values;
    if (channels != textureChannels_ || size != measuredSize_) {
        textureChannels_ = channels;
        measuredSize_ = size;
        measuredPairs_ = 0;
        // Any band may hold every block: reserved now, so that no later pair allocates.
        const std::size_t blocks = size / static_cast<std::size_t>(values);
        for (auto& band : differences_[0])
            band.reserve(blocks * static_cast<std::size_t>(channels));
        for (auto& band : differences_[1])
            band.reserve(blocks);
        hasReference_ = false;
    }
    current_.resize(size);
    // Each block row: the columns' sums over its pixel rows first (one long vectorisable loop per pixel row),
    // then the blocks' sums along them.
    textureColumns_.resize(static_cast<std::size_t>(region.width) * channels);
    subtractionColumns_.resize(static_cast<std::size_t>(region.width));
    const float perPixel = 1.0f / static_cast<float>(blockPx_ * blockPx_);
    for (int by = 0; by < rows; ++by) {
        std::fill(textureColumns_.begin(), textureColumns_.end(), 0);
        std::fill(subtractionColumns_.begin(), subtractionColumns_.end(), 0);
        for (int r = 0; r < blockPx_; ++r) {
            const int y = region.y + by * blockPx_ + r;
            const uchar* t = texture.ptr<uchar>(y) + region.x * channels;
            const short* sub = subtraction.ptr<short>(y) + region.x;
            addRow(t, textureColumns_.data(), static_cast<int>(textureColumns_.size()));
            addRow(sub, subtractionColumns_.data(), static_cast<int>(subtractionColumns_.size()));
        }
        float* out = current_.data() + static_cast<std::size_t>(by) * cols * values;
        if (channels == 3)
            sumBlocks<3>(textureColumns_.data(), subtractionColumns_.data(), blockPx_, cols, perPixel, out);
        else
            sumBlocks<1>(textureColumns_.data(), subtractionColumns_.data(), blockPx_, cols, perPixel, out);
    }
}

void StillScene::learnNoise(const std::vector<float>& earlier) {
    const int values = textureChannels_ + 1;
    for (auto& group : differences_)
        for (auto& band : group)
            band.clear();
    for (std::size_t block = 0; block < current_.size(); block += static_cast<std::size_t>(values)) {
        const int band = bandOf(&earlier[block]);
        for (int v = 0; v < values; ++v)
            differences_[v < textureChannels_ ? 0 : 1][band].push_back(current_[block + v] -
                                                                       earlier[block + v]);
    }
    for (int group = 0; group < 2; ++group)
        for (int band = 0; band < kBands; ++band) {
            std::vector<float>& differences = differences_[group][band];
            if (differences.size() < kMinSamples)
                continue;
            const float centre = quantile(differences, 0.5);
            for (float& d : differences)
                d = std::abs(d - centre);
            const double spread = quantile(differences, 0.25) / kLowerQuartileDeviationPerSigma;
            double& smoothed = smoothedNoise_[group][band];
            smoothed = smoothed < 0.0 ? spread : smoothed + kSmoothing * (spread - smoothed);
            double& noise = noise_[group][band];
            noise = noise < 0.0 ? smoothed : std::min(noise, smoothed);
        }
}

bool StillScene::matchesReference(const cv::Mat& texture, const cv::Mat& subtraction) {
    measure(texture, subtraction);
    if (measuredPairs_ >= 2 && (measuredPairs_ == 2 || ++pairsSinceLearning_ >= kLearningInterval)) {
        learnNoise(beforePrevious_);
        pairsSinceLearning_ = 0;
    }
    bool matches = hasReference_ && noiseOf(0, 0) >= 0.0 && noiseOf(1, 0) >= 0.0;
    if (matches) {
        float textureLimit[kBands], subtractionLimit[kBands];
        for (int band = 0; band < kBands; ++band) {
            textureLimit[band] = static_cast<float>(kNoiseSigmas * noiseOf(0, band));
            subtractionLimit[band] = static_cast<float>(kNoiseSigmas * noiseOf(1, band));
        }
        const int values = textureChannels_ + 1;
        const std::uint8_t* band = referenceBands_.data();
        for (std::size_t block = 0; block < current_.size() && matches; block += values, ++band) {
            for (int c = 0; c < textureChannels_; ++c)
                matches =
                    matches && std::abs(current_[block + c] - reference_[block + c]) <= textureLimit[*band];
            const std::size_t s = block + textureChannels_;
            matches = matches && std::abs(current_[s] - reference_[s]) <= subtractionLimit[*band];
        }
    }
    std::swap(beforePrevious_, previous_);
    std::swap(previous_, current_);
    measuredPairs_ = std::min(measuredPairs_ + 1, 3);
    return matches;
}

void StillScene::adoptAsReference() {
    if (measuredPairs_ == 0)
        return;
    reference_.assign(previous_.begin(), previous_.end());
    const int values = textureChannels_ + 1;
    referenceBands_.resize(reference_.size() / static_cast<std::size_t>(values));
    for (std::size_t i = 0; i < referenceBands_.size(); ++i)
        referenceBands_[i] = static_cast<std::uint8_t>(bandOf(&reference_[i * values]));
    hasReference_ = true;
}

}  // namespace everytouch::core

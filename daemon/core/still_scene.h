#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// Tells whether a frame pair shows the scene of the last pair that was analysed, within the camera's noise:
// then that pair's hand mask and fingertips still hold and the segmentation need not run again. A table with
// nobody at it, or a hand held still, costs next to nothing.
//
// The scene is compared block by block: the mean texture (each channel) and the mean subtraction image, so
// that both what the hand looks like and where the code falls on it count. A block has changed when it
// differs from the reference by more than kNoiseSigmas standard deviations of the camera's noise at its
// brightness (shot noise grows with the light). That noise is learned from pairs that share no frame: the
// spread of their block differences in each band of brightness, read from the quietest quarter of the blocks
// (content may move in the rest), the lowest seen since the last reset. A noise taken too small makes pairs
// count as changed, which costs time, never a hand.
class StillScene {
public:
    StillScene() { reset(); }

    // blockPx: the blocks' side in camera pixels (at most 257), a fraction of a fingertip's width. region:
    // the part of the camera image that matters (the display); changes elsewhere are ignored.
    void setRegion(const cv::Rect& region, int blockPx);

    // Measures the pair (T: CV_8UC3 or CV_8UC1, S: CV_16SC1, camera size). True when a reference exists and
    // no block of this pair lies beyond the noise of it.
    bool matchesReference(const cv::Mat& texture, const cv::Mat& subtraction);
    // The pair last measured becomes the reference: call after analysing it.
    void adoptAsReference();
    // Forgets the reference and the noise learned (a new rig, a gap in the frames).
    void reset();

    // The standard deviation of a block mean's difference between two pairs that share no frame, as learned
    // for blocks whose mean texture is `brightness` (texture, subtraction image; DN); 0 before it is known.
    double textureNoise(double brightness) const;
    double subtractionNoise(double brightness) const;

    static constexpr double kNoiseSigmas = 6.0;
    // Bands of brightness (DN of the texture's mean over its channels) within which the noise is taken as
    // one.
    static constexpr int kBands = 8;
    static constexpr double kBandDn = 256.0 / kBands;

private:
    void measure(const cv::Mat& texture, const cv::Mat& subtraction);
    void learnNoise(const std::vector<float>& earlier);
    int bandOf(const float* block) const;
    // The noise of a band, or of the quietest band known when it has not been learned yet.
    double noiseOf(int group, int band) const;

    cv::Rect region_;
    int blockPx_ = 4;
    int textureChannels_ = 0;
    // Block means, block-row major, textureChannels_ texture values then one subtraction value per block.
    // current_: this pair; previous_, beforePrevious_: the two pairs before it.
    std::vector<float> current_, previous_, beforePrevious_, reference_;
    std::size_t measuredSize_ = 0;  // values per pair
    int measuredPairs_ = 0;         // since the last reset, at most 3
    int pairsSinceLearning_ = 0;
    bool hasReference_ = false;
    std::vector<std::uint8_t> referenceBands_;  // each reference block's band of brightness
    std::vector<std::uint16_t> textureColumns_;
    std::vector<std::int32_t> subtractionColumns_;
    std::vector<float> differences_[2][kBands];
    double smoothedNoise_[2][kBands] = {};
    double noise_[2][kBands] = {};  // negative where not learned
};

}  // namespace everytouch::core

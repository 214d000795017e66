#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::eval {

// The background-subtraction baseline (BkSub). The paper's predecessor (PROCAMS12, the paper's [1]/[32])
// predicts the camera image of the bare table from the projected content through its geometric and
// radiometric calibration and marks as hand what differs from the prediction. A recording does not carry the
// displayed content, so this variant takes the empty table from the recording itself: the per-pixel median of
// the textures T of its first pairs. It thus assumes that the content does not change and that the hand
// covers a pixel in fewer than half of those pairs (a recording that starts with the table empty); it has no
// radiometric prediction error, which flatters it, and it sees projector shadows as change, as the original
// does. The threshold follows from the camera noise measured in the same pairs, not from any tuning.
struct BackgroundOptions {
    // Textures of pairs that share no frame whose median is the background: 15 make the median's noise a
    // third of one texture's (variance pi / 2N), and span 30 frames, a quarter of a second at 120 Hz.
    int samples = 15;
    // How many pixels of a frame camera noise alone may mark as hand, on average; sets the threshold in
    // noise sigmas (about 4.9 sigma for 648x488 BGR frames).
    double falsePixelsPerFrame = 1.0;

    std::optional<std::string> validate() const;
};

// Noise sigma (DN) of a texture channel at each digital level.
using NoiseTable = std::array<float, 256>;

// Pixels of a frame whose noise differs. Inside the frame, the four places of the 2x2 grid of a colour filter
// mosaic: a value the camera measured carries the full noise, one its demosaicing interpolated from two or
// four neighbours a half or a quarter of the variance. The frame's outermost pixels, where demosaicing has
// neighbours on fewer sides, are a class of their own. One sigma for all of them would be a mixture with far
// heavier tails than any one of them. Cameras without a mosaic just give the classes the same noise.
inline constexpr int kNoiseClasses = 5;
int noiseClass(int x, int y, cv::Size size);

// Noise of channel `channel` of a texture at each digital level over the pixels of `noiseClass`, from the
// differences of textures of the same static scene taken at different times: the difference of two textures
// carries twice a texture's noise variance. Channels have their own (colour gains).
// Levels are pooled in bins of 8 DN; the largest 5 % of differences in a bin are left out (a hand moving,
// content changing) and the trimmed spread is corrected to the Gaussian sigma. Between the bins with enough
// samples the variance is interpolated linearly in the level. Never below the texture's rounding noise,
// 1/sqrt(12) DN.
// textures: at least two, of one size and type (CV_8UC1 or CV_8UC3), sharing no frame.
NoiseTable estimateTextureNoise(const std::vector<cv::Mat>& textures, int channel, int noiseClass);

// The multiple of the difference's sigma that noise exceeds in `falsePixelsPerFrame` pixels of a frame of
// `pixels` pixels with `channels` independent channels on average (two-sided Gaussian tail).
double noiseThresholdSigmas(double falsePixelsPerFrame, int pixels, int channels);

class BackgroundSubtraction {
public:
    // textures: the samples (options.samples of them), of one size and type, sharing no frame. Throws
    // std::invalid_argument when there are too few or the options are invalid.
    BackgroundSubtraction(const std::vector<cv::Mat>& textures, const BackgroundOptions& options);

    // texture: T of the frames' type. mask: receives CV_8UC1, 255 where any channel differs from the
    // background by more than the threshold.
    void segment(const cv::Mat& texture, cv::Mat& mask) const;

    const cv::Mat& background() const { return background_; }
    const NoiseTable& noiseSigmaDn(int channel, int noiseClass) const {
        return noiseSigmaDn_[channel * kNoiseClasses + noiseClass];
    }
    double thresholdSigmas() const { return thresholdSigmas_; }

private:
    cv::Mat background_;
    std::vector<NoiseTable> noiseSigmaDn_;  // per channel and noise class
    double thresholdSigmas_ = 0.0;
    cv::Mat thresholdDn_;  // per pixel and channel, CV_32FC(channels)
};

}  // namespace everytouch::eval

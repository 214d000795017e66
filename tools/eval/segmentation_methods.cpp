#include "eval/segmentation_methods.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "core/code_blur.h"
#include "core/code_image.h"
#include "core/frame_pairer.h"
#include "core/hand_segmentation.h"
#include "eval/skin_colour_model.h"

namespace everytouch::eval {

namespace {

template <typename... Arguments>
std::string format(const char* pattern, Arguments... arguments) {
    std::string text(std::snprintf(nullptr, 0, pattern, arguments...), '\0');
    std::snprintf(text.data(), text.size() + 1, pattern, arguments...);
    return text;
}

// The pipeline's own segmentation with its default options, set up from rig.yml as the daemon sets it up.
SegmentationMethod pipelineMethod(const io::Recording& recording, core::SegmentationMethod which,
                                  const std::string& name, const std::string& description) {
    core::SegmentationOptions options;
    options.method = which;
    // As the pipeline does, the code on the table is predicted as blurred as the first pair with code shows
    // it.
    struct State {
        core::HandSegmenter segmenter;
        core::CodeBlurMeter codeBlur;
        bool blurMeasured = false;
    };
    auto state = std::make_shared<State>(State{core::HandSegmenter(options), {}, false});
    const core::Calibration& calibration = recording.rig().calibration;
    const cv::Mat& pattern = recording.rig().pattern;
    state->segmenter.setRig(calibration, pattern);
    if (which == core::SegmentationMethod::Code)
        state->codeBlur.setRig(calibration, pattern, state->segmenter.judgedRegion());
    SegmentationMethod method;
    method.name = name;
    method.description = description;
    method.judged = state->segmenter.judgedRegion();
    method.segment = [state, calibration, pattern](const SegmentationInput& input, cv::Mat& mask) {
        if (state->codeBlur.hasRig() && !state->blurMeasured)
            if (const std::optional<double> blur = state->codeBlur.measure(input.subtraction)) {
                state->segmenter.setRig(calibration, pattern, *blur);
                state->blurMeasured = true;
            }
        state->segmenter.segment(input.texture, input.subtraction, mask);
    };
    return method;
}

SegmentationMethod skinColourMethod(const io::Recording& recording, double likelihoodRatio) {
    SegmentationMethod method;
    method.name = "SCM";
    method.description = format(
        "statistical skin-colour model: the RGB Gaussian mixtures of Jones & Rehg (IJCV 2002), 16 skin "
        "and 16 non-skin kernels as published, skin where the likelihood ratio exceeds %g; on T",
        likelihoodRatio);
    if (recording.frames().empty() || recording.loadFrame(0).image.channels() != 3) {
        method.unavailable = "needs colour frames";
        return method;
    }
    auto model = std::make_shared<SkinColourModel>(likelihoodRatio);
    method.segment = [model](const SegmentationInput& input, cv::Mat& mask) {
        model->segment(input.texture, mask);
    };
    return method;
}

SegmentationMethod backgroundMethod(const io::Recording& recording, const BackgroundOptions& options) {
    SegmentationMethod method;
    method.name = "BkSub";
    // Textures of the first pairs that share no frame, so that their noise is independent.
    std::vector<cv::Mat> textures;
    core::FramePairer pairer;
    cv::Mat subtraction, texture;
    std::size_t lastUsed = 0;
    for (std::size_t position = 0;
         position < recording.frames().size() && static_cast<int>(textures.size()) < options.samples;
         ++position) {
        const std::optional<core::FramePair> pair = pairer.push(recording.loadFrame(position));
        if (!pair || (!textures.empty() && position < lastUsed + 2))
            continue;
        core::computeSubtractionAndTexture(*pair, subtraction, texture);
        textures.push_back(texture.clone());
        lastUsed = position;
    }
    if (static_cast<int>(textures.size()) < options.samples) {
        method.description = format(
            "background subtraction: needs %d pairs that share no frame for its background", options.samples);
        method.unavailable = "recording too short for the background";
        return method;
    }
    auto subtractor = std::make_shared<BackgroundSubtraction>(textures, options);
    // The noise of the green channel (or the only one) at one place of the 2x2 grid, as a sample of what was
    // measured.
    const NoiseTable& sigma = subtractor->noiseSigmaDn(subtractor->background().channels() > 1 ? 1 : 0, 0);
    method.description = format(
        "background subtraction against the per-pixel median of the textures of the first %d pairs that "
        "share "
        "no frame (frames 0-%zu; stands in for the content predicted through the calibration); hand where a "
        "channel differs by more than %.2f noise sigma (measured in green: %.2f DN at level 32, %.2f at 128, "
        "%.2f at 224)",
        options.samples, lastUsed, subtractor->thresholdSigmas(), sigma[32], sigma[128], sigma[224]);
    if (recording.hasMasks()) {
        // The median assumes the table empty in most of those frames; the truth tells how far it was.
        double hand = 0.0;
        for (std::size_t position = 0; position <= lastUsed; ++position)
            hand += cv::countNonZero(recording.loadMask(position));
        const double pixels =
            static_cast<double>(lastUsed + 1) * recording.rig().calibration.cameraSize.area();
        method.description +=
            format("; the truth shows a hand in %.2f %% of those frames' pixels", 100.0 * hand / pixels);
    }
    method.segment = [subtractor](const SegmentationInput& input, cv::Mat& mask) {
        subtractor->segment(input.texture, mask);
    };
    return method;
}

}  // namespace

std::optional<std::string> MethodOptions::validate() const {
    if (const auto problem = background.validate())
        return "background: " + *problem;
    if (!(skinLikelihoodRatio > 0) || !std::isfinite(skinLikelihoodRatio))
        return "skinLikelihoodRatio: must be a positive number";
    return std::nullopt;
}

std::vector<SegmentationMethod> segmentationMethods(const io::Recording& recording,
                                                    const MethodOptions& options) {
    if (const auto problem = options.validate())
        throw std::invalid_argument("segmentation methods: " + *problem);
    std::vector<SegmentationMethod> methods;
    methods.push_back(
        pipelineMethod(recording, core::SegmentationMethod::Code, "ours",
                       "the pipeline's segmentation by the embedded code (core::HandSegmenter)"));
    methods.push_back(pipelineMethod(recording, core::SegmentationMethod::Paper, "paper",
                                     "the paper's method as published: HC saliency, mean shift, confidence "
                                     "fusion (eq. 8-12), closing (core::HandSegmenter)"));
    methods.push_back(skinColourMethod(recording, options.skinLikelihoodRatio));
    methods.push_back(backgroundMethod(recording, options.background));
    return methods;
}

}  // namespace everytouch::eval

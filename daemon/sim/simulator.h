#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/frame.h"
#include "sim/renderer.h"
#include "sim/scenario.h"
#include "sim/sim_parameters.h"

namespace everytouch::sim {

// The code the simulated rig projects: the project's pattern (core::generatePattern) for the projector's
// size, 6x6 windows, from the parameters' seed.
cv::Mat rigPattern(const SimParameters& parameters);

// The simulated rig: a scenario played on the renderer. Frame k is exposed at k / frameRate seconds and shows
// I = O + P for even k, I' = O - P for odd k; everything in it follows from the parameters, the pattern, the
// content and k, so any frame can be rendered alone and again.
class Simulator {
public:
    // pattern: CV_8UC1, projector size, 0/1 (rigPattern(parameters) for the rig). contentImage: when not
    // empty, shown instead of any procedural content (8-bit gray or BGR, any size: it is scaled to the
    // display). Throws std::invalid_argument when the parameters are invalid, name an unknown scenario, or
    // name a content that is neither a procedural kind nor "auto" and no content image is given.
    Simulator(const SimParameters& parameters, const cv::Mat& pattern,
              const cv::Mat& contentImage = cv::Mat());

    const SimParameters& parameters() const { return parameters_; }
    const core::Calibration& calibration() const { return calibration_; }
    const cv::Mat& pattern() const { return pattern_; }
    const Scenario& scenario() const { return *scenario_; }

    // The stream: frames firstFrame() up to (not including) endFrame(); endless when there is no end.
    std::uint64_t firstFrame() const;
    std::optional<std::uint64_t> endFrame() const;
    double frameSeconds(std::uint64_t index) const { return index / parameters_.frameRate; }
    std::int64_t frameTimestampUs(std::uint64_t index) const;
    static core::Polarity framePolarity(std::uint64_t index) {
        return index % 2 == 0 ? core::Polarity::Positive : core::Polarity::Negative;
    }
    // Room light on the table at `seconds`.
    double ambientLux(double seconds) const;

    // From the next rendered frame on the projector shows `projectorImage` (8-bit gray or BGR, exactly the
    // projector's size, panel pixels, not warped through display_to_projector) instead of the content; the
    // code stays embedded (I = O + P, I' = O - P). An empty image returns to the content. Throws
    // std::invalid_argument for another size or type.
    void projectImage(const cv::Mat& projectorImage) { renderer_->setProjectorImage(projectorImage); }

    // Renders frame `index` into `frame` (image, timestamp, index, polarity) and `truth`. The frame's
    // timestamp is the start of its exposure; the truth describes the scene at mid-exposure.
    void render(std::uint64_t index, core::Frame& frame, FrameTruth& truth);

private:
    void showContent(const SceneState& scene);
    // Largest distance a wrist or fingertip moves between two scenes, mm.
    static double travelMm(const SceneState& from, const SceneState& to);

    SimParameters parameters_;
    core::Calibration calibration_;
    cv::Mat pattern_;
    std::unique_ptr<Scenario> scenario_;
    std::unique_ptr<Renderer> renderer_;
    std::optional<ContentKind> fixedKind_;  // content=KIND
    bool fixedImage_ = false;               // content from an image
    std::optional<std::pair<ContentKind, int>> shown_;
    double exposureMs_ = 0.0;
    double mmPerCameraPixel_ = 1.0;  // on the table at the image centre
    std::vector<std::vector<HandPose>> exposureHands_;
};

}  // namespace everytouch::sim

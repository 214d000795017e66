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
// content, what the projector was given to show and the keystone, and k, so any frame can be rendered alone
// and again.
class Simulator {
public:
    // pattern: CV_8UC1, projector size, 0/1 (rigPattern(parameters) for the rig). contentImage: when not
    // empty, shown instead of any procedural content (8-bit gray or BGR, any size: it is scaled to the
    // display). Throws std::invalid_argument when the parameters are invalid, name an unknown scenario, or
    // name a content that is neither a procedural kind nor "auto" and no content image is given.
    Simulator(const SimParameters& parameters, const cv::Mat& pattern,
              const cv::Mat& contentImage = cv::Mat());

    const SimParameters& parameters() const { return parameters_; }
    // The rig's calibration, exact until the camera is knocked; it stays the same after, as a real rig's
    // does (the camera's image and the truth follow the camera where it is).
    const core::Calibration& calibration() const { return calibration_; }
    // The rig's true geometry at `seconds` into the session: calibration() before a knock, the camera where
    // the knock put it after; the projector's image moved by its drift; after the table slid or tilted, the
    // rig against the table's new place (the scenario's hands keep to the table).
    core::Calibration geometryAt(double seconds) const;
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
    // std::invalid_argument for another size or type. The first image begins the session of a scenario that
    // follows the calibration dialogue (Scenario::beginsWithTheProjector) with the frame after the last one
    // rendered.
    void projectImage(const cv::Mat& projectorImage);

    // From the next rendered frame on the desktop is a display of displaySize pixels drawn onto the panel
    // through displayToProjector, as the daemon's calibration asks, instead of the rig's own keystone:
    // calibration() and the truth's display coordinates describe that display, the content is drawn at its
    // size, and the scenario's hands go where it shows them. Throws std::invalid_argument for an empty size
    // or a homography that is not finite and invertible.
    void setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector);

    // Renders frame `index` into `frame` (image, timestamp, index, polarity) and `truth`. The frame's
    // timestamp is the start of its exposure; the truth describes the scene at mid-exposure.
    void render(std::uint64_t index, core::Frame& frame, FrameTruth& truth);

private:
    // The scene at `seconds` of the stream: the scenario's, shifted to begin with the first projected image
    // when it follows the calibration dialogue.
    SceneState sceneAt(double seconds) const;
    void showContent(const SceneState& scene);
    // The content image, scaled to the display.
    void showFixedImage();
    // The rig as it stands at `seconds`: where the camera is and how far the projector's image has crept.
    struct Placement {
        bool knocked = false;
        bool tableShifted = false;
        bool tableTilted = false;
        long driftSteps = 0;  // how far the projector's image has crept, in steps of a fiftieth of a pixel
        bool operator==(const Placement&) const = default;
    };
    Placement placementAt(double seconds) const;
    // The renderer of the rig as it stands at `seconds`.
    void placeRig(double seconds);
    // The camera's pose after the knock (SimParameters::knockS).
    Eigen::Isometry3d knockedTableToCamera() const;
    // Where the table has slid (SimParameters::tableShiftS): a point of the table that lay at X before lies
    // at slide * X after, both in the table's frame from before.
    Eigen::Isometry3d tableSlide() const;
    // How the table has tilted (SimParameters::tableTiltS), as tableSlide() says how it slid.
    Eigen::Isometry3d tableTilt() const;
    // The unit direction, in projector pixels, in which the projector's image creeps.
    Eigen::Vector2d driftDirection() const;
    // Largest distance a wrist or fingertip moves between two scenes, mm.
    static double travelMm(const SceneState& from, const SceneState& to);

    SimParameters parameters_;
    core::Calibration calibration_;
    cv::Mat pattern_;
    std::unique_ptr<Scenario> scenario_;
    std::unique_ptr<Renderer> renderer_;
    std::optional<ContentKind> fixedKind_;  // content=KIND
    cv::Mat fixedImage_;                    // content from an image (BGR), as given
    std::optional<std::pair<ContentKind, int>> shown_;
    double exposureMs_ = 0.0;
    double mmPerCameraPixel_ = 1.0;  // on the table at the image centre
    std::vector<std::vector<HandPose>> exposureHands_;
    std::uint64_t nextIndex_ = 0;       // the frame after the last one rendered
    std::optional<double> userStartS_;  // stream time of the first projected image
    cv::Mat projectorImage_;            // shown instead of the content when not empty
    Placement placed_;                  // the rig the renderer shows
};

}  // namespace everytouch::sim

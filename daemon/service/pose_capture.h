#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/camera_model.h"
#include "core/frame.h"
#include "core/plane_view.h"
#include "core/projector_chessboard.h"
#include "core/result.h"

namespace everytouch::service {

// How a pose of the board is told to be held still and new.
struct PoseCaptureOptions {
    // The scene must stay unchanged this long before a view is taken, seconds: a hand lets go of a board in
    // a fraction of a second.
    double stillSeconds = 0.5;
    // A pixel has changed when its texture differs from the still scene's by more than this many standard
    // deviations of the sensor noise at its level (5: noise alone trips it at about 6 pixels in ten million).
    double changeSigmas = 5.0;
    // The scene counts as still while fewer than this fraction of its pixels changed (0.001 of a 648 x 488
    // frame is 316 pixels, about 2 cm^2 on the table).
    double maxChangedFraction = 0.001;
    // A new view's surface must be tilted at least this much against every view taken so far, degrees: the
    // pair calibration needs surfaces 10 degrees apart or more.
    double minTiltDeg = 10.0;

    std::optional<std::string> validate() const;
};

// The standard deviation of the sensor noise of an 8-bit gray image at each level (256 entries, DN), from
// the image alone: the residual of a discrete Laplacian (Immerkaer 1996) is pure noise away from edges, and
// its median in each band of levels is robust to the edges there are. Never below the quantisation noise.
std::vector<double> noiseLevels(const cv::Mat& gray);

// Per pixel of `gray` (8-bit), the largest difference from another texture of the same scene that sensor
// noise explains: changeSigmas x sqrt(2) x the noise at the pixel's level (noiseLevels), in whole DN.
void changeThresholds(const cv::Mat& gray, double changeSigmas, cv::Mat& thresholds);

// The fraction of the pixels of `texture` that differ from `reference` by more than noise explains
// (changeThresholds of `texture`); both 8-bit gray of one size.
double changedFraction(const cv::Mat& reference, const cv::Mat& texture, double changeSigmas);

// The normal (camera frame, unit, towards the camera) of the surface a rectangle of sizeMm lies on, from its
// corners in undistorted pixels of a camera with matrix K (TableRectangleDetection order: the corners of a
// convex quadrilateral). With the camera's true matrix it is within 1.8 degrees on the simulated rig's
// calibration poses (seeds 1-8), unless the stripe lies at the very edge of the projector's light.
Eigen::Vector3d rectangleSurfaceNormal(const std::array<Eigen::Vector2d, 4>& corners, cv::Size2d sizeMm,
                                       const Eigen::Matrix3d& cameraMatrix);

// Whether the scene in front of the camera holds still: fed the texture of each frame pair in turn, it
// compares each with the texture that began the still spell, pixel by pixel against the noise at that pixel's
// level, and averages the textures while nothing changes.
class StillnessTracker {
public:
    explicit StillnessTracker(const PoseCaptureOptions& options) : options_(options) {}

    enum class State {
        Changed,   // this texture differs from the last: a new spell begins
        Settling,  // unchanged, but not for long enough yet
        Still,     // unchanged for options.stillSeconds or more
    };
    // texture: 8-bit gray; timestampUs: when it was exposed.
    State offer(const cv::Mat& texture, std::int64_t timestampUs);
    // The average of the spell's textures (8-bit): noise is lower by the square root of their number.
    void average(cv::Mat& texture) const;
    double stillSeconds() const { return (lastUs_ - startUs_) * 1e-6; }
    double changedFraction() const { return changedFraction_; }

private:
    PoseCaptureOptions options_;
    cv::Mat reference_, threshold_, difference_, changed_, sum_;
    int count_ = 0;
    std::int64_t startUs_ = 0, lastUs_ = 0;
    double changedFraction_ = 0.0;
};

// A still scene that can be taken as a new view.
struct Pose {
    core::PlaneView view;
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // the surface's, camera frame
};

// The views of the pair calibration, taken one by one from still scenes: each must show the projected
// chessboard and the card, on a surface tilted away from every view taken before.
class PoseCapture {
public:
    // board: what the projector shows; camera: the camera as far as it is known (its matrix for the
    // surface's tilt, its distortion for the card's corners).
    PoseCapture(const PoseCaptureOptions& options, const core::ChessboardOptions& board,
                cv::Size projectorSize, cv::Size2d cardSizeMm, const core::CameraModel& camera);

    enum class Event {
        Moving,    // the scene changes
        Settling,  // still, not long enough yet
        Waiting,   // still, and this scene was looked at already: it needs to change
        Captured,  // a new view was taken (views() has it)
        Refused,   // still, but not usable: problem() says why
    };
    Event offer(const core::FramePair& pair);

    const std::vector<core::PlaneView>& views() const { return views_; }
    // The still texture (8-bit gray, averaged) the last view was taken from; empty before the first.
    const cv::Mat& lastViewTexture() const { return lastViewTexture_; }
    const std::string& problem() const { return problem_; }

    // Looks at one still texture (8-bit gray or BGR) as the next view, without taking it. Fails, in words for
    // the user, when it cannot be taken.
    core::Result<Pose> attempt(const cv::Mat& texture) const;

private:
    PoseCaptureOptions options_;
    core::ChessboardOptions board_;
    cv::Size projectorSize_;
    cv::Size2d cardSizeMm_;
    core::CameraModel camera_;
    StillnessTracker stillness_;
    bool looked_ = false;  // the current still spell was offered as a view already
    std::vector<core::PlaneView> views_;
    std::vector<Eigen::Vector3d> normals_;
    std::string problem_;
    cv::Mat subtraction_, texture_, gray_, average_;
    cv::Mat lastViewTexture_;
};

}  // namespace everytouch::service

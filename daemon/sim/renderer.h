#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/frame.h"
#include "sim/camera_sensor.h"
#include "sim/hand.h"
#include "sim/sim_parameters.h"
#include "sim/surface.h"

namespace everytouch::sim {

// Ground truth of one fingertip in one frame.
struct FingertipTruth {
    int hand = 0;  // index of the hand in the scene
    Finger finger = Finger::Index;
    std::uint32_t id = 0;   // hand * 5 + finger: stable for the scenario
    Eigen::Vector3d pad;    // lowest point of the fingertip, table mm
    double heightMm = 0.0;  // pad above the table; exactly 0 when touching
    bool touching = false;
    bool presented = false;  // pointing, touching or hovering, not curled into the hand
    cv::Point2d display;     // contact point (the pad's foot on the table), display pixels
    cv::Point2d camera;      // the same table point in the camera image, pixels
};

// What the renderer knows about one frame besides the image.
struct FrameTruth {
    std::vector<FingertipTruth> fingertips;
    cv::Mat handMask;         // CV_8UC1, camera size: 255 where the pixel's central ray hits a hand
    cv::Mat visibleHeightMm;  // CV_32FC1, camera size: height above the table of what each pixel sees
    double ambientLux = 0.0;
    double exposureMs = 0.0;
};

// Touch tolerance of the ground truth: a pad closer to the table than this counts as touching (skin deforms
// far more than this under the lightest touch).
inline constexpr double kContactToleranceMm = 0.1;

// Ray-casting renderer of table, projector, hands and camera. Everything that does not move is precomputed:
// the table's image for each projected image (per camera pixel, integrated over the pixel), the light the
// projector throws, the skin's view of it, vignetting. Per frame only the hands' bounding regions are ray
// cast, in the camera and, for their shadow, in the projector.
class Renderer {
public:
    // pattern: CV_8UC1, projector size, 0/1.
    Renderer(const SimParameters& parameters, const core::Calibration& calibration, const cv::Mat& pattern);

    // The display image (BGR 8-bit, display size): recomputes the light of both projected images.
    void setContent(const cv::Mat& displayContent);

    // Renders the camera frame showing I (Positive) or I' (Negative). `exposure` holds the hands at an odd
    // number of instants spread evenly over the exposure; the image averages them (motion blur) and the truth
    // describes the middle one. `image` receives the 8-bit camera image; `truth` the fingertips, mask and
    // visible heights.
    void render(const std::vector<std::vector<HandPose>>& exposure, core::Polarity polarity,
                double ambientLux, double exposureMs, std::uint64_t noiseSeed, cv::Mat& image,
                FrameTruth& truth);

    // Exposure that brings white content on the table (projector white plus `ambientLux`) to the metering
    // level at the image centre, bounded by the longest allowed exposure.
    double meterExposureMs(double ambientLux) const;

private:
    // A hand capsule ready for ray casting from both devices, with its image regions.
    struct PreparedCapsule {
        CapsuleHit camera;
        CapsuleHit projector;
        Eigen::Matrix3f cameraPixelToLocal;  // (u, v, 1) -> local ray direction
        Eigen::Matrix3f projectorPixelToLocal;
        cv::Rect cameraBox, projectorBox;
        HandPart part;
        float length;
    };

    void castShadows(const std::vector<PreparedCapsule>& capsules, const cv::Rect& box);
    // Camera region of the table that hand shadows within `projectorBox` can fall on.
    cv::Rect shadowOnTable(const cv::Rect& projectorBox) const;
    void shadeTable(const cv::Rect& cameraBox, const cv::Mat& projected);
    // Ray casts the hands into radiance_; records mask and visible heights into `truth` when given.
    void castHands(const std::vector<PreparedCapsule>& capsules, const cv::Rect& box, int polarityIndex,
                   double ambientLux, FrameTruth* truth);
    void prepare(const std::vector<HandPose>& hands, std::vector<PreparedCapsule>& capsules,
                 cv::Rect& cameraBox, cv::Rect& projectorBox) const;
    void shadeHit(const PreparedCapsule& capsule, const Eigen::Vector3f& direction, float t,
                  int polarityIndex, double ambientLux, float* bgr, float& height) const;

    SimParameters parameters_;
    core::Calibration calibration_;
    cv::Mat pattern_;
    CameraSensor sensor_;
    // Devices, in float for the per-pixel work.
    Eigen::Vector3d cameraCentre_, projectorCentre_;
    Eigen::Matrix3d cameraPixelToRay_, projectorPixelToRay_;  // (u, v, 1) -> table-frame direction, z-depth 1
    Eigen::Matrix3f projectorProjection_;                     // K_p R_p
    Eigen::Vector3f projectorTranslation_;                    // K_p t_p
    Eigen::Matrix3d cameraToProjector_;                       // table-plane homography
    Eigen::Matrix3d projectorToCamera_;
    double referenceDistance2_ = 1.0;  // squared projector distance of the display centre
    double referenceCosine_ = 1.0;     // incidence cosine there
    // Static images.
    cv::Mat panelFalloff_;    // CV_32FC3, projector size: relative light of each panel pixel (vignetting)
    cv::Mat albedo_;          // CV_32FC3, camera size: table reflectance integrated over each pixel
    cv::Mat tableIncidence_;  // CV_32FC1, camera size: projector light falloff on the table (1 at the centre)
    cv::Mat ambientTerm_;     // CV_32FC3: albedo x ambient colour
    cv::Mat ambientBlurred_;  // the same through the camera's blur
    Eigen::Vector3f skinBgr_, nailBgr_;
    Eigen::Vector3f ambientBgr_;
    // Per content: for I and I', the table radiance from the projector (camera size) and the light as skin
    // receives it (projector size).
    cv::Mat projected_[2];
    cv::Mat projectedBlurred_[2];
    cv::Mat skinLight_[2];
    // Per-frame buffers.
    cv::Mat shadowDepth_;  // CV_32FC1, projector size: depth of the nearest hand along each projector ray
    cv::Mat shadowMask_;   // CV_32FC1, projector size: fraction of each panel pixel's light the hands block
    cv::Rect shadowBox_;
    cv::Mat depth_;     // CV_32FC1, camera size: nearest hand hit per pixel
    cv::Mat hitIndex_;  // CV_16SC1: capsule of that hit, -1 for none
    cv::Mat radiance_;  // CV_32FC3, camera size: unblurred radiance, valid where hands changed it
    // Per polarity, CV_32FC3, camera size: the last frame's radiance through the camera's blur, the region
    // the hands changed in it, and the ambient level and content it was made for.
    cv::Mat frameRadiance_[2];
    cv::Rect dirty_[2];
    double frameAmbientLux_[2] = {-1.0, -1.0};
    int frameContentVersion_[2] = {-1, -1};
    int contentVersion_ = 0;
    cv::Mat partBlurred_;     // CV_32FC3, camera size: the changed region through the camera's blur
    cv::Mat blockedOnTable_;  // CV_32FC1, camera size: shadow mask in camera pixels, in the shadow's region
    cv::Mat exposed_;         // CV_32FC3, camera size: radiance summed over the instants of the exposure
    std::vector<std::vector<PreparedCapsule>> instantCapsules_;  // per instant of the exposure
    std::vector<cv::Rect> instantCameraBoxes_, instantProjectorBoxes_;
    cv::Mat work_[4];  // content precomputation
};

}  // namespace everytouch::sim

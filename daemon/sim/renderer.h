#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/frame.h"
#include "sim/camera_sensor.h"
#include "sim/hand.h"
#include "sim/props.h"
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
    Props props;  // the calibration props at mid-exposure
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

    // The display image (BGR 8-bit, display size): recomputes the light of both projected images, unless a
    // projector image is shown instead.
    void setContent(const cv::Mat& displayContent);

    // From now on the display is displaySize pixels drawn onto the panel through displayToProjector (the
    // keystone), and the truth gives display coordinates of that display. The content must come again, of
    // the new size, before the next frame that shows it.
    void setDisplay(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector);

    // From the next frame on the projector shows `projectorImage` (8-bit gray or BGR, projector size, panel
    // pixels: not warped through the display's keystone) instead of the content, the code embedded in it as
    // always. An empty image returns to the content. Throws std::invalid_argument for another size or type.
    void setProjectorImage(const cv::Mat& projectorImage);

    // The calibration props in the scene. When they differ from the last ones, what each camera pixel sees of
    // table and props is ray cast again: with `fine`, n x n samples per pixel (pixel_samples) and 8 x 8 where
    // a pixel sees more than one surface or material; otherwise one sample per pixel, for props in motion
    // (whose motion blurs more than that loses), and the projected light of only the polarity rendered.
    void setProps(const Props& props, bool fine = true);

    // Renders the camera frame showing I (Positive) or I' (Negative). `exposure` holds the hands at an odd
    // number of instants spread evenly over the exposure; the image averages them (motion blur) and the truth
    // describes the middle one. `image` receives the 8-bit camera image; `truth` the fingertips, mask and
    // visible heights.
    void render(const std::vector<std::vector<HandPose>>& exposure, core::Polarity polarity,
                double ambientLux, double exposureMs, std::uint64_t noiseSeed, cv::Mat& image,
                FrameTruth& truth);

    // Exposure that brings white content on the table (projector white plus `ambientLux`) to the metering
    // level at the image centre, and keeps it there on the brightest face of `props` (at its centre), bounded
    // by the longest allowed exposure.
    double meterExposureMs(double ambientLux, const std::vector<Props>& props = {}) const;

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
    // A flat surface of the static scene: the table or a prop's face.
    struct ScenePlane {
        Eigen::Matrix3d cameraToProjector;  // camera pixels -> projector pixels through the plane
        cv::Rect cameraBox;                 // camera region where it can be seen
        cv::Mat weight;  // CV_32FC3, cameraBox size: albedo x projector incidence, integrated over the pixel
                         // (0 where the plane is hidden)
        bool shadowedByBoard = false;  // the board is between the projector and this plane
    };

    // Ray casts the static scene (table and props) for every camera pixel the props can change.
    void buildScene(bool fine);
    // The light of a projector image (gray or BGR 8-bit, projector size) for both polarities, code embedded.
    void showPanelImage(const cv::Mat& panelImage);
    // The static scene's radiance from the projector for one polarity, camera size.
    void projectLight(int polarityIndex);
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
    cv::Mat panelLight_[2];  // CV_32FC3, projector size: light of each panel pixel through the defocus
    bool projectedValid_[2] = {false, false};
    cv::Mat panelContent_;    // CV_8UC3, projector size: the content warped onto the panel
    cv::Mat projectorImage_;  // CV_8UC3, projector size: shown instead of the content when not empty
    // The static scene: table and props.
    Props props_;
    bool propsFine_ = true;
    cv::Mat tableWeight_;             // CV_32FC3, camera size: table albedo x incidence
    std::vector<ScenePlane> planes_;  // the table first
    cv::Mat sceneAlbedo_;  // CV_32FC3, camera size: reflectance of what each pixel sees, integrated
    cv::Mat sceneHeight_;  // CV_32FC1, camera size: height above the table of what the central ray hits
    cv::Mat planeLabel_;   // CV_8UC1, camera size: the plane most of each pixel sees (index into planes_)
    cv::Mat boardShadow_;  // CV_32FC1, projector size: fraction of each panel pixel's light the board takes
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

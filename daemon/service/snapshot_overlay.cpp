#include "service/snapshot_overlay.h"

#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"

namespace everytouch::service {

namespace {

// Points per display edge: enough for the outline to follow the lens distortion smoothly.
constexpr int kOutlineSamplesPerEdge = 32;
const cv::Scalar kOutlineColour(0, 255, 0);
const cv::Scalar kTouchingColour(0, 0, 255);
const cv::Scalar kHoveringColour(0, 255, 255);
const cv::Scalar kPalmColour(160, 160, 160);

// Display pixel -> raw camera pixel: the camera's view of the point `heightMm` straight above where the pixel
// lands on the table, as a contact hovering there is.
class DisplayToCamera {
public:
    DisplayToCamera(const core::Calibration& calibration, double heightMm)
        : toUndistorted_(calibration.cameraToDisplayBelowHomography(heightMm).inverse()),
          camera_{calibration.cameraMatrix, calibration.cameraDistortion} {}

    cv::Point operator()(double x, double y) const {
        const Eigen::Vector2d raw =
            camera_.distortPixel(core::applyHomography(toUndistorted_, Eigen::Vector2d(x, y)));
        return {cvRound(raw.x()), cvRound(raw.y())};
    }

private:
    Eigen::Matrix3d toUndistorted_;
    core::CameraModel camera_;
};

void drawDisplayOutline(const core::Calibration& calibration, int thickness, cv::Mat& image) {
    const DisplayToCamera toCamera(calibration, 0.0);
    // The display's outer edges: pixel centres lie at whole coordinates (as warpPerspective draws the desktop
    // onto the panel), so the first and last pixels reach half a pixel beyond them.
    const double left = -0.5, top = -0.5;
    const double right = calibration.displaySize.width - 0.5, bottom = calibration.displaySize.height - 0.5;
    const cv::Point2d corners[] = {{left, top}, {right, top}, {right, bottom}, {left, bottom}};
    std::vector<cv::Point> outline;
    for (int edge = 0; edge < 4; ++edge) {
        const cv::Point2d from = corners[edge], to = corners[(edge + 1) % 4];
        for (int i = 0; i < kOutlineSamplesPerEdge; ++i) {
            const cv::Point2d point = from + (to - from) * (double(i) / kOutlineSamplesPerEdge);
            outline.push_back(toCamera(point.x, point.y));
        }
    }
    cv::polylines(image, outline, true, kOutlineColour, thickness, cv::LINE_AA);
}

void drawContact(const core::Calibration& calibration, const core::Contact& contact, int radius,
                 cv::Mat& image) {
    const cv::Point at = DisplayToCamera(calibration, contact.heightMm)(contact.x, contact.y);
    const cv::Scalar colour = contact.palm       ? kPalmColour
                              : contact.touching ? kTouchingColour
                                                 : kHoveringColour;
    cv::circle(image, at, radius, colour, contact.touching ? cv::FILLED : std::max(1, radius / 3),
               cv::LINE_AA);
    char label[48];
    std::snprintf(label, sizeof label, "%u %.1f mm", contact.id, contact.heightMm);
    cv::putText(image, label, at + cv::Point(radius + 2, -radius), cv::FONT_HERSHEY_SIMPLEX, radius / 16.0,
                colour, 1, cv::LINE_AA);
}

}  // namespace

void drawOverlay(const std::optional<core::Calibration>& calibration, const core::Contacts& contacts,
                 cv::Mat& image) {
    // Sizes follow the image so that the drawing reads the same on any camera.
    const int scale = std::max(1, image.cols / 640);
    if (!calibration) {
        cv::putText(image, "not calibrated", cv::Point(8 * scale, 24 * scale), cv::FONT_HERSHEY_SIMPLEX,
                    0.7 * scale, kTouchingColour, scale, cv::LINE_AA);
        return;
    }
    drawDisplayOutline(*calibration, scale, image);
    for (const core::Contact& contact : contacts)
        drawContact(*calibration, contact, 6 * scale, image);
}

void drawDetection(const core::PipelineResult& detection, cv::Mat& image) {
    const cv::Scalar handColour(255, 128, 0);
    const cv::Scalar fingertipColour(255, 0, 255);
    if (!detection.handMask.empty()) {
        std::vector<std::vector<cv::Point>> outlines;
        cv::findContours(detection.handMask, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
        cv::drawContours(image, outlines, -1, handColour, 1, cv::LINE_AA);
    }
    for (const core::FingertipObservation& observation : detection.fingertips) {
        const core::Fingertip& tip = observation.fingertip;
        const cv::Point end(cvRound(tip.tip.x()), cvRound(tip.tip.y()));
        const Eigen::Vector2d back = tip.tip - 1.5 * tip.widthPx * tip.direction;
        cv::line(image, end, cv::Point(cvRound(back.x()), cvRound(back.y())), fingertipColour, 1,
                 cv::LINE_AA);
        cv::drawMarker(image, end, fingertipColour, cv::MARKER_CROSS, 9, 1);
    }
}

}  // namespace everytouch::service

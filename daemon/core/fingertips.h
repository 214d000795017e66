#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/outer_contours.h"

namespace everytouch::core {

// One fingertip found on the hand mask's contour (paper section VI.B), camera pixels.
struct Fingertip {
    // The pad: where the finger meets the table when it touches (the paper's fingertip F_C), from the
    // silhouette's end by the model of FingertipOptions. For a finger hovering above the table, the pad's
    // own image.
    Eigen::Vector2d pad = Eigen::Vector2d::Zero();
    // The end of the finger's silhouette, sub-pixel. The camera looks at the finger from above and in front:
    // what ends its outline is the rounded end of the finger a few millimetres above and ahead of the pad.
    Eigen::Vector2d tip = Eigen::Vector2d::Zero();
    // Unit vector along the finger, from its base towards the tip.
    Eigen::Vector2d direction = Eigen::Vector2d::UnitY();
    double widthPx = 0.0;   // the silhouette's width across the finger behind the tip
    double angleRad = 0.0;  // eq. 13 at the tip: the sharper, the more finger-like
    int hand = 0;           // which region of the mask it belongs to (0, 1, ... in raster order)
};
using Fingertips = std::vector<Fingertip>;

// How fingertips are found on a contour. Every length follows from fingerWidthPx, the scale of a finger in
// this camera, as a multiple of it, so that nothing depends on the camera's resolution or distance.
struct FingertipOptions {
    // Expected width of a finger near its tip in the image, camera pixels: about 16 mm of finger over the
    // calibration's millimetres per camera pixel at the table (rigFingertipOptions).
    double fingerWidthPx = 20.0;
    // The silhouette's width behind a tip must lie within these multiples of fingerWidthPx: narrower is a
    // sliver of segmentation noise, wider is no single finger. Fingertips are 13-18.5 mm wide, the camera's
    // scale changes by 20 % either way across the table, and a finger raised 40 mm is 8 % nearer the camera.
    double minWidthRatio = 0.5;
    double maxWidthRatio = 1.5;
    // Eq. 14-15: contour points T(k-t), T(k+t) lie this far from T(k) along the contour, finger widths. Half
    // a rounded tip is 0.79 widths of contour: the step must reach past it onto the finger's sides even for a
    // finger maxWidthRatio wide, and stay on them for a short one.
    double stepWidths = 1.5;
    // Eq. 13: a contour point is a candidate where the angle between T(k)-T(k-t) and T(k)-T(k+t) is below
    // this, radians. Under the step above a long finger of round end makes 2 atan(r / (r + t - pi r / 2)),
    // r its half width: 45 degrees at the expected width, 70 at maxWidthRatio, which is this limit. The
    // paper's pi/2 also takes the bulges of curled fingers and knuckles, 1.3-1.8 finger widths wide; a finger
    // seen end on (pointing at the table) passes when it stands out 1.1 finger widths or more beyond the
    // hand's outline.
    double maxAngleRad = 70.0 * M_PI / 180.0;
    // Candidates closer than this along the contour are one group (the paper's "nearly consecutive"),
    // finger widths: a tip's candidates run without a gap; the tips of neighbouring fingers are a valley
    // apart, at least a finger width of contour.
    double groupGapWidths = 0.25;
    // A tip must stand out at least this far beyond the middle of its two side points T(k-t), T(k+t), finger
    // widths: what shows less is a bump of the outline (a knuckle, the ball of the thumb), not a finger.
    double minLengthWidths = 0.6;
    // Regions smaller than this many finger widths squared are not searched: a lone finger seen from above
    // covers several (a finger's tip alone is about one).
    double minRegionWidths2 = 2.0;
    // The same for a region the edge of the image or of the judged region cuts: only the part of a finger
    // within it shows, and a fingertip touching near that edge (a button at the display's near side) shows
    // its end alone, about one finger width squared.
    double minCutRegionWidths2 = 1.0;
    // A tip pointing within this angle of the way back out of the image where its region's forearm enters
    // is dropped, radians. Fingers point away from the wrist; what seems to point back towards the arm is a
    // thumb raised towards the camera, whose image the parallax pulls back over the hand. Fingers on or near
    // the table point 75 degrees or more away from that way.
    double minArmAngleRad = M_PI / 3.0;
    // A group of candidates that comes this close to the edge of the image or of the judged region, finger
    // widths, is the corner where that edge cuts an arm, rounded off by the mask's smoothing (a majority vote
    // half a finger wide, HandSegmenter), not a fingertip.
    double edgeMarginWidths = 0.25;
    // Most fingertips kept per frame: two hands. The sharpest are kept when there are more.
    int maxFingertips = 10;

    // From the silhouette's end to the pad. A fingertip is about two thirds as thick as it is wide and its
    // end is rounded with half its thickness: the pad lies under the centre of that rounding, a third of the
    // finger's width back along the finger from the silhouette's end (padBackWidths), and the silhouette's
    // end, where the camera's line of sight grazes the rounding, lies about 4 mm above the pad (measured on
    // the simulated rig: 0.33 widths and 4.3 mm for touching fingers, see docs/fingertips.md).
    double padBackWidths = 1.0 / 3.0;
    // Camera pixels of a point at the silhouette end's height -> camera pixels of the point that far straight
    // below it (padDropHomography). The identity when the rig's geometry is unknown: the pad then lies only
    // back along the finger, which a camera looking straight down would see.
    Eigen::Matrix3d padDrop = Eigen::Matrix3d::Identity();

    std::optional<std::string> validate() const;
};

// The homography that drops a camera pixel seen `heightMm` above the table to the point straight below it on
// the table: H_TC(0) H_TC(heightMm)^-1 in camera pixels.
Eigen::Matrix3d padDropHomography(const Calibration& calibration, double heightMm);

// Options for a calibrated rig: fingerWidthPx from `fingerWidthMm` over the camera's scale on the table at
// the image's centre, and padDrop for a silhouette end `endHeightMm` above the pad.
FingertipOptions rigFingertipOptions(const Calibration& calibration, double fingerWidthMm = 16.0,
                                     double endHeightMm = 4.0);

// Buffers reused from frame to frame: once a frame size and a contour length have been seen, nothing is
// allocated.
struct FingertipScratch {
    OuterContours contours;
    std::vector<double> arc;       // arc length along the contour at each point, pixels
    std::vector<double> cosAngle;  // eq. 13 per point; 2 where a point is not a candidate
    Fingertips found;              // before the sharpest are kept
};

// Paper eq. 13-15 on the outer contour of every region of `handMask` (CV_8UC1, 0 / nonzero), then each group
// of candidates refined to a sub-pixel tip and its pad. The image's edge cuts hands and arms that reach
// beyond it: no fingertip is taken where a group of candidates touches it. `judged` (CV_8UC1, the mask's
// size, nonzero where the mask was decided; empty: everywhere) adds the edges of what a segmentation judged,
// which cut hands the same way. `fingertips` is cleared first. Throws std::invalid_argument when the options
// are invalid, the mask is not CV_8UC1 or `judged` does not fit it.
void findFingertips(const cv::Mat& handMask, const FingertipOptions& options, FingertipScratch& scratch,
                    Fingertips& fingertips, const cv::Mat& judged = cv::Mat());

}  // namespace everytouch::core

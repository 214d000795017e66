#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/calibration.h"
#include "core/camera_model.h"
#include "core/contact.h"

namespace everytouch::eval {

// A truth finger where the camera sees it.
struct TruthPoint {
    std::uint32_t id = 0;
    Eigen::Vector2d camera = Eigen::Vector2d::Zero();  // the finger pad, raw camera pixels
    double fingerWidthPx = 0.0;                        // a finger's width there, camera pixels
};

// Maps truth.csv's fingers into the camera through the calibration: the contact point (display pixels) to
// the table (mm), up to the pad at its height above the table (the plane z = height_mm), into the camera
// (undistorted, then through the lens distortion to raw pixels, where masks and frames live).
class TruthToCamera {
public:
    // fingerWidthMm: the physical width of a finger, turned into camera pixels at each place.
    TruthToCamera(const core::Calibration& calibration, double fingerWidthMm);

    TruthPoint operator()(const core::FingerTruth& finger) const;
    // A finger's width on the table at the display's centre, camera pixels: the scale of the fingertip
    // finder.
    double fingerWidthPxAtCentre() const;

private:
    // Table millimetres on the plane z = heightMm -> raw camera pixels.
    Eigen::Vector2d tableToRaw(const Eigen::Vector2d& tableMm, double heightMm) const;
    double widthPxAt(const Eigen::Vector2d& tableMm, double heightMm) const;

    core::Calibration calibration_;
    core::CameraModel camera_;
    Eigen::Matrix3d displayToTable_;
    double fingerWidthMm_;
};

struct FingertipMatch {
    std::size_t truth = 0;      // index into the truth points
    std::size_t detection = 0;  // index into the detections
    double errorPx = 0.0;
};

// One-to-one matches of detected fingertips (their pads, raw camera pixels) to truth points, the closest
// pairs first. A detection can match a truth point no further than one finger width away: the next finger is
// a finger width away or more, so a wider radius would credit a neighbour's tip, and a pad placed anywhere on
// the right fingertip, even at the silhouette's end a third of a width ahead, is within it.
std::vector<FingertipMatch> matchFingertips(const std::vector<TruthPoint>& truth,
                                            const std::vector<Eigen::Vector2d>& detections);

// Fingertip detection over many pairs.
class FingertipScore {
public:
    void add(std::size_t truthCount, std::size_t detectionCount, const std::vector<FingertipMatch>& matches);

    std::int64_t truth() const { return truth_; }
    std::int64_t detections() const { return detections_; }
    std::int64_t matched() const { return matched_; }
    // Matched truth fingers over all truth fingers; nothing without truth fingers.
    std::optional<double> detectionRate() const;
    // Mean distance of the matches, camera pixels; nothing without matches.
    std::optional<double> meanErrorPx() const;
    // Detections without a truth finger per pair. Not all are false: truth lists the fingers a scene
    // presents (pointing, touching, hovering), not a curled finger whose end the silhouette also shows.
    std::optional<double> unmatchedPerPair() const;

private:
    std::int64_t pairs_ = 0;
    std::int64_t truth_ = 0;
    std::int64_t detections_ = 0;
    std::int64_t matched_ = 0;
    double errorSumPx_ = 0.0;
};

}  // namespace everytouch::eval

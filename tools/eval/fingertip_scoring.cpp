#include "eval/fingertip_scoring.h"

#include <algorithm>
#include <cmath>

#include "core/geometry.h"

namespace everytouch::eval {

TruthToCamera::TruthToCamera(const core::Calibration& calibration, double fingerWidthMm)
    : calibration_(calibration),
      camera_{calibration.cameraMatrix, calibration.cameraDistortion},
      displayToTable_(calibration.displayToTableHomography()),
      fingerWidthMm_(fingerWidthMm) {}

Eigen::Vector2d TruthToCamera::tableToRaw(const Eigen::Vector2d& tableMm, double heightMm) const {
    return camera_.distortPixel(
        core::applyHomography(calibration_.tableToCameraHomography(heightMm), tableMm));
}

double TruthToCamera::widthPxAt(const Eigen::Vector2d& tableMm, double heightMm) const {
    // The local scale, pixels per millimetre, as the square root of the map's area ratio: a finger's
    // direction in the image is not known here.
    const double step = 0.5 * fingerWidthMm_;
    const Eigen::Vector2d dx = (tableToRaw(tableMm + Eigen::Vector2d(step, 0), heightMm) -
                                tableToRaw(tableMm - Eigen::Vector2d(step, 0), heightMm)) /
                               (2.0 * step);
    const Eigen::Vector2d dy = (tableToRaw(tableMm + Eigen::Vector2d(0, step), heightMm) -
                                tableToRaw(tableMm - Eigen::Vector2d(0, step), heightMm)) /
                               (2.0 * step);
    return fingerWidthMm_ * std::sqrt(std::abs(dx.x() * dy.y() - dx.y() * dy.x()));
}

TruthPoint TruthToCamera::operator()(const core::FingerTruth& finger) const {
    const Eigen::Vector2d tableMm =
        core::applyHomography(displayToTable_, Eigen::Vector2d(finger.x, finger.y));
    TruthPoint point;
    point.id = finger.id;
    point.camera = tableToRaw(tableMm, finger.heightMm);
    point.fingerWidthPx = widthPxAt(tableMm, finger.heightMm);
    return point;
}

double TruthToCamera::fingerWidthPxAtCentre() const {
    const Eigen::Vector2d centre = core::applyHomography(
        displayToTable_,
        Eigen::Vector2d(calibration_.displaySize.width / 2.0, calibration_.displaySize.height / 2.0));
    return widthPxAt(centre, 0.0);
}

std::vector<FingertipMatch> matchFingertips(const std::vector<TruthPoint>& truth,
                                            const std::vector<Eigen::Vector2d>& detections) {
    std::vector<FingertipMatch> candidates;
    for (std::size_t t = 0; t < truth.size(); ++t)
        for (std::size_t d = 0; d < detections.size(); ++d) {
            const double distance = (detections[d] - truth[t].camera).norm();
            if (distance <= truth[t].fingerWidthPx)
                candidates.push_back({t, d, distance});
        }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const FingertipMatch& a, const FingertipMatch& b) { return a.errorPx < b.errorPx; });
    std::vector<bool> truthTaken(truth.size(), false), detectionTaken(detections.size(), false);
    std::vector<FingertipMatch> matches;
    for (const FingertipMatch& candidate : candidates) {
        if (truthTaken[candidate.truth] || detectionTaken[candidate.detection])
            continue;
        truthTaken[candidate.truth] = detectionTaken[candidate.detection] = true;
        matches.push_back(candidate);
    }
    return matches;
}

void FingertipScore::add(std::size_t truthCount, std::size_t detectionCount,
                         const std::vector<FingertipMatch>& matches) {
    ++pairs_;
    truth_ += static_cast<std::int64_t>(truthCount);
    detections_ += static_cast<std::int64_t>(detectionCount);
    matched_ += static_cast<std::int64_t>(matches.size());
    for (const FingertipMatch& match : matches)
        errorSumPx_ += match.errorPx;
}

std::optional<double> FingertipScore::detectionRate() const {
    if (truth_ == 0)
        return std::nullopt;
    return static_cast<double>(matched_) / static_cast<double>(truth_);
}

std::optional<double> FingertipScore::meanErrorPx() const {
    if (matched_ == 0)
        return std::nullopt;
    return errorSumPx_ / static_cast<double>(matched_);
}

std::optional<double> FingertipScore::unmatchedPerPair() const {
    if (pairs_ == 0)
        return std::nullopt;
    return static_cast<double>(detections_ - matched_) / static_cast<double>(pairs_);
}

}  // namespace everytouch::eval

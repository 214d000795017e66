#include "service/pose_capture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_image.h"
#include "core/gray_frame.h"
#include "core/table_rectangle.h"

namespace everytouch::service {

namespace {

// Levels per band of the noise estimate: narrow enough for shot noise to change little within one, wide
// enough to hold many pixels.
constexpr int kLevelsPerBand = 16;
// A band's median needs this many residuals to be worth more than its neighbours' (its relative error is
// then about 10 %).
constexpr int kMinSamplesPerBand = 100;
// Variance of rounding to whole levels, DN^2.
constexpr double kQuantisationVariance = 1.0 / 12.0;

// A measured tilt that fell short of a limit, in words that agree with the comparison: rounded down to a
// tenth of a degree, so 9.96 reads "9.9" against a limit of 10, never "10".
std::string formatShortTilt(double degrees) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", std::floor(degrees * 10.0) / 10.0);
    return text;
}

// A limit as it is set.
std::string formatLimit(double degrees) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", degrees);
    return text;
}

}  // namespace

std::optional<std::string> PoseCaptureOptions::validate() const {
    if (!(stillSeconds > 0.0 && stillSeconds <= 10.0))
        return "stillSeconds: must be more than 0 and at most 10 s";
    if (!(changeSigmas >= 3.0 && changeSigmas <= 20.0))
        return "changeSigmas: must be from 3 to 20";
    if (!(maxChangedFraction > 0.0 && maxChangedFraction < 1.0))
        return "maxChangedFraction: must be more than 0 and less than 1";
    if (!(minTiltDeg >= 0.0 && minTiltDeg < 90.0))
        return "minTiltDeg: must be from 0 to less than 90 degrees";
    return std::nullopt;
}

std::vector<double> noiseLevels(const cv::Mat& gray) {
    // Immerkaer's mask is the difference of two Laplacians; on pure noise of deviation s its response has
    // deviation 6 s.
    const cv::Mat mask = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
    cv::Mat response;
    cv::filter2D(gray, response, CV_32F, mask, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
    constexpr int bands = 256 / kLevelsPerBand;
    std::vector<std::vector<float>> residuals(bands);
    for (int y = 1; y + 1 < gray.rows; ++y) {
        const auto* level = gray.ptr<std::uint8_t>(y);
        const auto* value = response.ptr<float>(y);
        for (int x = 1; x + 1 < gray.cols; ++x)
            residuals[level[x] / kLevelsPerBand].push_back(std::abs(value[x]));
    }
    std::vector<std::optional<double>> bandSigma(bands);
    for (int band = 0; band < bands; ++band) {
        std::vector<float>& values = residuals[band];
        if (static_cast<int>(values.size()) < kMinSamplesPerBand)
            continue;
        const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
        std::nth_element(values.begin(), middle, values.end());
        // The median of |N(0, s)| is 0.6745 s.
        bandSigma[band] = *middle / 0.6745 / 6.0;
    }
    std::vector<double> levels(256, std::sqrt(kQuantisationVariance));
    for (int band = 0; band < bands; ++band) {
        // Bands without enough pixels take the nearest band that has them.
        std::optional<double> sigma;
        for (int distance = 0; distance < bands && !sigma; ++distance)
            for (const int candidate : {band - distance, band + distance})
                if (candidate >= 0 && candidate < bands && bandSigma[candidate] && !sigma)
                    sigma = bandSigma[candidate];
        for (int level = band * kLevelsPerBand; level < (band + 1) * kLevelsPerBand; ++level)
            levels[level] = std::sqrt(sigma.value_or(0.0) * sigma.value_or(0.0) + kQuantisationVariance);
    }
    return levels;
}

Eigen::Vector3d rectangleSurfaceNormal(const std::array<Eigen::Vector2d, 4>& corners, cv::Size2d sizeMm,
                                       const Eigen::Matrix3d& cameraMatrix) {
    // The rectangle's pose by IPPE (Collins and Bartoli 2014), which takes the rotation from the homography's
    // first-order part at the rectangle, where the foreshortening is well measured, and keeps it a rotation.
    // The directions of the sides alone (the homography's columns) hang on their vanishing points, which a
    // card's stripe of 140 x 16 pixels barely shows: 0.1 px on its corners turns them by 3-5 degrees.
    const std::vector<cv::Point3d> model = {{0.0, 0.0, 0.0},
                                            {sizeMm.width, 0.0, 0.0},
                                            {sizeMm.width, sizeMm.height, 0.0},
                                            {0.0, sizeMm.height, 0.0}};
    std::vector<cv::Point2d> image;
    for (const Eigen::Vector2d& corner : corners)
        image.emplace_back(corner.x(), corner.y());
    cv::Mat intrinsics(3, 3, CV_64F);
    for (int row = 0; row < 3; ++row)
        for (int column = 0; column < 3; ++column)
            intrinsics.at<double>(row, column) = cameraMatrix(row, column);
    cv::Mat rotationVector, translation, rotation;
    const bool solved = cv::solvePnP(model, image, intrinsics, cv::noArray(), rotationVector, translation,
                                     false, cv::SOLVEPNP_IPPE);
    CV_Assert(solved);
    cv::Rodrigues(rotationVector, rotation);
    Eigen::Vector3d normal(rotation.at<double>(0, 2), rotation.at<double>(1, 2), rotation.at<double>(2, 2));
    if (normal.z() > 0.0)
        normal = -normal;
    return normal.normalized();
}

void changeThresholds(const cv::Mat& gray, double changeSigmas, cv::Mat& thresholds) {
    // The difference of two textures carries the noise of both.
    const std::vector<double> sigma = noiseLevels(gray);
    cv::Mat lut(1, 256, CV_8U);
    for (int level = 0; level < 256; ++level)
        lut.at<std::uint8_t>(level) = cv::saturate_cast<std::uint8_t>(
            std::floor(changeSigmas * std::sqrt(2.0) * sigma[static_cast<std::size_t>(level)]));
    cv::LUT(gray, lut, thresholds);
}

double changedFraction(const cv::Mat& reference, const cv::Mat& texture, double changeSigmas) {
    CV_Assert(reference.type() == CV_8UC1 && texture.type() == CV_8UC1 && reference.size() == texture.size());
    cv::Mat thresholds, difference, changed;
    changeThresholds(texture, changeSigmas, thresholds);
    cv::absdiff(texture, reference, difference);
    cv::compare(difference, thresholds, changed, cv::CMP_GT);
    return cv::countNonZero(changed) / static_cast<double>(texture.total());
}

StillnessTracker::State StillnessTracker::offer(const cv::Mat& texture, std::int64_t timestampUs) {
    if (!reference_.empty() && reference_.size() == texture.size()) {
        cv::absdiff(texture, reference_, difference_);
        cv::compare(difference_, threshold_, changed_, cv::CMP_GT);
        changedFraction_ = cv::countNonZero(changed_) / static_cast<double>(texture.total());
        if (changedFraction_ < options_.maxChangedFraction) {
            cv::accumulate(texture, sum_);
            ++count_;
            lastUs_ = timestampUs;
            return stillSeconds() >= options_.stillSeconds ? State::Still : State::Settling;
        }
    }
    texture.copyTo(reference_);
    changeThresholds(reference_, options_.changeSigmas, threshold_);
    sum_ = cv::Mat::zeros(texture.size(), CV_32F);
    cv::accumulate(texture, sum_);
    count_ = 1;
    startUs_ = lastUs_ = timestampUs;
    return State::Changed;
}

void StillnessTracker::average(cv::Mat& texture) const {
    sum_.convertTo(texture, CV_8U, 1.0 / std::max(count_, 1));
}

PoseCapture::PoseCapture(const PoseCaptureOptions& options, const core::ChessboardOptions& board,
                         cv::Size projectorSize, cv::Size2d cardSizeMm, const core::CameraModel& camera)
    : options_(options),
      board_(board),
      projectorSize_(projectorSize),
      cardSizeMm_(cardSizeMm),
      camera_(camera),
      stillness_(options) {}

PoseCapture::Event PoseCapture::offer(const core::FramePair& pair) {
    core::computeSubtractionAndTexture(pair, subtraction_, texture_);
    if (const core::Status frame = core::grayFrame(texture_, gray_); !frame.ok()) {
        problem_ = "the camera frames: " + frame.failure().message;
        return Event::Refused;
    }
    switch (stillness_.offer(gray_, pair.latest().timestampUs)) {
        case StillnessTracker::State::Changed:
            looked_ = false;
            return Event::Moving;
        case StillnessTracker::State::Settling:
            return looked_ ? Event::Waiting : Event::Settling;
        case StillnessTracker::State::Still:
            break;
    }
    if (looked_)
        return Event::Waiting;
    looked_ = true;
    stillness_.average(average_);
    core::Result<Pose> pose = attempt(average_);
    if (!pose.ok()) {
        problem_ = pose.failure().message;
        return Event::Refused;
    }
    problem_.clear();
    average_.copyTo(lastViewTexture_);
    views_.push_back(std::move(pose->view));
    normals_.push_back(pose->normal);
    return Event::Captured;
}

core::Result<Pose> PoseCapture::attempt(const cv::Mat& texture) const {
    const core::Result<core::ChessboardDetection> board =
        core::detectProjectedChessboard(texture, board_, projectorSize_);
    if (!board.ok())
        return core::Failure{"the projected chessboard is not in view whole (" + board.failure().message +
                             ")"};
    core::TableRectangleOptions cardOptions;
    cardOptions.sizeMm = cardSizeMm_;
    const core::Result<core::TableRectangleDetection> card =
        core::findTableRectangle(texture, cardOptions, camera_);
    if (!card.ok())
        return core::Failure{"the card's stripe is not in view (" + card.failure().message + ")"};
    Pose pose;
    pose.normal = rectangleSurfaceNormal(card->corners, cardSizeMm_, camera_.matrix);
    for (std::size_t view = 0; view < normals_.size(); ++view) {
        const double tiltDeg =
            std::acos(std::clamp(pose.normal.dot(normals_[view]), -1.0, 1.0)) * 180.0 / M_PI;
        if (tiltDeg < options_.minTiltDeg)
            return core::Failure{"the surface is tilted only " + formatShortTilt(tiltDeg) +
                                 " degrees against pose " + std::to_string(view + 1) + "; it needs " +
                                 formatLimit(options_.minTiltDeg) + " or more"};
    }
    pose.view.cameraPoints = board->cameraCorners;
    pose.view.projectorPoints = board->projectorCorners;
    std::array<Eigen::Vector2d, 4> rawCorners;
    for (std::size_t corner = 0; corner < rawCorners.size(); ++corner)
        rawCorners[corner] = camera_.distortPixel(card->corners[corner]);
    pose.view.rectangleCorners = rawCorners;
    return pose;
}

}  // namespace everytouch::service

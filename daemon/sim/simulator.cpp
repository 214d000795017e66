#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "core/geometry.h"
#include "core/keystone.h"
#include "core/pattern.h"
#include "sim/rig_geometry.h"

namespace everytouch::sim {

namespace {

// The steps the projector's image creeps in: a tenth of what 1 mm of height moves the code by on the default
// rig (0.19 px).
constexpr double kDriftStepPx = 0.02;

std::uint64_t mix(std::uint64_t value) {
    value += 0x9E3779B97F4A7C15ull;
    value = (value ^ (value >> 30)) * 0xBF58476D1CE4E5B9ull;
    value = (value ^ (value >> 27)) * 0x94D049BB133111EBull;
    return value ^ (value >> 31);
}

}  // namespace

cv::Mat rigPattern(const SimParameters& parameters) {
    core::PatternOptions options;
    options.size = parameters.projectorSize;
    options.seed = parameters.seed;
    return core::generatePattern(options);
}

Simulator::Simulator(const SimParameters& parameters, const cv::Mat& pattern, const cv::Mat& contentImage)
    : parameters_(parameters) {
    if (auto problem = parameters_.validate())
        throw std::invalid_argument(*problem);
    calibration_ = rigCalibration(parameters_);
    if (auto problem = calibration_.validate())
        throw std::invalid_argument("the rig's geometry: " + *problem);
    if (pattern.type() != CV_8UC1 || pattern.size() != calibration_.projectorSize)
        throw std::invalid_argument("pattern: expected a CV_8UC1 image of the projector's size");
    pattern_ = pattern.clone();
    nextIndex_ = firstFrame();
    scenario_ = makeScenario(parameters_.scenario, {calibration_, parameters_.seed, parameters_.handScale});
    renderer_ = std::make_unique<Renderer>(parameters_, calibration_, pattern_);
    if (!contentImage.empty()) {
        if (contentImage.type() == CV_8UC1)
            cv::cvtColor(contentImage, fixedImage_, cv::COLOR_GRAY2BGR);
        else if (contentImage.type() == CV_8UC3)
            fixedImage_ = contentImage.clone();
        else
            throw std::invalid_argument("content: expected an 8-bit gray or BGR image");
        showFixedImage();
    } else if (parameters_.content != "auto") {
        fixedKind_ = contentKindFromName(parameters_.content);
        if (!fixedKind_)
            throw std::invalid_argument(
                "content: \"" + parameters_.content +
                "\" is not a procedural kind (grid35, shapes, photo, ui, text, white, gray)");
    }
    exposureMs_ = parameters_.exposureMs
                      ? *parameters_.exposureMs
                      : renderer_->meterExposureMs(ambientLux(0.0), scenario_->stillProps());
}

std::uint64_t Simulator::firstFrame() const {
    return static_cast<std::uint64_t>(std::llround(parameters_.startS * parameters_.frameRate));
}

std::optional<std::uint64_t> Simulator::endFrame() const {
    if (!parameters_.durationS)
        return std::nullopt;
    return firstFrame() +
           static_cast<std::uint64_t>(std::ceil(*parameters_.durationS * parameters_.frameRate - 1e-9));
}

std::int64_t Simulator::frameTimestampUs(std::uint64_t index) const {
    return static_cast<std::int64_t>(std::llround(index * 1e6 / parameters_.frameRate));
}

double Simulator::ambientLux(double seconds) const {
    if (parameters_.ambientChangeLux && seconds >= parameters_.ambientChangeAtS)
        return *parameters_.ambientChangeLux;
    return parameters_.ambientLux;
}

void Simulator::projectImage(const cv::Mat& projectorImage) {
    renderer_->setProjectorImage(projectorImage);
    projectorImage_ = projectorImage.clone();
    if (!projectorImage.empty() && !userStartS_)
        userStartS_ = frameSeconds(nextIndex_);
}

SceneState Simulator::sceneAt(double seconds) const {
    if (!scenario_->beginsWithTheProjector())
        return scenario_->at(seconds);
    return scenario_->at(userStartS_ ? seconds - *userStartS_ : 0.0);
}

void Simulator::setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) {
    core::checkDisplayToProjector(displaySize, displayToProjector);
    const Eigen::Matrix3d normalised = displayToProjector / displayToProjector(2, 2);
    if (displaySize == calibration_.displaySize &&
        normalised.isApprox(calibration_.displayToProjector, 1e-12))
        return;
    calibration_.displaySize = displaySize;
    calibration_.displayToProjector = normalised;
    renderer_->setDisplay(displaySize, normalised);
    // Hands reach for what the display shows where it now shows it.
    scenario_ = makeScenario(parameters_.scenario, {calibration_, parameters_.seed, parameters_.handScale});
    if (!fixedImage_.empty())
        showFixedImage();
    shown_.reset();
}

void Simulator::showFixedImage() {
    cv::Mat scaled;
    cv::resize(fixedImage_, scaled, calibration_.displaySize, 0, 0, cv::INTER_AREA);
    renderer_->setContent(scaled);
}

void Simulator::showContent(const SceneState& scene) {
    if (!fixedImage_.empty())
        return;
    const std::pair<ContentKind, int> wanted =
        fixedKind_ ? std::pair<ContentKind, int>(*fixedKind_, scene.contentVariant)
                   : std::pair<ContentKind, int>(scene.content, scene.contentVariant);
    if (shown_ == wanted)
        return;
    renderer_->setContent(
        renderContent(wanted.first, calibration_.displaySize, parameters_.seed, wanted.second));
    shown_ = wanted;
}

Eigen::Isometry3d Simulator::knockedTableToCamera() const {
    // The axis and the direction follow from the seed alone: the same knock in every run of the spec.
    std::mt19937_64 random(mix(parameters_.seed ^ 0x6B6E6F636Bull));
    std::normal_distribution<double> normal;
    const auto randomDirection = [&] {
        Eigen::Vector3d v(normal(random), normal(random), normal(random));
        return Eigen::Vector3d(v.normalized());
    };
    const Eigen::Vector3d axis = randomDirection();
    const Eigen::Vector3d direction = randomDirection();
    const Eigen::Isometry3d& before = calibration_.tableToCamera;
    const Eigen::Vector3d centre = -(before.linear().transpose() * before.translation());
    // The camera turns about its own centre: its axes turn in the table's frame, its centre moves only by
    // the shift.
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(parameters_.knockDeg * M_PI / 180.0, axis).toRotationMatrix();
    Eigen::Isometry3d after = Eigen::Isometry3d::Identity();
    after.linear() = before.linear() * turn.transpose();
    after.translation() = -(after.linear() * (centre + parameters_.knockMm * direction));
    return after;
}

Eigen::Isometry3d Simulator::tableSlide() const {
    std::mt19937_64 random(mix(parameters_.seed ^ 0x736C696465ull));
    const double angle = std::uniform_real_distribution<double>(0.0, 2.0 * M_PI)(random);
    const double turn = (std::bernoulli_distribution(0.5)(random) ? 1.0 : -1.0) * parameters_.tableShiftDeg;
    const Eigen::Vector2d onTable = calibration_.displayCentreOnTable();
    const Eigen::Vector3d centre(onTable.x(), onTable.y(), 0.0);
    Eigen::Isometry3d slide = Eigen::Isometry3d::Identity();
    slide.linear() = Eigen::AngleAxisd(turn * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    slide.translation() = centre - slide.linear() * centre +
                          parameters_.tableShiftMm * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    return slide;
}

Eigen::Isometry3d Simulator::tableTilt() const {
    std::mt19937_64 random(mix(parameters_.seed ^ 0x74696C74ull));
    const double angle = std::uniform_real_distribution<double>(0.0, 2.0 * M_PI)(random);
    const Eigen::Vector2d onTable = calibration_.displayCentreOnTable();
    const Eigen::Vector3d centre(onTable.x(), onTable.y(), 0.0);
    const Eigen::Vector3d axis(std::cos(angle), std::sin(angle), 0.0);
    Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
    tilt.linear() = Eigen::AngleAxisd(parameters_.tableTiltDeg * M_PI / 180.0, axis).toRotationMatrix();
    tilt.translation() = centre - tilt.linear() * centre;
    return tilt;
}

Eigen::Vector2d Simulator::driftDirection() const {
    std::mt19937_64 random(mix(parameters_.seed ^ 0x6472696674ull));
    const double angle = std::uniform_real_distribution<double>(0.0, 2.0 * M_PI)(random);
    return {std::cos(angle), std::sin(angle)};
}

Simulator::Placement Simulator::placementAt(double seconds) const {
    Placement placement;
    placement.knocked = parameters_.knockS && seconds >= *parameters_.knockS;
    placement.tableShifted = parameters_.tableShiftS && seconds >= *parameters_.tableShiftS;
    placement.tableTilted = parameters_.tableTiltS && seconds >= *parameters_.tableTiltS;
    // The image creeps in steps far below what the code or a touch can tell, so that the renderer is set up
    // again every few seconds rather than for every frame, and any frame renders alone as in the stream.
    placement.driftSteps = static_cast<long>(
        std::floor(parameters_.driftPxPerMin * std::max(0.0, seconds) / 60.0 / kDriftStepPx));
    return placement;
}

core::Calibration Simulator::geometryAt(double seconds) const {
    const Placement placement = placementAt(seconds);
    core::Calibration geometry = calibration_;
    if (placement.knocked)
        geometry.tableToCamera = knockedTableToCamera();
    // The rig stays where it was, so it stands against the table's new frame as it stood against the old
    // frame's points the table slid to: the plane, and with it the code's registration, is the same.
    if (placement.tableShifted) {
        const Eigen::Isometry3d slide = tableSlide();
        geometry.tableToCamera = geometry.tableToCamera * slide;
        geometry.tableToProjector = geometry.tableToProjector * slide;
    }
    // A tilted table's plane is another plane: the code falls elsewhere than the calibration predicts.
    if (placement.tableTilted) {
        const Eigen::Isometry3d tilt = tableTilt();
        geometry.tableToCamera = geometry.tableToCamera * tilt;
        geometry.tableToProjector = geometry.tableToProjector * tilt;
    }
    // The panel's image moves over the table as its principal point does.
    const Eigen::Vector2d drift = placement.driftSteps * kDriftStepPx * driftDirection();
    geometry.projectorMatrix(0, 2) += drift.x();
    geometry.projectorMatrix(1, 2) += drift.y();
    return geometry;
}

void Simulator::placeRig(double seconds) {
    renderer_ = std::make_unique<Renderer>(parameters_, geometryAt(seconds), pattern_);
    if (!projectorImage_.empty())
        renderer_->setProjectorImage(projectorImage_);
    shown_.reset();
    if (!fixedImage_.empty())
        showFixedImage();
    placed_ = placementAt(seconds);
}

double Simulator::travelMm(const SceneState& from, const SceneState& to) {
    if (from.hands.size() != to.hands.size())
        return 0.0;
    double travel = 0.0;
    for (size_t h = 0; h < from.hands.size(); ++h) {
        travel = std::max(
            travel,
            (from.hands[h].wristToTable.translation() - to.hands[h].wristToTable.translation()).norm());
        for (int f = 0; f < kFingerCount; ++f)
            travel = std::max(travel, (fingerPad(from.hands[h], static_cast<Finger>(f)) -
                                       fingerPad(to.hands[h], static_cast<Finger>(f)))
                                          .norm());
    }
    return travel;
}

void Simulator::render(std::uint64_t index, core::Frame& frame, FrameTruth& truth) {
    const double start = frameSeconds(index);
    const double exposure = exposureMs_ / 1000.0;
    if (placementAt(start) != placed_)
        placeRig(start);
    // The scene at mid-exposure; hands that move are also rendered at more instants of the exposure, about
    // one per camera pixel they travel, and the image averages them.
    const SceneState middle = sceneAt(start + exposure / 2.0);
    showContent(middle);
    // Props in motion are cast with one sample per pixel at mid-exposure; still ones in full.
    const bool still = middle.props.empty() || (middle.props == sceneAt(start).props &&
                                                middle.props == sceneAt(start + exposure).props);
    renderer_->setProps(middle.props, still);
    int instants = 1;
    if (parameters_.motionSamples > 1 && !middle.hands.empty()) {
        const double pixels = 2.0 * travelMm(middle, sceneAt(start + exposure)) / mmPerCameraPixel_;
        instants = std::min(parameters_.motionSamples,
                            1 + 2 * static_cast<int>(std::ceil(std::max(0.0, pixels - 1.0) / 2.0)));
    }
    exposureHands_.resize(instants);
    for (int i = 0; i < instants; ++i)
        exposureHands_[i] =
            i == instants / 2 ? middle.hands : sceneAt(start + (i + 0.5) / instants * exposure).hands;
    frame.index = index;
    frame.timestampUs = frameTimestampUs(index);
    frame.polarity = framePolarity(index);
    renderer_->render(exposureHands_, frame.polarity, ambientLux(start + exposure / 2.0), exposureMs_,
                      mix(parameters_.seed ^ mix(index)), frame.image, truth);
    nextIndex_ = index + 1;
}

}  // namespace everytouch::sim

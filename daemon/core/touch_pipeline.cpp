#include "core/touch_pipeline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/camera_model.h"
#include "core/camera_relocation.h"
#include "core/code_image.h"
#include "core/fill.h"
#include "core/geometry.h"

namespace everytouch::core {

namespace {

bool sameCalibration(const Calibration& a, const Calibration& b) {
    return a.cameraSize == b.cameraSize && a.cameraMatrix == b.cameraMatrix &&
           a.cameraDistortion == b.cameraDistortion && a.projectorSize == b.projectorSize &&
           a.projectorMatrix == b.projectorMatrix && a.tableToCamera.matrix() == b.tableToCamera.matrix() &&
           a.tableToProjector.matrix() == b.tableToProjector.matrix() && a.displaySize == b.displaySize &&
           a.displayToProjector == b.displayToProjector;
}

// A fingertip stays put while it moves less than this fraction of its width between two frames.
constexpr double kStillWidths = 0.1;
// A fingertip of this frame is the one of the last frame when it lies within this fraction of its width.
constexpr double kSameWidths = 0.5;
// A still scene keeps the last segmented pair's mask for at most this long (µs): segmentations that missed a
// hand holding still (a finger resting on the table) are taken again within it, instead of for as long as
// the hand stays put.
constexpr std::int64_t kMostStillUs = 100'000;
// A pair whose S shows no code for the blur to be measured on is followed by this many without a try.
constexpr int kPairsBetweenBlurMeasurements = 30;
// Tiles running, the latest the check measured, that all lie beyond the hold's misregistration hold touches
// back before the check's median moves (half a round of tiles after a knock), and as many running within it
// let them go again: one tile's peak of chance is rare, the same shift in three places of the table running
// is the code that moved. A knock that turns the camera shifts the code by different amounts across the
// table, so single tiles within the limit come and go while it holds.
constexpr std::size_t kTilesRunning = 3;
// A pad read further below the table than this many deviations of its height is no finger's.
constexpr double kBelowTableDeviations = 3.0;
constexpr std::string_view kHeldBackProblem =
    "the code lies further from where the calibration puts it than the table can be told from a hand at, and "
    "no touch is reported";

}  // namespace

std::optional<std::string> DetectionOptions::validate() const {
    if (auto problem = segmentation.validate())
        return "segmentation." + *problem;
    if (auto problem = fingertips.validate())
        return "fingertips." + *problem;
    if (auto problem = height.validate())
        return "height." + *problem;
    if (auto problem = tracker.validate())
        return "tracker." + *problem;
    if (auto problem = registration.validate())
        return "registration." + *problem;
    if (auto problem = correction.validate())
        return "correction." + *problem;
    if (correctCalibration && registration.tilesPerEstimate < kMinRelocationTiles)
        return "registration.tilesPerEstimate: the calibration's correction needs at least " +
               std::to_string(kMinRelocationTiles) + " tiles";
    if (!(fingerWidthMm > 0.0 && fingerWidthMm < 50.0))
        return "fingerWidthMm: must be in (0, 50) mm";
    if (!(visibleSpreadMm >= 0.0 && visibleSpreadMm < 20.0))
        return "visibleSpreadMm: must be in [0, 20) mm";
    if (!(evidenceDecay >= 0.0 && evidenceDecay < 1.0))
        return "evidenceDecay: must be in [0, 1)";
    if (!(slopeMemoryS >= 0.0 && slopeMemoryS <= 60.0))
        return "slopeMemoryS: must be in [0, 60] s";
    return std::nullopt;
}

TouchPipeline::TouchPipeline(const DetectionOptions& options)
    : options_(options),
      segmenter_(options.segmentation),
      registration_(options.registration),
      corrector_(options.correction),
      height_(options.height),
      tracker_(options.tracker),
      remembered_(options.fingertips.maxFingertips),
      rememberedNext_(options.fingertips.maxFingertips) {
    if (auto problem = options.validate())
        throw std::invalid_argument("detection options: " + *problem);
    observations_.reserve(options.fingertips.maxFingertips);
    result_.fingertips.reserve(options.fingertips.maxFingertips);
    found_.reserve(options.fingertips.maxFingertips);
}

void TouchPipeline::reset() {
    tracker_.reset();
    stillScene_.reset();
    segmentationsWithoutFingertips_ = 0;
    rememberedCount_ = 0;
    result_.contacts.clear();
    result_.fingertips.clear();
}

void TouchPipeline::adoptRig(const PipelineSettings& settings) {
    const Calibration& calibration = *settings.calibration;
    const bool samePattern =
        rigPattern_.data == settings.pattern.data && rigPattern_.size() == settings.pattern.size();
    if (samePattern && rigCalibration_ && sameCalibration(*rigCalibration_, calibration))
        return;
    // The settings still hold the calibration this pipeline corrected: it goes on with its correction.
    if (samePattern && correctedFrom_ && sameCalibration(*correctedFrom_, calibration))
        return;
    correctedFrom_.reset();
    segmenter_.setRig(calibration, settings.pattern);
    polarityLock_.setRig(segmenter_.tableCode(), segmenter_.judgedRegion());
    height_.setRig(calibration, settings.pattern);
    codeBlur_.setRig(calibration, settings.pattern, segmenter_.judgedRegion());
    registration_.setRig(calibration, settings.pattern, segmenter_.judgedRegion(),
                         options_.segmentation.cameraBlurPx);
    corrector_.setRig(calibration, options_.registration.tilesPerEstimate);
    result_.calibrationErrorPx.reset();
    result_.calibrationProblem.clear();
    codeBlurMeasured_ = false;
    codeBlurPx_.reset();
    pairsUntilBlurMeasure_ = 0;
    prepareFingertips(calibration);
    prepareHoldBack(calibration);
    const cv::Size2d displayMm = calibration.displaySizeMm();
    displayPixelsPerMm_ = calibration.displaySize.width / displayMm.width;
    rigCalibration_ = calibration;
    rigPattern_ = settings.pattern;
    reset();
}

void TouchPipeline::prepareHoldBack(const Calibration& calibration) {
    // The code seen at a camera pixel moves by parallax as the surface there rises; least at the display's
    // far side from the projector. A 3 x 3 grid over the display's box finds that least.
    const Eigen::Matrix3d onTable = calibration.cameraToProjectorHomography(0.0);
    const Eigen::Matrix3d raised = calibration.cameraToProjectorHomography(1.0);
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const cv::Rect box = segmenter_.displayBox();
    double leastPxPerMm = std::numeric_limits<double>::infinity();
    for (int j = 0; j <= 2; ++j)
        for (int i = 0; i <= 2; ++i) {
            const Eigen::Vector2d pixel = camera.undistortPixel(
                Eigen::Vector2d(box.x + 0.5 * i * box.width, box.y + 0.5 * j * box.height));
            leastPxPerMm = std::min(
                leastPxPerMm, (applyHomography(raised, pixel) - applyHomography(onTable, pixel)).norm());
        }
    heldBackBeyondPx_ = options_.segmentation.minElevationMm * leastPxPerMm;
}

bool TouchPipeline::holdTouches() {
    const std::vector<TileShift>& latest = registration_.latest();
    const auto running = [&](auto&& test) {
        return latest.size() >= kTilesRunning &&
               std::all_of(latest.end() - static_cast<std::ptrdiff_t>(kTilesRunning), latest.end(), test);
    };
    const double limitPx = heldBackBeyondPx_;
    if (running([limitPx](const TileShift& tile) { return tile.projectorPx.norm() > limitPx; }))
        holding_ = true;
    else if (latest.size() < kTilesRunning ||
             running([limitPx](const TileShift& tile) { return tile.projectorPx.norm() <= limitPx; }))
        holding_ = false;
    return holding_ || (result_.calibrationErrorPx && *result_.calibrationErrorPx > limitPx);
}

void TouchPipeline::prepareFingertips(const Calibration& calibration) {
    const FingertipOptions rig = rigFingertipOptions(calibration, options_.fingerWidthMm);
    options_.fingertips.fingerWidthPx = rig.fingerWidthPx;
    options_.fingertips.padDrop = rig.padDrop;
    // Blocks a quarter of a finger wide: a fingertip that moves changes several of them.
    stillScene_.setRegion(segmenter_.displayBox(),
                          std::clamp(static_cast<int>(std::lround(rig.fingerWidthPx / 4.0)), 2, 64));
}

void TouchPipeline::adoptCorrection(const CalibrationCorrection& correction,
                                    const PipelineSettings& settings) {
    if (!correctedFrom_)
        correctedFrom_ = *settings.calibration;
    const Calibration& calibration = correction.calibration;
    segmenter_.setRig(calibration, settings.pattern, codeBlurPx_);
    polarityLock_.setRig(segmenter_.tableCode(), segmenter_.judgedRegion());
    height_.setRig(calibration, settings.pattern);
    registration_.setRig(calibration, settings.pattern, segmenter_.judgedRegion(),
                         codeBlurPx_.value_or(options_.segmentation.cameraBlurPx));
    // A blur measured while the code lay off its prediction (a camera knocked before detection started)
    // is the misregistration's as much as the rig's: it is measured again against the corrected prediction.
    codeBlur_.setRig(calibration, settings.pattern, segmenter_.judgedRegion());
    codeBlurMeasured_ = false;
    pairsUntilBlurMeasure_ = 0;
    prepareFingertips(calibration);
    prepareHoldBack(calibration);
    rigCalibration_ = calibration;
    // The fingertips' evidence was gathered through the old geometry; the tracks and contacts go on.
    rememberedCount_ = 0;
    result_.correction = correction;
}

void TouchPipeline::measureCodeBlur(const cv::Mat& subtraction, const PipelineSettings& settings) {
    if (codeBlurMeasured_ || !codeBlur_.hasRig() || pairsUntilBlurMeasure_-- > 0)
        return;
    // Only where the check finds the code as the calibration predicts it: a code that lies off it (a camera
    // knocked before detection started) follows a prediction blurred far beyond the rig's blur best (2.1
    // camera px instead of 0.92 for a knock that put it 10 projector px off), and the check, predicting
    // through that blur, then found no shift consistent enough to correct. Until then the stages predict
    // with the default blur.
    if (const std::optional<double> errorPx = registration_.errorPx();
        !errorPx || *errorPx > heldBackBeyondPx_)
        return;
    const std::optional<double> blur = codeBlur_.measure(subtraction);
    if (!blur) {
        pairsUntilBlurMeasure_ = kPairsBetweenBlurMeasurements;
        return;
    }
    // Once: a rig's focus does not change while it runs, and a new calibration measures it again.
    codeBlurMeasured_ = true;
    // Measured again after a correction, the blur the stages predict with already: the check goes on with the
    // tiles it has instead of starting over.
    if (codeBlurPx_ && std::abs(*codeBlurPx_ - *blur) < 0.5 * CodeBlurMeter::kStepPx)
        return;
    codeBlurPx_ = *blur;
    segmenter_.setRig(*rigCalibration_, settings.pattern, *blur);
    polarityLock_.setRig(segmenter_.tableCode(), segmenter_.judgedRegion());
    registration_.setRig(*rigCalibration_, settings.pattern, segmenter_.judgedRegion(), *blur);
}

const PipelineResult& TouchPipeline::process(const FramePair& pair, const PipelineSettings& settings) {
    result_.frameIndex = pair.latest().index;
    result_.sceneStill = false;
    result_.correction.reset();  // told in the one pair that made it, idle pairs included
    result_.timestampUs = pair.latest().timestampUs;
    result_.handMask.create(pair.positive.image.size(), CV_8UC1);
    const auto idle = [&](std::string_view reason) -> const PipelineResult& {
        // A pair of frames of two sizes (the camera's changed between them) shows nothing.
        if (pair.negative.image.size() == pair.positive.image.size()) {
            computeSubtractionAndTexture(pair, result_.subtraction, result_.texture);
        } else {
            result_.subtraction.create(pair.positive.image.size(), CV_16SC1);
            result_.texture.create(pair.positive.image.size(), pair.positive.image.type());
            result_.subtraction = cv::Scalar::all(0);
            result_.texture = cv::Scalar::all(0);
        }
        result_.detecting = false;
        result_.idleReason = reason;
        result_.framesSwapped = false;
        fill(result_.handMask, 0);
        reset();
        return result_;
    };
    if (!settings.detect)
        return idle("the projector shows calibration images");
    if (!settings.calibration)
        return idle("not calibrated");
    if (settings.pattern.empty())
        return idle("the projected code is not known");
    if (settings.pattern.size() != settings.calibration->projectorSize)
        return idle("the code does not match the calibration's projector size");
    const cv::Size cameraSize = settings.calibration->cameraSize;
    for (const Frame* frame : {&pair.positive, &pair.negative})
        if (frame->image.size() != cameraSize)
            return idle("the camera's frames are " + std::to_string(frame->image.cols) + "x" +
                        std::to_string(frame->image.rows) + ", the calibration's " +
                        std::to_string(cameraSize.width) + "x" + std::to_string(cameraSize.height));
    adoptRig(settings);
    result_.detecting = true;
    result_.idleReason.clear();
    // The frames in the order the code's sign says: a pair made the wrong way round is made again.
    FramePair ordered = polarityLock_.swapped() ? swappedPair(pair) : pair;
    computeSubtractionAndTexture(ordered, result_.subtraction, result_.texture);
    if (polarityLock_.relock(result_.subtraction)) {
        ordered = swappedPair(ordered);
        computeSubtractionAndTexture(ordered, result_.subtraction, result_.texture);
    }
    measureCodeBlur(result_.subtraction, settings);
    result_.framesSwapped = polarityLock_.swapped();
    result_.polaritySwaps = polarityLock_.swaps();
    // The last pair's mask stays in place while a scene without fingertips stands still. Fingertips are found
    // again in every pair: a finger that moves less than the comparison sees (a pixel or two, within its
    // blocks' noise) still moves the region its height is read on, and a tip kept in place read false
    // touches (palm, seed 2: 4 false touch-downs in 14 instead of 1 in 9).
    // A scene counts as without fingertips once two segmentations running found none: one pair's
    // segmentation can lose a hand that the next finds again.
    const bool unchanged = stillScene_.matchesReference(result_.texture, result_.subtraction);
    result_.sceneStill = unchanged && segmentationsWithoutFingertips_ >= 2 &&
                         result_.timestampUs - segmentedUs_ < kMostStillUs;
    if (!result_.sceneStill) {
        segmenter_.segment(result_.texture, result_.subtraction, result_.handMask);
        findFingertips(result_.handMask, options_.fingertips, fingertipScratch_, found_,
                       segmenter_.judgedRegion());
        stillScene_.adoptAsReference();
        segmentedUs_ = result_.timestampUs;
        segmentationsWithoutFingertips_ = found_.empty() ? segmentationsWithoutFingertips_ + 1 : 0;
    }
    registration_.update(result_.subtraction, result_.handMask, result_.timestampUs);
    result_.calibrationErrorPx = registration_.errorPx();
    if (options_.correctCalibration)
        if (std::optional<CalibrationCorrection> correction =
                corrector_.update(registration_.measured(), registration_.latest()))
            adoptCorrection(*correction, settings);
    measureFingertips(ordered, settings);
    // Beyond heldBackBeyondPx_ the segmentation's height test takes the table itself for something above it,
    // and what it then finds on the table are no fingers (a camera knocked by 0.25 degrees over grid35:
    // 37 false touch-downs in the 0.3 s before the correction). Every contact is released until the
    // correction, or a calibration, brings the code back.
    result_.heldBack = holdTouches();
    std::string_view problem = corrector_.problem();
    if (problem.empty() && result_.heldBack)
        problem = kHeldBackProblem;
    if (result_.calibrationProblem != problem)
        result_.calibrationProblem = problem;
    if (result_.heldBack) {
        tracker_.reset();
        result_.contacts.clear();
    } else {
        tracker_.update(result_.timestampUs, observations_, settings.touchHeightMm, displayPixelsPerMm_,
                        result_.contacts);
    }
    return result_;
}

void TouchPipeline::measureFingertips(const FramePair& pair, const PipelineSettings& settings) {
    const Calibration& calibration = *rigCalibration_;
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    result_.fingertips.clear();
    observations_.clear();
    int next = 0;
    for (const Fingertip& tip : found_) {
        height_.measureFingertip(pair, result_.handMask, tip.tip, tip.direction, tip.widthPx, frameEvidence_);
        // The same fingertip in the last frame: its evidence carries over while it stays put.
        int same = -1;
        double nearest = kSameWidths * tip.widthPx;
        for (int i = 0; i < rememberedCount_; ++i)
            if (const double d = (remembered_[i].tip - tip.tip).norm(); d < nearest) {
                nearest = d;
                same = i;
            }
        Remembered& memory = rememberedNext_[next++];
        memory.tip = tip.tip;
        memory.widthPx = tip.widthPx;
        memory.timestampUs = result_.timestampUs;
        memory.evidence.clear(height_.hypotheses());
        memory.evidence.add(frameEvidence_, 1.0);
        if (same >= 0 && nearest < kStillWidths * tip.widthPx)
            memory.evidence.add(remembered_[same].evidence, options_.evidenceDecay);
        height_.supportSlopes(frameEvidence_, memory.slopes);
        if (same >= 0 && options_.slopeMemoryS > 0.0) {
            const double sinceS =
                static_cast<double>(result_.timestampUs - remembered_[same].timestampUs) * 1e-6;
            memory.slopes.add(remembered_[same].slopes,
                              std::exp(-std::max(0.0, sinceS) / options_.slopeMemoryS));
        }
        const double slope = height_.bestSlope(memory.slopes);

        FingertipObservation& observation = result_.fingertips.emplace_back();
        observation.fingertip = tip;
        observation.visible = height_.estimate(memory.evidence, slope);
        const double uncertaintyMm = std::hypot(observation.visible.uncertaintyMm, options_.visibleSpreadMm);
        // Without a height (the code on it not seen well enough) the pad is placed on the table: the
        // tracker uses it only for a finger that touches.
        if (observation.visible.valid)
            observation.padHeightMm = std::max(0.0, observation.visible.padHeightMm);
        // The contact point: the display pixel straight below the pad, at the height it was read.
        const Eigen::Vector2d undistorted = camera.undistortPixel(tip.pad);
        observation.display =
            applyHomography(calibration.cameraToDisplayBelowHomography(observation.padHeightMm), undistorted);
        // The code there lies on the table itself, a finger's thickness and more below any fingertip's top:
        // the segmentation took a patch of table for skin (an empty table whose code has crept a little off
        // its prediction, between the corrections; the table between spread fingers over dark content).
        // The tracker sees no finger there rather than one resting on the table.
        if (observation.visible.valid &&
            observation.visible.padHeightMm < -kBelowTableDeviations * uncertaintyMm)
            continue;
        FingerObservation& finger = observations_.emplace_back();
        finger.display = observation.display;
        finger.heightKnown = observation.visible.valid;
        // From the evidence the height was sought in: a slide's frames add up to a lean where one frame
        // is too faint. A rising finger also stays put in the image, but its lift shows a height above the
        // touch height before its code fades, and the tracker then lifts it at once.
        if (!finger.heightKnown)
            finger.codeFavoursTable = height_.favoursPadUpTo(memory.evidence, settings.touchHeightMm, slope);
        finger.padHeightMm = observation.padHeightMm;
        if (finger.heightKnown)
            finger.heightUncertaintyMm = uncertaintyMm;
    }
    std::swap(remembered_, rememberedNext_);
    rememberedCount_ = next;
}

}  // namespace everytouch::core

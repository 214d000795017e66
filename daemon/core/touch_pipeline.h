#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/calibration_correction.h"
#include "core/code_blur.h"
#include "core/contact.h"
#include "core/contact_tracker.h"
#include "core/fingertips.h"
#include "core/frame.h"
#include "core/hand_segmentation.h"
#include "core/polarity_lock.h"
#include "core/registration_check.h"
#include "core/still_scene.h"
#include "core/surface_height.h"

namespace everytouch::core {

// What the pipeline needs besides the frames: set by the daemon, changed between two pairs.
struct PipelineSettings {
    std::optional<Calibration> calibration;  // nothing while uncalibrated: no contacts can be found
    cv::Mat pattern;             // the code projected: CV_8UC1 0/1, projector size; empty when unknown
    double touchHeightMm = 0.0;  // a finger pad at or below this height touches
    // False while the projector shows something else than the content (a calibration's images): there is
    // nothing to detect, and the calibration wants the frames at their full rate.
    bool detect = true;
};

// How the pipeline finds contacts. Each stage's options document themselves.
struct DetectionOptions {
    SegmentationOptions segmentation;
    FingertipOptions
        fingertips;  // the scale and the pad's drop come from the calibration (rigFingertipOptions)
    // Fingertips are followed while they hover up to 40 mm, and the top of a fingertip the camera reads lies
    // up to 16 mm above its pad (a finger pointing down at the table): the heights searched reach 60 mm. The
    // segmentation's own measure of a region's height needs only the first few millimetres.
    HeightOptions height{.maxHeightMm = 60.0};
    TrackerOptions tracker;
    RegistrationOptions registration;
    // Whether a calibration the code shows to be off, because the camera or the table moved or the
    // projector's image crept, is corrected while detection runs (core/calibration_correction.h), and how.
    bool correctCalibration = true;
    CorrectionOptions correction;
    // A finger's width (mm): with the calibration's scale it sets the fingertip search's scale.
    double fingerWidthMm = 16.0;
    // How much a fingertip's visible height varies from frame to frame on a resting fingertip, one standard
    // deviation (mm): the correlation's peak shifts as the surface under the region changes with the finger's
    // pose. It adds to each frame's statistical uncertainty, so that the tracker's hysteresis and its
    // decisive evidence see how far one frame's height can really be trusted.
    double visibleSpreadMm = 2.0;
    // Evidence of earlier frames counts this much less each frame while a fingertip stays put (moves less
    // than a tenth of its width): a half-life of about two frames keeps a touch-down's latency at one frame.
    double evidenceDecay = 0.7;
    // How long a fingertip's slope (its finger's pitch) remembers the evidence of earlier frames, s: the
    // support of a frame that long ago counts 1/e as much as this frame's, whether or not the finger moved.
    // Hands change their pitch over a tap or a slide, not from one frame to the next.
    double slopeMemoryS = 0.4;

    std::optional<std::string> validate() const;
};

// One fingertip of one frame, as the pipeline saw it.
struct FingertipObservation {
    Fingertip fingertip;       // camera pixels
    HeightEstimate visible;    // the visible surface's height on the fingertip, from this and earlier frames
    double padHeightMm = 0.0;  // the pad's estimated height above the table
    Eigen::Vector2d display = Eigen::Vector2d::Zero();  // the contact point, display pixels
};

// Everything one pair gave, kept until the next: the images the stages worked on, so that a snapshot shows
// what detection really saw.
struct PipelineResult {
    std::uint64_t frameIndex = 0;
    std::int64_t timestampUs = 0;
    bool detecting = false;  // detection ran: calibrated and the code known
    std::string idleReason;  // why it did not, when it did not
    cv::Mat subtraction;     // S, CV_16SC1
    cv::Mat texture;         // T, the frames' type
    cv::Mat handMask;        // CV_8UC1, 255 on the hand; all 0 when not detecting
    // The scene matched the last segmented pair within the camera's noise (core/still_scene.h), segmented
    // less than 0.1 s before, and that segmentation and the one before it found no fingertip: the mask is
    // that pair's. Tracking ran on this pair.
    bool sceneStill = false;
    // The pair's frames were taken the other way round than they came labelled: the code's sign says which
    // shows O + P (core/polarity_lock.h). S, the height and everything after follow that order.
    bool framesSwapped = false;
    // How often that order has changed since the pipeline started: a camera that started on an O - P frame,
    // a refresh the projector missed.
    std::uint64_t polaritySwaps = 0;
    std::vector<FingertipObservation> fingertips;
    Contacts contacts;  // tracked, in display pixels
    // How far the code on the table lies from where the calibration puts it, projector pixels
    // (core/registration_check.h): from the latest tiles measured; nothing until enough were.
    std::optional<double> calibrationErrorPx;
    // Set in the pair after which the pipeline works with a corrected calibration (the camera or the table
    // moved, or the projector's image crept): it goes on with it, contacts and all, for as long as its
    // settings hold the calibration it corrected.
    std::optional<CalibrationCorrection> correction;
    // Why a calibration the code shows to be off was not corrected, or why no contact is reported while it
    // is off (heldBack); empty otherwise.
    std::string calibrationProblem;
    // The code lies further from where the calibration puts it than the table can be told from a hand at:
    // no contact is reported until it is corrected (fingertips are still found).
    bool heldBack = false;
};

// The seam between the frame loop and detection: one call per frame pair on the pipeline thread.
class PairPipeline {
public:
    virtual ~PairPipeline() = default;
    // The result stays valid until the next call. Throws on failures inside a stage; the caller then calls
    // reset(), which releases every contact.
    virtual const PipelineResult& process(const FramePair& pair, const PipelineSettings& settings) = 0;
    virtual void reset() = 0;
};

// Segmentation, fingertips, height, tracking (docs/detection.md). Allocates nothing per pair once the
// first pairs of a size have been seen.
class TouchPipeline final : public PairPipeline {
public:
    // Throws std::invalid_argument when options.validate() fails.
    explicit TouchPipeline(const DetectionOptions& options = {});

    const PipelineResult& process(const FramePair& pair, const PipelineSettings& settings) override;
    void reset() override;

private:
    // A fingertip remembered from the last frame: its evidence adds up while it stays put.
    struct Remembered {
        Eigen::Vector2d tip = Eigen::Vector2d::Zero();
        double widthPx = 0.0;
        std::int64_t timestampUs = 0;
        HeightEvidence evidence;
        SlopeSupport slopes;
    };

    void adoptRig(const PipelineSettings& settings);
    // Goes on with `correction`'s calibration from the next pair: every stage that predicts the code is
    // prepared for it and the code's blur measured again, while the tracks and their contacts stay.
    void adoptCorrection(const CalibrationCorrection& correction, const PipelineSettings& settings);
    void prepareFingertips(const Calibration& calibration);
    // heldBackBeyondPx_ for this calibration (after the segmenter's).
    void prepareHoldBack(const Calibration& calibration);
    // Whether touches are held back in this pair: the check's median reading beyond heldBackBeyondPx_, or
    // its latest tiles, three running, beyond it since they were last all within it.
    bool holdTouches();
    void measureCodeBlur(const cv::Mat& subtraction, const PipelineSettings& settings);
    void measureFingertips(const FramePair& pair, const PipelineSettings& settings);

    DetectionOptions options_;
    HandSegmenter segmenter_;
    PolarityLock polarityLock_;
    // The code's blur on this rig, read from the first pair that shows the code: the segmentation predicts
    // the table's code with it (core/code_blur.h).
    CodeBlurMeter codeBlur_;
    bool codeBlurMeasured_ = false;
    int pairsUntilBlurMeasure_ = 0;
    StillScene stillScene_;
    RegistrationCheck registration_;
    CalibrationCorrector corrector_;
    std::optional<double> codeBlurPx_;        // as measured on this rig
    std::int64_t segmentedUs_ = 0;            // the timestamp of the last pair segmented
    int segmentationsWithoutFingertips_ = 0;  // running, up to the last
    SurfaceHeight height_;
    ContactTracker tracker_;
    FingertipScratch fingertipScratch_;
    Fingertips found_;
    std::optional<Calibration> rigCalibration_;  // the calibration the stages were prepared for
    // The settings' calibration that rigCalibration_ corrects, while one does.
    std::optional<Calibration> correctedFrom_;
    cv::Mat rigPattern_;
    double displayPixelsPerMm_ = 1.0;
    // The misregistration beyond which the table can no longer be told from a hand, projector pixels:
    // what the segmentation's least elevation moves the code by, where it moves least over the display.
    double heldBackBeyondPx_ = 0.0;
    bool holding_ = false;  // by the latest tiles (holdTouches)
    HeightEvidence frameEvidence_;
    // Fixed capacity (the most fingertips), so that remembering allocates nothing; counts say what is used.
    std::vector<Remembered> remembered_;
    std::vector<Remembered> rememberedNext_;
    int rememberedCount_ = 0;
    std::vector<FingerObservation> observations_;
    PipelineResult result_;
};

}  // namespace everytouch::core

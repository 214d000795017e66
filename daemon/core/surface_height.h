#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/frame.h"

namespace everytouch::core {

// How high the surface is that the camera sees on a fingertip, from the code the projector throws on it
// (paper section VI.C-D, beyond its single 36-bit test): the light a camera pixel sees on a surface at height
// d came from the projector pixel that the homography of the plane at d names. For each candidate height the
// code is predicted over the whole visible fingertip, as the camera blurs it and as skin scatters it, and
// correlated with S there; the best height is the surface's. A fingertip is no plane: its predicted code
// follows the shape of a fingertip (a capsule whose cap is as wide as the finger) tilted towards the hand by
// a slope searched with the height.
struct HeightOptions {
    double maxHeightMm = 48.0;  // candidate heights from 0 up to this (mm)
    double stepMm = 1.0;        // between candidate heights (mm): a fifth of a projector pixel of parallax
    // How skin blurs the code it returns (Gaussian sigma, mm), summed over the camera's channels: part of the
    // light leaves at the surface where it fell, the rest after spreading inside, about a millimetre for red
    // light and a third of that for blue. One Gaussian with the second moment of that mix is about 0.5 mm.
    // Red light's spread alone (0.8 mm) blurred the prediction more than the code on skin is blurred: the
    // peak then follows the code's coarse structure, whose chance alignments moved it by 1-2 mm from one
    // fingertip position to the next (docs/detection.md).
    double skinScatterMm = 0.5;
    // The fingertip region: hand pixels within regionWidths finger widths of a point centreBehindWidths
    // behind the silhouette's end, the centre of the fingertip's cap. Three quarters of a width: with the
    // shape below, the larger region's pixels add evidence instead of spreading it over heights; with a
    // plane, half a width around a quarter behind the end was best.
    double regionWidths = 0.75;
    double centreBehindWidths = 0.5;
    // A correlation must exceed this many standard deviations of chance to count as seeing the code.
    double significance = 3.0;
    // The best height must beat every other peak of the correlation by this many standard deviations of the
    // difference of two chance correlations: otherwise the height is ambiguous and none is given. Two, where
    // the significance above asks three: on grid35 three also rejected a touching finger's height for many
    // frames and missed 1 to 3 of 13 taps, two missed none and still removed nearly all false touches
    // (docs/detection.md).
    double distinctness = 2.0;
    // A finger that moves between the two frames of a pair leaves its own shading in their difference along
    // its outline and creases, often far stronger than the faint code on skin. Over a fingertip such a move
    // is a translation, so what it leaves is the texture's gradient times the move: the difference is first
    // cleared of what the gradient explains, then correlated with the code. On the drag scenario this reads
    // a sliding fingertip's height in 0.53 of its frames instead of 0.15 (surface_height_rendered_test).
    bool explainMotion = true;
    // The fingertip's shape: its thickness over its width (the last joint of a finger is about 12 mm thick
    // and 16 mm wide), which sets how far the cap and the finger's sides fall away from their top.
    double thicknessPerWidth = 0.75;
    // The finger's back rises from its cap towards the hand by a slope (mm per mm along the finger, over the
    // table) searched from 0 up to maxSlope in slopeStep: from a finger lying flat to one pointing down at
    // 63 degrees. A camera far from the projector sees 1 mm of height move the code by 0.7 projector pixels,
    // and there a plane through the fingertip matched the code over too little of it to tell touching from
    // hovering (docs/detection.md, "Other rig geometries").
    double maxSlope = 2.0;
    double slopeStep = 0.5;

    std::optional<std::string> validate() const;
};

// One frame's evidence about the height of a fingertip's visible surface: the covariance of S with the
// predicted code at each candidate height, and the variances it is normalised by. Evidence of frames in which
// the fingertip stays put is summed, which is how several frames add up to one sharper measurement.
struct HeightEvidence {
    std::vector<double> covariance;  // per candidate height
    std::vector<double> codeVariance;
    double subtractionVariance = 0.0;
    double pixels = 0.0;
    // How far the top of the shape the height was sought with lies above its lowest point, the pad (mm),
    // times pixels; 0 for a region searched flat.
    double topAbovePadTimesPixels = 0.0;

    void clear(std::size_t heights);
    void add(const HeightEvidence& other, double weight);
};

// How well each slope of a fingertip's shape explains its code, summed over the frames of its track: the
// log-likelihood of the slope's best height (chance correlations over n pixels having a variance of 2 / n).
// A finger's pitch changes slowly, while one frame's faint code trades slope for height by chance: searched
// frame by frame, the slope's choice alone moved a hovering fingertip's height by 2 mm from one frame to the
// next (docs/detection.md).
struct SlopeSupport {
    std::vector<double> logLikelihood;  // per slope

    void clear(std::size_t slopes);
    void add(const SlopeSupport& other, double weight);
};

struct HeightEstimate {
    // The code was seen on the fingertip well enough to tell a height, its best height lies below the top
    // of the range, and no other height comes near it.
    bool valid = false;
    double heightMm = 0.0;  // of the visible surface above the table: for a fingertip, its top
    // Of its lowest point, by the fingertip's shape (heightMm otherwise): below the table (negative) when the
    // surface read lies lower than the shape's top can.
    double padHeightMm = 0.0;
    double correlation = 0.0;    // at that height
    double uncertaintyMm = 0.0;  // one standard deviation
};

class BilinearSampler;

class SurfaceHeight {
public:
    // Throws std::invalid_argument when options.validate() fails.
    explicit SurfaceHeight(const HeightOptions& options);

    // pattern: CV_8UC1 0/1, projector size.
    void setRig(const Calibration& calibration, const cv::Mat& pattern);

    std::size_t heights() const { return heightCount_; }
    // Candidate (height, slope) pairs in a fingertip's evidence: heights() per slope, slope by slope.
    std::size_t hypotheses() const { return heightCount_ * slopeCount_; }
    double slopeOf(std::size_t candidate) const { return candidate * options_.slopeStep; }
    double heightOf(std::size_t candidate) const { return candidate * options_.stepMm; }

    // Gathers the evidence of one frame pair around a fingertip (camera pixels, raw) of `widthPx` whose
    // finger points along `direction`; handMask: CV_8UC1. The code is read from the frames' difference summed
    // over their channels, not from S (the largest channel's): on skin every channel carries it, and what a
    // move leaves in the sum is linear in the texture's gradient, which explainMotion removes. No allocation
    // once sized.
    void measureFingertip(const FramePair& pair, const cv::Mat& handMask, const Eigen::Vector2d& tip,
                          const Eigen::Vector2d& direction, double widthPx, HeightEvidence& evidence);

    // The evidence of the pixels added since clear(): for any surface, e.g. a region that might be a hand.
    void clearPixels();
    void addPixel(const cv::Mat& subtraction, int x, int y);
    std::size_t pixelCount() const { return values_.size(); }
    // Every `stride`-th candidate height only (the others get no evidence): a coarse look is enough to tell
    // the table from something well above it.
    void measurePixels(HeightEvidence& evidence, std::size_t stride = 1);

    // What one frame's evidence says of each slope.
    void supportSlopes(const HeightEvidence& evidence, SlopeSupport& support) const;
    // The slope the support favours, between the candidates; 0 without support.
    double bestSlope(const SlopeSupport& support) const;

    // The height the evidence supports best: at `slope` (interpolated between the two nearest candidates)
    // when given, otherwise at whichever slope fits best.
    HeightEstimate estimate(const HeightEvidence& evidence, std::optional<double> slope = std::nullopt) const;
    // Whether evidence that gives no height (its peak not distinct, or at the top of the range) still leans:
    // its best match among the pad heights up to `padHeightMm` is significant and beats every one above.
    bool favoursPadUpTo(const HeightEvidence& evidence, double padHeightMm,
                        std::optional<double> slope = std::nullopt) const;

private:
    // Where the projector sees each pixel's ray: on the table and a step up to the next candidate height
    // (homogeneous, in projector pixels), one array per coordinate so that pixels are read four at a time.
    struct PanelRays {
        std::vector<float> x, y, z, stepX, stepY, stepZ;

        void clear();
        void reserve(std::size_t pixels);
        void add(const Eigen::Vector3d& onTable, const Eigen::Vector3d& step);
        void addOutside();  // a ray that meets no candidate plane: it samples nothing
    };
    static constexpr std::size_t kLanes = 4;  // candidate heights summed together

    void addValue(float value, int x, int y);
    // residuals_: values_ less their mean and, when gradients_ were gathered, what the gradients explain.
    void fitResiduals();
    // How many candidate steps apart a ray's profile from firstStep over `length` steps may be sampled so
    // that the panel moves at most profileSpacingPx_ between two samples.
    std::size_t profileSpacingSteps(int firstStep, std::size_t length) const;
    // profiles_: each pixel's predicted code at firstStep, firstStep + 1, ... (length steps) up its ray,
    // sampled every `spacing` steps and at the last, and interpolated between.
    void sampleProfiles(const BilinearSampler& sample, int firstStep, std::size_t length,
                        std::size_t spacing);
    // Over the region's pixels, the predicted code at kLanes candidates from `candidate` on, blended from
    // the profiles as blendOffsets_ and blendWeights_ say: its sum, its sum of squares and its sum of
    // products with the residuals.
    void accumulateBlends(std::size_t candidate, std::array<float, kLanes>& values,
                          std::array<float, kLanes>& squares, std::array<float, kLanes>& products) const;
    // Where an undistorted pixel's ray meets the table (mm), and the cosine of its angle from the vertical.
    Eigen::Vector2d onTable(const Eigen::Vector2d& undistorted) const;
    double verticalCosine(const Eigen::Vector2d& undistorted) const;
    // The ray through an undistorted pixel, table frame, from the camera's centre (not unit length).
    Eigen::Vector3d rayThrough(const Eigen::Vector2d& undistorted) const;

    HeightOptions options_;
    cv::Mat panel_;                  // CV_32FC1: the pattern as skin and the camera blur it, projector pixels
    double profileSpacingPx_ = 1.0;  // how far the panel may move between two samples of a ray's profile
    cv::Mat undistorted_;            // CV_32FC2, camera size: each raw pixel's undistorted position
    std::size_t heightCount_ = 0;
    std::size_t slopeCount_ = 1;
    // For a fingertip's pixels: how far behind the cap's centre along the finger (mm) and how far below
    // the fingertip's top the surface they see lies (mm; along the view until the rays are known, then in
    // height). Empty for other regions, which are searched flat.
    struct FingertipShape {
        float behindCapMm, belowTopMm;
    };
    std::vector<FingertipShape> shape_;
    // The geometry of the candidate planes: undistorted pixel -> ray (table frame), the camera's centre
    // (table frame), the projector's intrinsics times rotation, and the projector's image of the camera's
    // centre (homogeneous).
    Eigen::Matrix3d rayFromPixel_ = Eigen::Matrix3d::Identity();
    Eigen::Vector3d cameraCentre_ = Eigen::Vector3d::Zero();
    Eigen::Matrix3d projectorRotation_ = Eigen::Matrix3d::Identity();
    Eigen::Vector3d epipole_ = Eigen::Vector3d::Zero();
    std::vector<float> values_;           // S (or a pair's difference) at the region's pixels
    std::vector<cv::Point2f> gradients_;  // the texture's gradient there, when a move is explained
    std::vector<cv::Point2f> points_;     // the region's undistorted pixels
    std::vector<float> residuals_;        // values_ less what their mean and a move explain
    PanelRays rays_;
    std::vector<float> profiles_;
    std::vector<std::size_t> blendOffsets_;  // per pixel: where its profile is read for candidate 0
    std::vector<float> blendWeights_;        // per pixel: how far between two profile steps
};

}  // namespace everytouch::core

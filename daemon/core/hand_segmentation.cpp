#include "core/hand_segmentation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "core/camera_model.h"
#include "core/fill.h"
#include "core/geometry.h"

namespace everytouch::core {

namespace {

enum BlockClass : uchar {
    Outside = 0,    // not on the display
    Table = 1,      // shows the table's code
    Unlit = 2,      // the code is too faint to tell: a shadow, black content
    Candidate = 3,  // lit, and not the table's code
    Hand = 4,       // a candidate in a region large enough to be a hand
    Grown = 5,      // too faint to tell by the code, joined to the hand by its colour
    Touching = 6,   // shows the table's code, joined to the hand by its colour: a touching fingertip's end
};

bool isHand(uchar c) {
    return c == Hand || c == Grown || c == Touching;
}

// Where in the sorted values the fraction lies (nth_element on a reused buffer).
float quantile(std::vector<float>& values, double fraction) {
    if (values.empty())
        return 0.0f;
    const auto nth = values.begin() + static_cast<long>(fraction * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), nth, values.end());
    return *nth;
}

// How much brightness counts against colour when a pixel is matched to a side of the outline: shading
// changes brightness across the hand and the projected content changes both sides alike, while the skin's
// chromaticity differs from the table's wherever the light comes from.
constexpr float kBrightnessWeight = 0.25f;

// A colour as chromaticity and brightness, in levels: (r, g) / (r + g + b) scaled to 0..255, then the
// weighted mean level. A gray camera has brightness only.
void colourFeature(const float* bgr, int channels, float* feature) {
    if (channels == 1) {
        feature[0] = feature[1] = 0.0f;
        feature[2] = bgr[0];
        return;
    }
    const float sum = std::max(bgr[0] + bgr[1] + bgr[2], 1.0f);
    feature[0] = 255.0f * bgr[2] / sum;
    feature[1] = 255.0f * bgr[1] / sum;
    feature[2] = kBrightnessWeight * sum / 3.0f;
}

float chromaticityDistanceSquared(const float* a, const float* b) {
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]);
}

float featureDistanceSquared(const float* a, const float* b) {
    return chromaticityDistanceSquared(a, b) + (a[2] - b[2]) * (a[2] - b[2]);
}

// Blocks searched for colour samples around a block on the outline.
constexpr int kColourReach = 3;
constexpr int kColourSamples = (2 * kColourReach + 1) * (2 * kColourReach + 1);

// The blocks around an outline block, nearest first: a pixel's colour most often resembles the blocks next to
// it, so a search in this order finds a sample that settles its side sooner.
const std::array<cv::Point, kColourSamples>& colourSampleOffsets() {
    static const std::array<cv::Point, kColourSamples> offsets = [] {
        std::array<cv::Point, kColourSamples> sorted;
        int i = 0;
        for (int dy = -kColourReach; dy <= kColourReach; ++dy)
            for (int dx = -kColourReach; dx <= kColourReach; ++dx)
                sorted[i++] = cv::Point(dx, dy);
        std::stable_sort(sorted.begin(), sorted.end(),
                         [](cv::Point a, cv::Point b) { return a.dot(a) < b.dot(b); });
        return sorted;
    }();
    return offsets;
}

// Colour features of one side of the outline, and the squared distance from a pixel's feature to the nearest
// of them. Each component is kept in its own array so that four samples are compared at once; once all are
// added, finish() repeats the last sample up to a multiple of four, which changes no minimum.
class NearestColour {
public:
    bool empty() const { return count_ == 0; }
    void add(const float* feature) {
        first_[count_] = feature[0];
        second_[count_] = feature[1];
        third_[count_] = feature[2];
        ++count_;
    }
    void finish() {
        for (int k = count_; k % kLanes != 0; ++k) {
            first_[k] = first_[count_ - 1];
            second_[k] = second_[count_ - 1];
            third_[k] = third_[count_ - 1];
        }
    }
    float nearestDistance(const float* feature) const {
        const Query query(feature);
        constexpr float kFar = std::numeric_limits<float>::max();
        Lanes nearest = {kFar, kFar, kFar, kFar};
        for (int k = 0; k < count_; k += kLanes) {
            const Lanes distance = distancesAt(query, k);
            nearest = distance < nearest ? distance : nearest;
        }
        return std::min(std::min(nearest[0], nearest[1]), std::min(nearest[2], nearest[3]));
    }
    // Whether a sample lies within `limit` (squared distance) of the feature; with `strictly`, nearer than
    // it. The search stops at the first.
    bool anyWithin(const float* feature, float limit, bool strictly = false) const {
        const Query query(feature);
        const Lanes bound = {limit, limit, limit, limit};
        for (int k = 0; k < count_; k += kLanes) {
            const Lanes distance = distancesAt(query, k);
            const auto within = strictly ? distance < bound : distance <= bound;
            if (within[0] | within[1] | within[2] | within[3])
                return true;
        }
        return false;
    }

private:
    static constexpr int kLanes = 4;
    typedef float Lanes __attribute__((vector_size(kLanes * sizeof(float))));
    // A feature's components, each in every lane.
    struct Query {
        explicit Query(const float* feature)
            : first{feature[0], feature[0], feature[0], feature[0]},
              second{feature[1], feature[1], feature[1], feature[1]},
              third{feature[2], feature[2], feature[2], feature[2]} {}
        Lanes first, second, third;
    };
    // The squared distances from the query to samples k .. k + kLanes - 1.
    Lanes distancesAt(const Query& query, int k) const {
        Lanes da, db, dc;
        std::memcpy(&da, first_ + k, sizeof da);
        std::memcpy(&db, second_ + k, sizeof db);
        std::memcpy(&dc, third_ + k, sizeof dc);
        da -= query.first;
        db -= query.second;
        dc -= query.third;
        return da * da + db * db + dc * dc;
    }
    static constexpr int kCapacity = (kColourSamples + kLanes - 1) / kLanes * kLanes;
    float first_[kCapacity], second_[kCapacity], third_[kCapacity];
    int count_ = 0;
};

// Without a view beyond the projection the noise is taken as this variance of S (DN^2): a camera at its
// default gain with some 1.4 DN of noise per frame.
constexpr float kFallbackNoiseVariance = 4.0f;
// Windows beyond the projection needed to measure the noise there: the median of their variances then lies
// within a few per cent of the noise's.
constexpr std::size_t kMinUnlitWindows = 32;
// Where nothing is lit, S of a colour camera is the largest of three channels' noise: its mean is 0.846 and
// its standard deviation 0.748 of one channel's, so its level is 1.13 standard deviations of S itself.
constexpr float kZeroLevelPerSd = 1.1314f;
// How many standard deviations of chance correlation the table's expected correlation must exceed for the
// code to tell the table from something else.
constexpr float kSignificance = 3.0f;
// The brightest code pixel shows twice the code's mean (half the bits are 1); noise and a brighter patch of
// table add to that. Beyond this many times the table's mean, S is no longer code.
constexpr float kMotionAmplitudes = 3.0f;
// The table's colour beyond the projection is measured on the pixels of this many of its blocks at most: 256
// pixels set a median to a tenth of their scatter, and the scatter's median to a fifth of itself.
constexpr std::size_t kMaxUnlitTableBlocks = 16;
// An unlit pixel is the hand's when its chromaticity is at least three times nearer the skin's than the unlit
// table's (squared distances nine times): a pixel that mixes the two is then three quarters skin or more.
constexpr float kUnlitSkinRatio = 9.0f;
// S within this many standard deviations of its noise about the level where nothing is lit: the scene did
// not change between the two frames.
constexpr float kStillSigmas = 3.0f;
// A pixel that gets no projector light is the hand only when its chromaticity lies farther from the table's
// as the room alone lights it than all but one in a thousand of the table's own pixels would, were their
// scatter Gaussian: the squared distance of two such components exceeds 13.82 times their variance one time
// in a thousand, and its median is 1.386 times it.
constexpr float kUnlitTableSpreadPerMedian = 13.82f / 1.386f;
// A block that shows the table's code joins a touching finger only when its colour is at least three times
// nearer the hand's than the table's (squared distances nine times): the code, the stronger cue, says table.
constexpr float kTouchingColourRatio = 9.0f;
// The segmentation predicts the table's code this much sharper than the rig shows it (Gaussian sigma, camera
// pixels, in quadrature): the last millimetres of a touching fingertip show the table's code shifted by less
// than a pixel, which a sharper prediction tells from the table better. On the default simulated rig, which
// shows the code with 0.92 px, that is the 0.5 px the segmentation was developed with; predicted exactly as
// blurred as seen, ε at touch-down rose there by 0.1-0.35 px (docs/detection.md, "The code's blur").
constexpr double kPredictionSharperPx = 0.77;

}  // namespace

const char* toString(SegmentationMethod method) {
    return method == SegmentationMethod::Code ? "code" : "paper";
}

std::optional<SegmentationMethod> parseSegmentationMethod(const std::string& name) {
    if (name == "code")
        return SegmentationMethod::Code;
    if (name == "paper")
        return SegmentationMethod::Paper;
    return std::nullopt;
}

std::optional<std::string> SegmentationOptions::validate() const {
    if (blockPx < 2)
        return "blockPx: must be at least 2 pixels";
    if (windowBlocks < 1 || windowBlocks % 2 == 0)
        return "windowBlocks: must be an odd number of blocks";
    if (!(cameraBlurPx >= 0.0) || !std::isfinite(cameraBlurPx))
        return "cameraBlurPx: must be a non-negative number of pixels";
    if (!(fingerWidthMm > 0.0) || !std::isfinite(fingerWidthMm))
        return "fingerWidthMm: must be a positive number of millimetres";
    if (!(smoothingWidths >= 0.0 && smoothingWidths <= 2.0))
        return "smoothingWidths: must be from 0 to 2 finger widths";
    if (!(minElevationMm >= 0.0 && minElevationMm < elevation.maxHeightMm))
        return "minElevationMm: must be from 0 to the highest elevation measured";
    if (!(misregistrationPx >= 0.0 && misregistrationPx <= 8.0))
        return "misregistrationPx: must be from 0 to 8 projector pixels";
    if (closingRadiusPx < 0)
        return "closingRadiusPx: must not be negative";
    if (auto problem = saliency.validate())
        return "saliency." + *problem;
    if (auto problem = meanShift.validate())
        return "meanShift." + *problem;
    if (auto problem = elevation.validate())
        return "elevation." + *problem;
    if (auto problem = confidence.validate())
        return "confidence." + *problem;
    return std::nullopt;
}

HandSegmenter::HandSegmenter(const SegmentationOptions& options)
    : options_(options), elevation_(options.elevation) {
    if (auto problem = options.validate())
        throw std::invalid_argument("segmentation options: " + *problem);
}

void HandSegmenter::setRig(const Calibration& calibration, const cv::Mat& pattern,
                           std::optional<double> measuredCodeBlurPx) {
    const double predictionBlurPx =
        measuredCodeBlurPx ? std::sqrt(std::max(0.0, *measuredCodeBlurPx * *measuredCodeBlurPx -
                                                         kPredictionSharperPx * kPredictionSharperPx))
                           : options_.cameraBlurPx;
    tableCode_ = predictTableCode(calibration, pattern, predictionBlurPx);
    shiftedCode_.setCode(tableCode_.predicted);
    elevation_.setRig(calibration, pattern);
    evidence_ = CodeEvidence{};
    evidence_.blockPx = options_.blockPx;
    evidence_.windowBlocks = options_.windowBlocks;
    evidence_.wideWindowBlocks = options_.windowBlocks + 2;

    // The display's outline in raw camera pixels, through the lens distortion.
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const Eigen::Matrix3d displayToCamera = calibration.cameraToDisplayHomography(0.0).inverse();
    std::vector<cv::Point> outline;
    const double w = calibration.displaySize.width, h = calibration.displaySize.height;
    constexpr int kSamplesPerEdge = 32;
    const Eigen::Vector2d corners[] = {{0, 0}, {w, 0}, {w, h}, {0, h}, {0, 0}};
    for (int edge = 0; edge < 4; ++edge)
        for (int i = 0; i < kSamplesPerEdge; ++i) {
            const Eigen::Vector2d d =
                corners[edge] + (corners[edge + 1] - corners[edge]) * i / kSamplesPerEdge;
            const Eigen::Vector2d raw = camera.distortPixel(applyHomography(displayToCamera, d));
            outline.emplace_back(cvRound(raw.x()), cvRound(raw.y()));
        }
    cv::Mat display = cv::Mat::zeros(calibration.cameraSize, CV_8UC1);
    cv::fillPoly(display, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255));
    displayBox_ = cv::boundingRect(display);

    // A block is judged when its whole window lies on the display: a window reaching beyond the display's
    // edge sees the code end there, which looks like something above the table.
    const int blockPx = options_.blockPx, reach = options_.windowBlocks / 2;
    const cv::Size blocks(calibration.cameraSize.width / blockPx, calibration.cameraSize.height / blockPx);
    cv::Mat onDisplay(blocks, CV_8UC1);
    for (int by = 0; by < blocks.height; ++by)
        for (int bx = 0; bx < blocks.width; ++bx)
            onDisplay.at<uchar>(by, bx) =
                cv::countNonZero(display(cv::Rect(bx * blockPx, by * blockPx, blockPx, blockPx))) ==
                blockPx * blockPx;
    displayBlocks_ = cv::Mat::zeros(blocks, CV_8UC1);
    // The windows that no projector light reaches, where the noise of S is measured: whole windows (one that
    // the image's edge cuts short is no view beyond the projection) holding no pixel on the code, so that
    // the projection's blurred edge stays out.
    cv::Mat blockOnCode(blocks, CV_8UC1);
    for (int by = 0; by < blocks.height; ++by)
        for (int bx = 0; bx < blocks.width; ++bx) {
            double highest = 0.0;
            cv::minMaxLoc(tableCode_.predicted(cv::Rect(bx * blockPx, by * blockPx, blockPx, blockPx)),
                          nullptr, &highest);
            blockOnCode.at<uchar>(by, bx) = highest >= 0.0;  // negative where no projector pixel lands
        }
    unlitWindows_.clear();
    for (int by = reach; by < blocks.height - reach; ++by)
        for (int bx = reach; bx < blocks.width - reach; ++bx)
            if (cv::countNonZero(
                    blockOnCode(cv::Rect(bx - reach, by - reach, 2 * reach + 1, 2 * reach + 1))) == 0)
                unlitWindows_.push_back(by * blocks.width + bx);
    // The per-frame buffers at their largest, so that no frame allocates.
    const std::size_t blockCount = static_cast<std::size_t>(blocks.area());
    const std::size_t unlitPixels = static_cast<std::size_t>(kMaxUnlitTableBlocks * blockPx * blockPx);
    values_.reserve(std::max(blockCount, unlitPixels));
    for (auto& component : unlitChromaticities_)
        component.reserve(unlitPixels);
    unlitVariances_.reserve(blockCount);
    queue_.resize(blockCount);
    component_.resize(blockCount);
    sampleBlocks_.reserve(blockCount);
    blocksToHand_.resize(blockCount);
    tableDistance_.resize(blockCount);
    for (int by = reach; by < blocks.height - reach; ++by)
        for (int bx = reach; bx < blocks.width - reach; ++bx)
            displayBlocks_.at<uchar>(by, bx) =
                cv::countNonZero(onDisplay(cv::Rect(bx - reach, by - reach, 2 * reach + 1, 2 * reach + 1))) ==
                (2 * reach + 1) * (2 * reach + 1);

    judgedRegion_ = cv::Mat::zeros(calibration.cameraSize, CV_8UC1);
    if (options_.method == SegmentationMethod::Paper) {
        judgedRegion_(displayBox_).setTo(255);
    } else {
        for (int by = 0; by < blocks.height; ++by)
            for (int bx = 0; bx < blocks.width; ++bx)
                if (displayBlocks_.at<uchar>(by, bx))
                    judgedRegion_(cv::Rect(bx * blockPx, by * blockPx, blockPx, blockPx)).setTo(255);
    }

    const Eigen::Matrix3d cameraToTable = calibration.tableToCameraHomography(0.0).inverse();
    const Eigen::Vector2d centre(calibration.cameraSize.width / 2.0, calibration.cameraSize.height / 2.0);
    const double mmPerPixel = (applyHomography(cameraToTable, centre + Eigen::Vector2d(0.5, 0)) -
                               applyHomography(cameraToTable, centre - Eigen::Vector2d(0.5, 0)))
                                  .norm();
    pixelsPerMm_ = 1.0 / mmPerPixel;
}

void HandSegmenter::segment(const cv::Mat& texture, const cv::Mat& subtraction, cv::Mat& mask) {
    CV_Assert(texture.type() == CV_8UC3 || texture.type() == CV_8UC1);
    if (options_.method == SegmentationMethod::Paper) {
        segmentAsPaper(texture, mask);
        return;
    }
    if (!hasRig())
        throw std::logic_error("the code segmentation needs the rig: call setRig first");
    CV_Assert(subtraction.size() == texture.size() && texture.size() == tableCode_.predicted.size());
    segmentByCode(texture, subtraction, mask);
}

void HandSegmenter::segmentByCode(const cv::Mat& texture, const cv::Mat& subtraction, cv::Mat& mask) {
    measureCodeEvidence(subtraction, tableCode_, evidence_);
    classifyBlocks(texture.channels());
    keepHandComponents(subtraction);
    mask.create(texture.size(), CV_8UC1);
    fill(mask, 0);
    // Colours matter only around the hand; they are measured when first looked at.
    blockColour_.create(blockClass_.size(), CV_32FC3);
    colourKnown_.create(blockClass_.size(), CV_8UC1);
    fill(colourKnown_, 0);
    unlitTableMeasured_ = false;
    growIntoFaintBlocks(texture);
    growOverTouchingSkin(texture);
    findHandBox();
    labelPixels(texture, subtraction, mask);

    // The hand's blocks with the outline's blocks around them.
    const cv::Rect handBlocks =
        handBox_.empty() ? cv::Rect()
                         : cv::Rect(handBox_.x - 1, handBox_.y - 1, handBox_.width + 2, handBox_.height + 2);
    const int blockPx = options_.blockPx;
    const int radius =
        static_cast<int>(std::lround(0.5 * options_.smoothingWidths * options_.fingerWidthMm * pixelsPerMm_));
    voteByMajority(mask,
                   cv::Rect(handBlocks.x * blockPx, handBlocks.y * blockPx, handBlocks.width * blockPx,
                            handBlocks.height * blockPx),
                   radius, majorityScratch_);
}

void HandSegmenter::classifyBlocks(int channels) {
    const CodeEvidence::Window& narrow = evidence_.narrow;
    const int rows = narrow.correlation.rows, cols = narrow.correlation.cols;
    // Where the camera sees beyond the projection S holds nothing but noise: its level (which the largest
    // of three channels' differences lifts above zero) and its variance. A camera framed on the projection
    // has no such view.
    values_.clear();
    unlitVariances_.clear();
    for (const int window : unlitWindows_) {
        values_.push_back(narrow.meanS.at<float>(window));
        unlitVariances_.push_back(narrow.varianceS.at<float>(window));
    }
    float zeroLevel = 0.0f;
    if (values_.size() >= kMinUnlitWindows) {
        zeroLevel = quantile(values_, 0.5);
        noiseVariance_ = std::max(quantile(unlitVariances_, 0.5), 0.25f);
    } else {
        noiseVariance_ = kFallbackNoiseVariance;
        zeroLevel = channels == 3 ? kZeroLevelPerSd * std::sqrt(noiseVariance_) : 0.0f;
    }

    // What the table's code would correlate with where the code's amplitude is g: S = g P + noise gives
    // r = g sd(P) / sqrt(g^2 var(P) + noise). The camera's blur is predicted only approximately, so the
    // table reaches a fraction of that, measured in this frame among the blocks that are clearly lit.
    const auto ideal = [&](float meanS, float codeVariance) {
        const float gain = 2.0f * std::max(0.0f, meanS - zeroLevel);
        return gain * std::sqrt(codeVariance) / std::sqrt(gain * gain * codeVariance + noiseVariance_);
    };
    // The narrow window's ideal correlation on the display's blocks that show the code (NaN elsewhere).
    narrowIdeal_.create(narrow.correlation.size(), CV_32FC1);
    values_.clear();
    for (int by = 0; by < rows; ++by) {
        const float* correlation = narrow.correlation.ptr<float>(by);
        const float* meanS = narrow.meanS.ptr<float>(by);
        const float* codeVariance = narrow.varianceCode.ptr<float>(by);
        const uchar* onDisplay = displayBlocks_.ptr<uchar>(by);
        float* idealRow = narrowIdeal_.ptr<float>(by);
        for (int bx = 0; bx < cols; ++bx) {
            idealRow[bx] = std::numeric_limits<float>::quiet_NaN();
            if (!onDisplay[bx] || std::isnan(correlation[bx]))
                continue;
            idealRow[bx] = ideal(meanS[bx], codeVariance[bx]);
            if (idealRow[bx] > 0.5f)
                values_.push_back(correlation[bx] / idealRow[bx]);
        }
    }
    const float fidelity = std::clamp(quantile(values_, 0.9), 0.0f, 1.0f);
    fidelity_ = fidelity;

    // One standard deviation of a correlation over a window when nothing correlates: neighbouring pixels
    // share light through the blur, about two pixels per independent sample.
    const auto chance = [](int pixels) { return std::sqrt(2.0f / static_cast<float>(pixels)); };
    const float narrowChance = chance(narrow.pixels), wideChance = chance(evidence_.widePixels());

    blockClass_.create(narrow.correlation.size(), CV_8UC1);
    values_.clear();
    for (int by = 0; by < rows; ++by)
        for (int bx = 0; bx < cols; ++bx) {
            uchar& c = blockClass_.at<uchar>(by, bx);
            const float narrowIdeal = narrowIdeal_.at<float>(by, bx);
            if (std::isnan(narrowIdeal)) {
                c = Outside;
                continue;
            }
            // The narrow window where the code is strong enough there; the wide one where it is faint.
            float correlation = narrow.correlation.at<float>(by, bx);
            float expected = fidelity * narrowIdeal;
            if (expected < kSignificance * narrowChance) {
                const WindowStatistics wide = evidence_.wideAt(by, bx);
                if (std::isnan(wide.correlation)) {
                    c = Unlit;
                    continue;
                }
                correlation = wide.correlation;
                expected = fidelity * ideal(wide.meanS, wide.varianceCode);
                if (expected < kSignificance * wideChance) {
                    c = Unlit;  // the table's code would not stand out of the noise here either
                    continue;
                }
            }
            if (correlation >= 0.5f * expected) {
                c = Table;
                values_.push_back(narrow.meanS.at<float>(by, bx));
            } else {
                c = Candidate;
            }
        }
    const float tableAmplitude = quantile(values_, 0.5);
    tableAmplitude_ = tableAmplitude;
    // A pixel gets no projector light at all (a shadow) when the mean of S around it stays within the noise
    // of the level where nothing is lit: three standard deviations of a 3 x 3 mean.
    litAmplitude_ = zeroLevel + std::sqrt(noiseVariance_);
    zeroLevel_ = zeroLevel;
}

bool HandSegmenter::liesOnTable(const cv::Mat& subtraction, int size) {
    // Blocks on the component's rim have windows that see the table beside it, whose sharp code would pull
    // the height down: the height is measured on the blocks whose neighbours are all in the component, on
    // all of them when it has too few such blocks to tell.
    const int rows = blockClass_.rows, cols = blockClass_.cols;
    const uchar* classes = blockClass_.ptr<uchar>();
    const auto interior = [&](int i) {
        const int y = i / cols, x = i % cols;
        if (y == 0 || x == 0 || y == rows - 1 || x == cols - 1)
            return false;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                if (classes[(y + dy) * cols + x + dx] != Hand)
                    return false;
        return true;
    };
    int interiorCount = 0;
    for (int k = 0; k < size; ++k)
        interiorCount += interior(component_[k]);
    const double blockMm = options_.blockPx / pixelsPerMm_;
    const bool useInterior =
        interiorCount * blockMm * blockMm >= options_.fingerWidthMm * options_.fingerWidthMm / 4;

    // The component's pixels, at most about kMaxPixels of them (a sample of its blocks).
    constexpr int kMaxPixels = 800;
    const int blockPx = options_.blockPx;
    const int perBlock = blockPx * blockPx;
    const int used = useInterior ? interiorCount : size;
    const int blockStride = std::max(1, used * perBlock / kMaxPixels);
    sampleBlocks_.clear();
    elevation_.clearPixels();
    double idealSum = 0.0;
    int idealCount = 0;
    for (int k = 0, n = 0; k < size; ++k) {
        if (useInterior && !interior(component_[k]))
            continue;
        if (n++ % blockStride)
            continue;
        const int by = component_[k] / cols, bx = component_[k] % cols;
        const cv::Point origin(bx * blockPx, by * blockPx);
        sampleBlocks_.push_back(origin);
        for (int y = origin.y; y < origin.y + blockPx; ++y)
            for (int x = origin.x; x < origin.x + blockPx; ++x)
                elevation_.addPixel(subtraction, x, y);
        if (const float ideal = narrowIdeal_.at<float>(by, bx); !std::isnan(ideal)) {
            idealSum += ideal;
            ++idealCount;
        }
    }
    // Both searches below take the best of many tries (two dozen heights, two dozen shifts). Chance
    // correlations over the region, at the best of so many, stay below this many of their standard
    // deviations: neither a faint code over dark content nor the shading a moving hand leaves in S may
    // pass for the table by chance. Without it, one pair in a few dozen of a hand moving above the table
    // found a chance peak near the table's height, and the whole hand was lost for that pair.
    constexpr double kSearchSignificance = 4.0;
    const double chance = std::sqrt(2.0 / static_cast<double>(sampleBlocks_.size() * perBlock));
    const double searchLimit = kSearchSignificance * chance;
    // Heights a few millimetres apart: the table and a hand lie ten or more apart.
    const std::size_t stride = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::floor(0.5 * options_.minElevationMm / options_.elevation.stepMm)));
    elevation_.measurePixels(elevationEvidence_, stride);
    const HeightEstimate height = elevation_.estimate(elevationEvidence_);
    if (height.valid && height.heightMm < options_.minElevationMm && height.correlation >= searchLimit)
        return true;
    // A table the calibration puts a little off shows its code beside the predicted place: as a block, it
    // passes the table's test there (half the correlation the table reaches at that amplitude).
    if (idealCount == 0)
        return false;
    const double expected = fidelity_ * idealSum / idealCount;
    const CodeShiftMatch match =
        shiftedCode_.bestMatch(subtraction, sampleBlocks_, blockPx,
                               options_.misregistrationPx / tableCode_.projectorPixelsPerCameraPixel);
    if (match.correlation < searchLimit)
        return false;
    return match.correlation >= 0.5 * expected;
}

int HandSegmenter::floodComponent(int start, uchar from, uchar to) {
    const int rows = blockClass_.rows, cols = blockClass_.cols;
    uchar* classes = blockClass_.ptr<uchar>();
    int head = 0, tail = 0, size = 0;
    queue_[tail++] = start;
    classes[start] = to;
    while (head < tail) {
        const int i = queue_[head++];
        component_[size++] = i;
        const int y = i / cols, x = i % cols;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int ny = y + dy, nx = x + dx;
                if (ny < 0 || nx < 0 || ny >= rows || nx >= cols || classes[ny * cols + nx] != from)
                    continue;
                classes[ny * cols + nx] = to;
                queue_[tail++] = ny * cols + nx;
            }
    }
    return size;
}

void HandSegmenter::keepHandComponents(const cv::Mat& subtraction) {
    const int rows = blockClass_.rows, cols = blockClass_.cols;
    const double blockMm = options_.blockPx / pixelsPerMm_;
    const double fingerBlocks = options_.fingerWidthMm / blockMm;
    const int minBlocks = std::max(2, static_cast<int>(0.5 * fingerBlocks * fingerBlocks));
    queue_.resize(static_cast<std::size_t>(rows) * cols);
    component_.resize(static_cast<std::size_t>(rows) * cols);
    uchar* classes = blockClass_.ptr<uchar>();
    for (int start = 0; start < rows * cols; ++start) {
        if (classes[start] != Candidate)
            continue;
        const int size = floodComponent(start, Candidate, Hand);
        if (size < minBlocks || liesOnTable(subtraction, size))
            for (int k = 0; k < size; ++k)
                classes[component_[k]] = Unlit;
    }
}

inline const float* HandSegmenter::blockFeature(const cv::Mat& texture, int by, int bx) {
    const float* feature = blockColour_.ptr<cv::Vec3f>(by)[bx].val;
    return colourKnown_.ptr<uchar>(by)[bx] ? feature : measureBlockFeature(texture, by, bx);
}

const float* HandSegmenter::measureBlockFeature(const cv::Mat& texture, int by, int bx) {
    cv::Vec3f& feature = blockColour_.at<cv::Vec3f>(by, bx);
    const int blockPx = options_.blockPx, channels = texture.channels();
    // Each channel's sum in a local of its own: added through an array indexed by channel, every addition
    // went through memory.
    int blue = 0, green = 0, red = 0;
    for (int y = by * blockPx; y < (by + 1) * blockPx; ++y) {
        const uchar* row = texture.ptr<uchar>(y) + bx * blockPx * channels;
        if (channels == 3) {
            for (int x = 0; x < 3 * blockPx; x += 3) {
                blue += row[x];
                green += row[x + 1];
                red += row[x + 2];
            }
        } else {
            for (int x = 0; x < blockPx; ++x)
                blue += row[x];
        }
    }
    const float scale = 1.0f / static_cast<float>(blockPx * blockPx);
    const float colour[3] = {static_cast<float>(blue) * scale, static_cast<float>(green) * scale,
                             static_cast<float>(red) * scale};
    colourFeature(colour, channels, feature.val);
    colourKnown_.at<uchar>(by, bx) = 1;
    return feature.val;
}

template <typename IsSample>
float HandSegmenter::nearestTableColour(const cv::Mat& texture, int block, int reach, IsSample isSample) {
    float& nearest = tableDistance_[static_cast<std::size_t>(block)];
    if (nearest >= 0.0f)
        return nearest;
    const int rows = blockClass_.rows, cols = blockClass_.cols;
    const int y = block / cols, x = block % cols;
    const float* colour = blockFeature(texture, y, x);
    nearest = std::numeric_limits<float>::max();
    for (int ty = std::max(y - reach, 0); ty <= std::min(y + reach, rows - 1); ++ty)
        for (int tx = std::max(x - reach, 0); tx <= std::min(x + reach, cols - 1); ++tx)
            if (isSample(ty * cols + tx))
                nearest = std::min(nearest, featureDistanceSquared(colour, blockFeature(texture, ty, tx)));
    return nearest;
}

void HandSegmenter::measureUnlitTable(const cv::Mat& texture) {
    unlitTableMeasured_ = true;
    unlitTableKnown_ = false;
    // A gray camera sees no chromaticity, and the brightness of what the room alone lights says nothing.
    if (unlitWindows_.size() < kMinUnlitWindows || texture.channels() != 3)
        return;
    // The pixels of up to kMaxUnlitTableBlocks blocks beyond the projection, spread over them.
    const std::size_t stride = (unlitWindows_.size() + kMaxUnlitTableBlocks - 1) / kMaxUnlitTableBlocks;
    const int blockPx = options_.blockPx, cols = blockClass_.cols, channels = texture.channels();
    for (auto& component : unlitChromaticities_)
        component.clear();
    for (std::size_t k = 0; k < unlitWindows_.size(); k += stride) {
        const int by = unlitWindows_[k] / cols, bx = unlitWindows_[k] % cols;
        for (int y = by * blockPx; y < (by + 1) * blockPx; ++y) {
            const uchar* row = texture.ptr<uchar>(y);
            for (int x = bx * blockPx; x < (bx + 1) * blockPx; ++x) {
                float colour[3], feature[3];
                for (int ch = 0; ch < channels; ++ch)
                    colour[ch] = row[x * channels + ch];
                colourFeature(colour, channels, feature);
                for (std::size_t i = 0; i < unlitChromaticities_.size(); ++i)
                    unlitChromaticities_[i].push_back(feature[i]);
            }
        }
    }
    for (std::size_t i = 0; i < unlitChromaticities_.size(); ++i)
        unlitTableChromaticity_[i] = quantile(unlitChromaticities_[i], 0.5);
    // The spread of single pixels about it: the table's own variation and the camera's noise, which at low
    // light scatters the chromaticity widely. From the median distance, since an arm reaching in from
    // beyond the table's edge covers some of these pixels.
    values_.clear();
    for (std::size_t k = 0; k < unlitChromaticities_[0].size(); ++k) {
        const float chromaticity[2] = {unlitChromaticities_[0][k], unlitChromaticities_[1][k]};
        values_.push_back(chromaticityDistanceSquared(chromaticity, unlitTableChromaticity_));
    }
    unlitTableSpread_ = kUnlitTableSpreadPerMedian * quantile(values_, 0.5);
    unlitTableKnown_ = true;
}

void HandSegmenter::growIntoFaintBlocks(const cv::Mat& texture) {
    const int rows = blockClass_.rows, cols = blockClass_.cols;
    uchar* classes = blockClass_.ptr<uchar>();
    int head = 0, tail = 0;
    for (int i = 0; i < rows * cols; ++i)
        if (classes[i] == Hand)
            queue_[tail++] = i;
    // A hand over dark content or in another part's shadow shows no code: such blocks join the hand when
    // their colour is nearer the hand's next to them than the table's around them.
    constexpr int kTableReach = 3;
    std::fill(tableDistance_.begin(), tableDistance_.end(), -1.0f);
    while (head < tail) {
        const int i = queue_[head++];
        const int y = i / cols, x = i % cols;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int ny = y + dy, nx = x + dx;
                if (ny < 0 || nx < 0 || ny >= rows || nx >= cols || classes[ny * cols + nx] != Unlit)
                    continue;
                const int j = ny * cols + nx;
                const float* colour = blockFeature(texture, ny, nx);
                const float handDistance = featureDistanceSquared(colour, blockFeature(texture, y, x));
                const float tableDistance =
                    nearestTableColour(texture, j, kTableReach, [&](int k) { return classes[k] == Table; });
                if (handDistance < tableDistance) {
                    classes[j] = Grown;
                    queue_[tail++] = j;
                }
            }
    }
}

void HandSegmenter::growOverTouchingSkin(const cv::Mat& texture) {
    // The last millimetres of a touching finger lie too close to the table for the code to tell them from
    // it: their blocks show the table's code. They lie within half a finger's width of where the code sees
    // the finger, and their colour is the skin's: such blocks join the hand when their colour is clearly
    // nearer the hand's next to them than the table's beyond that reach (kTouchingColourRatio).
    const int rows = blockClass_.rows, cols = blockClass_.cols;
    uchar* classes = blockClass_.ptr<uchar>();
    const double blockMm = options_.blockPx / pixelsPerMm_;
    const int reach = std::max(1, static_cast<int>(std::lround(0.5 * options_.fingerWidthMm / blockMm)));
    // The table's colour is sampled beyond the reach, up to a finger's width further: a block inside a finger
    // that lies low (its whole length near the table on a slide) is that far from the table on either side.
    const int sampleReach = reach + 2 * reach;

    // Blocks to the nearest hand block, up to the farthest a table sample lies from the hand.
    constexpr int kFar = std::numeric_limits<int>::max();
    std::fill(blocksToHand_.begin(), blocksToHand_.end(), kFar);
    int head = 0, tail = 0;
    for (int i = 0; i < rows * cols; ++i)
        if (isHand(classes[i])) {
            blocksToHand_[i] = 0;
            queue_[tail++] = i;
        }
    if (tail == 0)
        return;
    const int handBlocks = tail;
    while (head < tail) {
        const int i = queue_[head++];
        if (blocksToHand_[i] >= reach + sampleReach)
            continue;
        const int y = i / cols, x = i % cols;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int ny = y + dy, nx = x + dx;
                if (ny < 0 || nx < 0 || ny >= rows || nx >= cols)
                    continue;
                const int j = ny * cols + nx;
                if (blocksToHand_[j] == kFar && classes[j] != Outside) {
                    blocksToHand_[j] = blocksToHand_[i] + 1;
                    queue_[tail++] = j;
                }
            }
    }

    std::fill(tableDistance_.begin(), tableDistance_.end(), -1.0f);
    head = 0;
    tail = handBlocks;  // the hand blocks are still at the queue's front
    while (head < tail) {
        const int i = queue_[head++];
        const int y = i / cols, x = i % cols;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int ny = y + dy, nx = x + dx;
                if (ny < 0 || nx < 0 || ny >= rows || nx >= cols)
                    continue;
                const int j = ny * cols + nx;
                if (classes[j] != Table || blocksToHand_[j] > reach)
                    continue;
                const float* colour = blockFeature(texture, ny, nx);
                const float handDistance = featureDistanceSquared(colour, blockFeature(texture, y, x));
                const float tableDistance = nearestTableColour(texture, j, sampleReach, [&](int k) {
                    return classes[k] == Table && blocksToHand_[k] > reach;
                });
                if (kTouchingColourRatio * handDistance < tableDistance &&
                    tableDistance < std::numeric_limits<float>::max()) {
                    classes[j] = Candidate;  // until the size of what grew is known
                    queue_[tail++] = j;
                }
            }
    }

    // A fingertip's end is no larger than a finger is wide, squared: more that looks like skin and shows the
    // table's code is content of the hand's colour lying beside it.
    const int mostBlocks =
        static_cast<int>(std::ceil(options_.fingerWidthMm * options_.fingerWidthMm / (blockMm * blockMm)));
    for (int start = 0; start < rows * cols; ++start) {
        if (classes[start] != Candidate)
            continue;
        const int size = floodComponent(start, Candidate, Touching);
        if (size > mostBlocks)
            for (int k = 0; k < size; ++k)
                classes[component_[k]] = Table;
    }
}

void HandSegmenter::findHandBox() {
    int top = blockClass_.rows, bottom = -1, left = blockClass_.cols, right = -1;
    for (int by = 0; by < blockClass_.rows; ++by) {
        const uchar* classes = blockClass_.ptr<uchar>(by);
        for (int bx = 0; bx < blockClass_.cols; ++bx)
            if (isHand(classes[bx])) {
                top = std::min(top, by);
                bottom = by;
                left = std::min(left, bx);
                right = std::max(right, bx);
            }
    }
    handBox_ = bottom < 0 ? cv::Rect() : cv::Rect(left, top, right - left + 1, bottom - top + 1);
}

void HandSegmenter::measureDepthInHand() {
    // The chessboard distance transform in two passes over the hand's box; beyond it lies no hand.
    const cv::Rect& handBox = handBox_;
    const int rows = blockClass_.rows, cols = blockClass_.cols;
    depthInHand_.create(blockClass_.size(), CV_8UC1);
    fill(depthInHand_, 0);
    const auto depthAt = [&](int y, int x) {
        return y < 0 || x < 0 || y >= rows || x >= cols ? 0 : int{depthInHand_.at<uchar>(y, x)};
    };
    for (int y = handBox.y; y < handBox.y + handBox.height; ++y)
        for (int x = handBox.x; x < handBox.x + handBox.width; ++x) {
            int depth = 0;
            if (isHand(blockClass_.at<uchar>(y, x)))
                depth = 1 + std::min({depthAt(y, x - 1), depthAt(y - 1, x - 1), depthAt(y - 1, x),
                                      depthAt(y - 1, x + 1)});
            depthInHand_.at<uchar>(y, x) = static_cast<uchar>(std::min(depth, 255));
        }
    for (int y = handBox.y + handBox.height - 1; y >= handBox.y; --y)
        for (int x = handBox.x + handBox.width - 1; x >= handBox.x; --x) {
            const int depth =
                std::min({int{depthInHand_.at<uchar>(y, x)}, 1 + depthAt(y, x + 1), 1 + depthAt(y + 1, x + 1),
                          1 + depthAt(y + 1, x), 1 + depthAt(y + 1, x - 1)});
            depthInHand_.at<uchar>(y, x) = static_cast<uchar>(depth);
        }
}

void HandSegmenter::labelPixels(const cv::Mat& texture, const cv::Mat& subtraction, cv::Mat& mask) {
    const int rows = blockClass_.rows, cols = blockClass_.cols, blockPx = options_.blockPx;
    const int channels = texture.channels();
    const auto classAt = [&](int y, int x) {
        return y < 0 || x < 0 || y >= rows || x >= cols ? uchar{Outside} : blockClass_.at<uchar>(y, x);
    };
    // A hand block is pure when the blocks within `depth` of it are hand too: its colour is then a clean
    // sample of the skin. Any other block is a sample of the other side: its window shows the table's code
    // or no code. A window reaching over the outline makes blocks up to a window's half beyond it look like
    // hand, so a clean sample of skin lies that far inside the region of hand blocks.
    const int depth = options_.windowBlocks / 2 + 1;
    if (handBox_.empty())
        return;
    constexpr int kLitReach = 1;  // the lit test averages S over 3 x 3 pixels
    const int motionLevel = static_cast<int>(std::ceil(kMotionAmplitudes * tableAmplitude_));
    const int litSum = static_cast<int>(std::ceil((2 * kLitReach + 1) * (2 * kLitReach + 1) * litAmplitude_));
    litPatch_.resize(static_cast<std::size_t>((blockPx + 2 * kLitReach) * (blockPx + 2 * kLitReach)));
    litColumns_.resize(static_cast<std::size_t>(blockPx + 2 * kLitReach));
    measureDepthInHand();
    const auto pure = [&](int y, int x) { return depthInHand_.at<uchar>(y, x) > depth; };
    const std::array<cv::Point, kColourSamples>& sampleOffsets = colourSampleOffsets();
    // Only the blocks next to the hand's are looked at.
    for (int by = std::max(handBox_.y - 1, 0); by <= std::min(handBox_.br().y, rows - 1); ++by)
        for (int bx = std::max(handBox_.x - 1, 0); bx <= std::min(handBox_.br().x, cols - 1); ++bx) {
            const uchar c = blockClass_.at<uchar>(by, bx);
            if (c == Outside)
                continue;
            bool nearHand = false;
            for (int dy = -1; dy <= 1 && !nearHand; ++dy)
                for (int dx = -1; dx <= 1 && !nearHand; ++dx)
                    nearHand = isHand(classAt(by + dy, bx + dx));
            if (!nearHand)
                continue;
            const cv::Rect block(bx * blockPx, by * blockPx, blockPx, blockPx);
            // Deep inside the hand every lit pixel is hand. The lit test below still applies there: the
            // shadow a finger high above the table casts beside itself (as wide as the code's parallax at its
            // height: 6 px at 35 mm) lies within the reach of windows that see the finger's code, and so do
            // its blocks.
            const bool inside = pure(by, bx);
            // On the outline: each pixel goes to the side whose nearby clean colour it resembles more.
            NearestColour hand, other, looseHand;
            for (int k = 0; k < kColourSamples && !inside; ++k) {
                const int y = by + sampleOffsets[k].y, x = bx + sampleOffsets[k].x;
                const uchar n = classAt(y, x);
                if (n == Outside)
                    continue;
                const float* colour = blockFeature(texture, y, x);
                if (isHand(n)) {
                    looseHand.add(colour);
                    if (pure(y, x))
                        hand.add(colour);
                } else {
                    other.add(colour);
                }
            }
            hand.finish();
            looseHand.finish();
            other.finish();
            const NearestColour& handSide = hand.empty() ? looseHand : hand;
            // A pixel in the hand's own shadow gets no light from the projector, and no code: whatever its
            // colour, it is not the hand (a hand over black content loses its outline pixels here too).
            // Beyond the brightest code the table shows, S is not code but the scene changing between the two
            // frames: a moving edge or a shadow sweeping over the table. It says nothing about light.
            const int side = blockPx + 2 * kLitReach;
            // Clamped to the image only where the patch reaches beyond it.
            const bool withinImage = block.x >= kLitReach && block.y >= kLitReach &&
                                     block.x + blockPx + kLitReach <= subtraction.cols &&
                                     block.y + blockPx + kLitReach <= subtraction.rows;
            for (int py = 0; py < side; ++py) {
                const short* s =
                    subtraction.ptr<short>(std::clamp(block.y - kLitReach + py, 0, subtraction.rows - 1));
                int* patch = litPatch_.data() + py * side;
                if (withinImage) {
                    const short* from = s + block.x - kLitReach;
                    for (int px = 0; px < side; ++px)
                        patch[px] = from[px] <= motionLevel ? from[px] : 0;
                    continue;
                }
                for (int px = 0; px < side; ++px) {
                    const int value = s[std::clamp(block.x - kLitReach + px, 0, subtraction.cols - 1)];
                    patch[px] = value <= motionLevel ? value : 0;
                }
            }
            // The side of the last pixel looked at: a pixel is searched for the nearest sample of the other
            // side first, then for any nearer one of its guessed side, which is found soon when the guess
            // holds. Either way the answer is the same: hand when its nearest sample is the hand's.
            bool lastWasHand = isHand(c);
            for (int py = 0; py < blockPx; ++py) {
                const int y = block.y + py;
                const uchar* row = texture.ptr<uchar>(y);
                uchar* out = mask.ptr<uchar>(y);
                int* columnSums = litColumns_.data();
                for (int px = 0; px < side; ++px) {
                    const int* patch = litPatch_.data() + py * side + px;
                    columnSums[px] = 0;
                    for (int dy = 0; dy <= 2 * kLitReach; ++dy)
                        columnSums[px] += patch[dy * side];
                }
                for (int px = 0; px < blockPx; ++px) {
                    const int x = block.x + px;
                    int localSum = 0;
                    for (int dx = 0; dx <= 2 * kLitReach; ++dx)
                        localSum += columnSums[px + dx];
                    // A pixel without projector light is hand only by the room's light (below), whichever way
                    // its block joined the hand: a faint block joined by its colour shows no code, and
                    // neither does the shadow beside the hand within it.
                    bool lit = localSum >= litSum;
                    if (!lit && (inside || c == Grown))
                        lit = (c == Grown && !roomLightKnown(texture)) ||
                              unlitHandAt(texture, subtraction, x, y, by, bx);
                    if (inside) {
                        out[x] = lit ? 255 : 0;
                        continue;
                    }
                    if (!lit) {
                        out[x] = 0;
                        continue;
                    }
                    float colour[3], pixel[3];
                    for (int ch = 0; ch < channels; ++ch)
                        colour[ch] = row[x * channels + ch];
                    colourFeature(colour, channels, pixel);
                    bool isHandPixel;
                    if (lastWasHand) {
                        isHandPixel = handSide.anyWithin(pixel, other.nearestDistance(pixel), true);
                    } else {
                        const float handDistance = handSide.nearestDistance(pixel);
                        isHandPixel = handDistance < std::numeric_limits<float>::max() &&
                                      !other.anyWithin(pixel, handDistance);
                    }
                    out[x] = isHandPixel ? 255 : 0;
                    lastWasHand = isHandPixel;
                }
            }
        }
}

bool HandSegmenter::unlitHandAt(const cv::Mat& texture, const cv::Mat& subtraction, int x, int y, int by,
                                int bx) {
    // No projector light: the table in the hand's shadow, or the hand over black content. Both are lit by
    // the room alone, as the table beyond the projection is, and the skin's chromaticity is its block's.
    if (!roomLightKnown(texture))
        return false;
    const int channels = texture.channels();
    const uchar* value = texture.ptr<uchar>(y) + x * channels;
    float colour[3], pixel[3];
    for (int ch = 0; ch < channels; ++ch)
        colour[ch] = value[ch];
    colourFeature(colour, channels, pixel);
    const float unlitTableDistance = chromaticityDistanceSquared(pixel, unlitTableChromaticity_);
    return unlitTableDistance > unlitTableSpread_ && stillAt(subtraction, x, y) &&
           kUnlitSkinRatio * chromaticityDistanceSquared(pixel, blockFeature(texture, by, bx)) <
               unlitTableDistance;
}

bool HandSegmenter::roomLightKnown(const cv::Mat& texture) {
    if (!unlitTableMeasured_)
        measureUnlitTable(texture);
    return unlitTableKnown_;
}

bool HandSegmenter::stillAt(const cv::Mat& subtraction, int x, int y) const {
    // Within three standard deviations of the noise about the level where nothing is lit, over 3 x 3
    // pixels: beyond it the scene changed between the two frames there.
    const float limit = kStillSigmas * std::sqrt(noiseVariance_);
    for (int py = std::max(y - 1, 0); py <= std::min(y + 1, subtraction.rows - 1); ++py) {
        const short* s = subtraction.ptr<short>(py);
        for (int px = std::max(x - 1, 0); px <= std::min(x + 1, subtraction.cols - 1); ++px)
            if (std::abs(s[px] - zeroLevel_) > limit)
                return false;
    }
    return true;
}

void HandSegmenter::segmentAsPaper(const cv::Mat& texture, cv::Mat& mask) {
    const cv::Mat* colour = &texture;
    if (texture.channels() == 1) {
        cv::cvtColor(texture, gray3_, cv::COLOR_GRAY2BGR);
        colour = &gray3_;
    }
    // The paper's camera frames the projection; ours sees the table around it too, so the method gets the
    // display's bounding box as its image.
    const cv::Rect whole = displayBox_.empty() ? cv::Rect(0, 0, texture.cols, texture.rows) : displayBox_;
    computeSaliency((*colour)(whole), cv::Rect(cv::Point(), whole.size()), options_.saliency,
                    saliencyScratch_, saliency_);
    // The salient region: Otsu's threshold on the saliency separates the few salient colours from the many
    // of the background; mean shift runs on their bounding box, widened by the spatial radius.
    cv::Mat saliency8;
    saliency_.convertTo(saliency8, CV_8U, 255.0);
    mask.create(texture.size(), CV_8UC1);
    mask.setTo(0);
    cv::Mat salient;
    cv::threshold(saliency8, salient, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
    cv::Rect roi = cv::boundingRect(salient);
    if (roi.empty())
        return;
    const int margin = options_.meanShift.spatialRadius;
    roi = cv::Rect(roi.x - margin, roi.y - margin, roi.width + 2 * margin, roi.height + 2 * margin) &
          cv::Rect(cv::Point(), whole.size());
    const cv::Rect inCamera = roi + whole.tl();
    const int count = segmentMeanShift((*colour)(inCamera), options_.meanShift, meanShiftScratch_, labels_);
    selectConfidentRegions(labels_, count, saliency_(roi), roi, whole.size(), options_.confidence,
                           confidenceScratch_, regionMask_);
    regionMask_.copyTo(mask(inCamera));
    if (options_.closingRadiusPx > 0) {
        const int side = 2 * options_.closingRadiusPx + 1;
        cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                         cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(side, side)));
    }
}

}  // namespace everytouch::core

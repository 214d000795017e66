#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/code_evidence.h"
#include "core/majority_filter.h"
#include "core/mean_shift_segmentation.h"
#include "core/saliency.h"
#include "core/segment_confidence.h"
#include "core/shifted_code_match.h"
#include "core/surface_height.h"
#include "core/table_code.h"

namespace everytouch::core {

enum class SegmentationMethod {
    // The embedded code first: where the projector's light shows the table's code, the camera sees the table;
    // where it lights something that does not show it, something stands above the table. Colours then place
    // the hand's outline to the pixel. Needs the calibration and the pattern.
    Code,
    // The paper's method as published (section VI.A): histogram-contrast saliency, mean-shift segmentation of
    // the salient region, the confidence fusion of eq. 12, morphological closing. Needs nothing but the
    // image.
    Paper,
};

const char* toString(SegmentationMethod method);
std::optional<SegmentationMethod> parseSegmentationMethod(const std::string& name);

struct SegmentationOptions {
    SegmentationMethod method = SegmentationMethod::Code;

    // The code's evidence is gathered over blocks of blockPx square pixels, each judged by the window of
    // windowBlocks x windowBlocks blocks around it: 12 x 12 pixels hold some 100 code bits on rigs where a
    // camera pixel sees about a projector pixel, enough to tell the table's code from another.
    int blockPx = 4;
    int windowBlocks = 3;
    // The camera's own blur (Gaussian sigma, camera pixels) on top of its pixels' footprint, for predicting
    // how it sees the table's code, until the rig's is measured (core/code_blur.h).
    double cameraBlurPx = 0.5;
    // A finger is this wide (mm); a region narrower than half a finger's area is noise, not a hand.
    double fingerWidthMm = 14.0;
    // Whatever of a hand the camera sees from above lies at least this high (mm): fingers are 10 mm thick
    // or more. A region whose code puts it lower is on the table: printed text or a stain that changed the
    // code's look, not a hand.
    double minElevationMm = 4.0;
    // The calibration may put the table's code this far (projector pixels) from where the table shows it
    // before the calibration's correction sets it right (core/calibration_correction.h): a camera turned by
    // 0.15 degrees moves it by up to about 2. A region whose code is the table's within that shift is the
    // table, not a hand; the code of a hand lies further, by parallax (2 projector pixels are 10 mm of height
    // on the default rig) and blurred by the skin.
    double misregistrationPx = 2.0;
    HeightOptions elevation;  // how the height of a region is measured
    // The outline's pixels are decided one by one; a majority vote over a square this many finger widths
    // wide then removes specks and notches narrower than a quarter of a finger (where the paper's method
    // closes), which the fingertip finder would take for the outline's shape.
    double smoothingWidths = 0.5;

    // The paper's method.
    SaliencyOptions saliency;
    MeanShiftOptions meanShift;    // (hs, hr, M) = (7, 10, 20)
    ConfidenceOptions confidence;  // threshold of eq. 12
    int closingRadiusPx = 2;       // the closing that fills small holes in the hand

    std::optional<std::string> validate() const;
};

// Separates the hand from the table, the projected content and the shadows in one frame pair (paper section
// VI.A). Stateful only for its buffers and the rig's precomputed code: it has no memory of earlier frames.
class HandSegmenter {
public:
    // Throws std::invalid_argument when options.validate() fails.
    explicit HandSegmenter(const SegmentationOptions& options);

    // The rig: its calibration and code (pattern CV_8UC1 0/1, projector size). The Code method needs it.
    // measuredCodeBlurPx: the blur the rig shows its code with beyond a pixel's footprint (CodeBlurMeter);
    // the table's code is predicted somewhat sharper than that. Nothing: options.cameraBlurPx.
    void setRig(const Calibration& calibration, const cv::Mat& pattern,
                std::optional<double> measuredCodeBlurPx = std::nullopt);
    bool hasRig() const { return !tableCode_.predicted.empty(); }
    // The table's code as the camera sees it, for the rig set.
    const TableCode& tableCode() const { return tableCode_; }

    // texture: T (CV_8UC3 or CV_8UC1), subtraction: S (CV_16SC1), camera size (core/code_image.h). mask:
    // receives CV_8UC1, 255 where the camera sees a hand. After the first frames of a size, the Code method
    // allocates nothing.
    void segment(const cv::Mat& texture, const cv::Mat& subtraction, cv::Mat& mask);

    // CV_8UC1, camera size: nonzero where the method decides hand or not (the display, less what a window at
    // its edge cannot judge); elsewhere the mask is 0 for want of a look, and its edge cuts hands as the
    // image's edge does. Empty before setRig.
    const cv::Mat& judgedRegion() const { return judgedRegion_; }

    // The display's bounding box in the camera: whatever the method decides lies within it. Empty before
    // setRig.
    const cv::Rect& displayBox() const { return displayBox_; }

    // Camera pixels per millimetre on the table near the image centre (from the calibration).
    double pixelsPerMm() const { return pixelsPerMm_; }

private:
    void segmentByCode(const cv::Mat& texture, const cv::Mat& subtraction, cv::Mat& mask);
    void segmentAsPaper(const cv::Mat& texture, cv::Mat& mask);
    // channels: the texture's, which set the level of S where nothing is lit.
    void classifyBlocks(int channels);
    // Relabels the 8-connected blocks of class `from` around `start` as `to`; component_ receives them.
    // Returns their number.
    int floodComponent(int start, uchar from, uchar to);
    void keepHandComponents(const cv::Mat& subtraction);
    // Whether the component (component_, `size` blocks) shows the table's code: at a height below
    // minElevationMm, or shifted by no more than misregistrationMm.
    bool liesOnTable(const cv::Mat& subtraction, int size);
    // A block's mean colour as colourFeature makes it, measured on first use in a frame: blockFeature is the
    // lookup, inlined where the outline's and the table's samples are read (some 57 000 times a pair with
    // one hand in view on grid35), measureBlockFeature the measurement.
    const float* blockFeature(const cv::Mat& texture, int by, int bx);
    const float* measureBlockFeature(const cv::Mat& texture, int by, int bx);
    // The squared colour distance from block `block` to the nearest block within `reach` that isSample(index)
    // takes as the table's, or the largest float without one: measured once per growth step (tableDistance_,
    // which the step clears), since a block beside several hand blocks is judged from each.
    template <typename IsSample>
    float nearestTableColour(const cv::Mat& texture, int block, int reach, IsSample isSample);
    // unlitTableChromaticity_ and unlitTableSpread_ receive the table's colour where only the room lights it,
    // from the view beyond the projection (unlitTableKnown_: there is one). Measured once per frame, when the
    // first unlit pixel of the hand's blocks asks for it.
    void measureUnlitTable(const cv::Mat& texture);
    // Whether the table's colour in the room's light alone is known (measured on first use in a pair): not
    // with a gray camera or without a view beyond the projection.
    bool roomLightKnown(const cv::Mat& texture);
    // Whether the pixel (x, y) of block (bx, by), which gets no projector light, is the hand's by its colour
    // in the room's light: deep inside the hand, or in a faint block joined to it by colour.
    bool unlitHandAt(const cv::Mat& texture, const cv::Mat& subtraction, int x, int y, int by, int bx);
    // Whether S around the pixel holds nothing but noise about the level where nothing is lit.
    bool stillAt(const cv::Mat& subtraction, int x, int y) const;
    void growIntoFaintBlocks(const cv::Mat& texture);
    void growOverTouchingSkin(const cv::Mat& texture);
    // handBox_ receives the box of the hand's blocks (empty without any).
    void findHandBox();
    // depthInHand_ receives each block's chessboard distance to the nearest block that is not hand (0 on
    // those, 1 on the hand's outline blocks), over handBox_.
    void measureDepthInHand();
    void labelPixels(const cv::Mat& texture, const cv::Mat& subtraction, cv::Mat& mask);

    SegmentationOptions options_;
    TableCode tableCode_;
    cv::Rect displayBox_;            // the display's bounding box in the camera
    cv::Mat displayBlocks_;          // CV_8UC1, block grid: 1 where the whole window lies on the display
    std::vector<int> unlitWindows_;  // blocks (row-major) whose whole window lies beyond the projection
    cv::Mat judgedRegion_;
    double pixelsPerMm_ = 1.0;
    float litAmplitude_ = 0.0f;
    float zeroLevel_ = 0.0f;       // S where nothing is lit (DN)
    float tableAmplitude_ = 0.0f;  // mean S on the table in the last frame
    float noiseVariance_ = 0.0f;   // of S where only noise is seen (DN^2)

    CodeEvidence evidence_;
    cv::Mat narrowIdeal_;  // CV_32FC1, block grid: the narrow window's ideal correlation (classifyBlocks)
    cv::Mat blockClass_;   // CV_8UC1, block grid
    cv::Mat blockColour_;  // CV_32FC3, block grid: mean texture colour as chromaticity and brightness
    cv::Mat colourKnown_;  // CV_8UC1, block grid: 1 where the colour has been measured this frame
    cv::Rect handBox_;     // block grid: the box of the hand's blocks (findHandBox)
    cv::Mat depthInHand_;  // CV_8UC1, block grid (measureDepthInHand)
    std::vector<int> litPatch_;    // S around one block, as labelPixels' lit test counts it
    std::vector<int> litColumns_;  // one row of litPatch_'s sums over the lit test's height
    std::vector<float> values_;
    std::vector<float> unlitVariances_;                      // of S in each window of unlitWindows_
    std::array<std::vector<float>, 2> unlitChromaticities_;  // of pixels beyond the projection
    bool unlitTableMeasured_ = false;                        // in this frame
    bool unlitTableKnown_ = false;
    float unlitTableChromaticity_[2] = {};  // the median of the pixels beyond the projection
    float unlitTableSpread_ = 0.0f;         // squared chromaticity distance from it that holds nearly all
    std::vector<int> queue_;
    std::vector<int> component_;
    std::vector<cv::Point> sampleBlocks_;  // the blocks of a component its tests read, top-left pixels
    ShiftedCodeMatcher shiftedCode_;
    float fidelity_ = 1.0f;  // the fraction of the ideal correlation the table reaches (classifyBlocks)
    std::vector<int> blocksToHand_;     // block grid: blocks to the nearest hand block (8-connected)
    std::vector<float> tableDistance_;  // block grid: nearestTableColour's, negative until measured
    MajorityScratch majorityScratch_;
    SurfaceHeight elevation_;
    HeightEvidence elevationEvidence_;

    cv::Mat gray3_;
    SaliencyScratch saliencyScratch_;
    cv::Mat saliency_;
    MeanShiftScratch meanShiftScratch_;
    cv::Mat labels_;
    ConfidenceScratch confidenceScratch_;
    cv::Mat regionMask_;
};

}  // namespace everytouch::core

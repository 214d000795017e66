// The code segmentation on rendered frames: what the code alone cannot tell, colour does.
#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "core/code_image.h"
#include "core/fingertips.h"
#include "core/geometry.h"
#include "core/hand_segmentation.h"
#include "sim/simulator.h"

namespace everytouch::core {
namespace {

struct DiskScore {
    long truth = 0, found = 0;  // hand pixels of the truth (near the pads), and how many the mask has
    long marked = 0;            // pixels the mask has (near the pads)
    double recall() const { return truth ? static_cast<double>(found) / truth : 0.0; }
    double precision() const { return marked ? static_cast<double>(found) / marked : 0.0; }
};

// Adds the pixels within `radiusPx` of `pad` (camera pixels) to `score`.
void addDisk(const cv::Mat& truthMask, const cv::Mat& mask, const Eigen::Vector2d& pad, double radiusPx,
             DiskScore& score) {
    const cv::Rect disk = cv::Rect(static_cast<int>(pad.x() - radiusPx), static_cast<int>(pad.y() - radiusPx),
                                   static_cast<int>(2 * radiusPx + 2), static_cast<int>(2 * radiusPx + 2)) &
                          cv::Rect(0, 0, mask.cols, mask.rows);
    for (int y = disk.y; y < disk.y + disk.height; ++y)
        for (int x = disk.x; x < disk.x + disk.width; ++x)
            if ((Eigen::Vector2d(x, y) - pad).norm() <= radiusPx) {
                const bool hand = truthMask.at<uchar>(y, x) != 0, marked = mask.at<uchar>(y, x) != 0;
                score.truth += hand;
                score.found += hand && marked;
                score.marked += marked;
            }
}

// Renders `samples` pairs spread over the scenario's cycle (consecutive samples start on frames of either
// polarity) and, where `wanted` accepts the newer frame's truth, segments them: visit(truth, mask).
template <typename Wanted, typename Visit>
void segmentSampledPairs(sim::Simulator& simulator, HandSegmenter& segmenter, int samples, Wanted wanted,
                         Visit visit) {
    Frame older, newer;
    sim::FrameTruth truth, olderTruth;
    cv::Mat subtraction, texture, mask;
    const double cycle = simulator.scenario().cycleSeconds();
    for (int i = 0; i < samples; ++i) {
        const auto index = static_cast<std::uint64_t>(cycle * i / samples * simulator.parameters().frameRate);
        simulator.render(index, older, olderTruth);
        simulator.render(index + 1, newer, truth);
        if (!wanted(truth))
            continue;
        const bool olderPositive = older.polarity == Polarity::Positive;
        computeSubtractionAndTexture(FramePair{olderPositive ? older : newer, olderPositive ? newer : older},
                                     subtraction, texture);
        segmenter.segment(texture, subtraction, mask);
        visit(truth, mask);
    }
}

// The hand's pixels within `radiusMm` of every touching pad, as the truth and the segmentation see them, over
// frames sampled across the scenario's cycle.
DiskScore scoreTouchingEnds(const std::string& scenario, const SegmentationOptions& options,
                            double radiusMm) {
    sim::SimParameters parameters;
    parameters.scenario = scenario;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    const Calibration& calibration = simulator.calibration();
    HandSegmenter segmenter(options);
    segmenter.setRig(calibration, simulator.pattern());
    const double radiusPx = radiusMm * segmenter.pixelsPerMm();
    const auto touching = [](const sim::FingertipTruth& finger) {
        return finger.presented && finger.touching;
    };

    DiskScore score;
    segmentSampledPairs(
        simulator, segmenter, 240,
        [&](const sim::FrameTruth& truth) {
            return std::any_of(truth.fingertips.begin(), truth.fingertips.end(), touching);
        },
        [&](const sim::FrameTruth& truth, const cv::Mat& mask) {
            for (const sim::FingertipTruth& finger : truth.fingertips)
                if (touching(finger))
                    addDisk(truth.handMask, mask,
                            projectPoint(calibration.cameraMatrix, calibration.tableToCamera, finger.pad),
                            radiusPx, score);
        });
    return score;
}

// Adds one pair's hand pixels where the segmentation decides (the display less a window's half at its
// edge) to `score`.
void addJudgedRegion(const cv::Mat& truthMask, const cv::Mat& mask, const cv::Mat& judged, DiskScore& score) {
    cv::Mat judgedTruth, found;
    cv::bitwise_and(truthMask, judged, judgedTruth);
    cv::bitwise_and(judgedTruth, mask, found);
    score.truth += cv::countNonZero(judgedTruth);
    score.marked += cv::countNonZero(mask);
    score.found += cv::countNonZero(found);
}

// The hand's pixels where the segmentation decides, over `samples` pairs spread across the scenario's cycle.
DiskScore scoreJudgedRegion(const sim::SimParameters& parameters, int samples) {
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    HandSegmenter segmenter(SegmentationOptions{});
    segmenter.setRig(simulator.calibration(), simulator.pattern());
    DiskScore score;
    segmentSampledPairs(
        simulator, segmenter, samples, [](const sim::FrameTruth&) { return true; },
        [&](const sim::FrameTruth& truth, const cv::Mat& mask) {
            addJudgedRegion(truth.handMask, mask, segmenter.judgedRegion(), score);
        });
    return score;
}

TEST(HandSegmentation, TouchingFingertipsKeepTheirEnds) {
    // The last millimetres of a touching finger show the table's code; their skin colour keeps them in the
    // hand, and with them the pad the touch is reported at.
    const DiskScore score = scoreTouchingEnds("grid35", SegmentationOptions{}, 6.0);
    ASSERT_GT(score.truth, 1000) << "the test needs touching fingers in view";
    // By the code alone 0.55 of them; 0.80 as measured with colour asked.
    EXPECT_GE(score.recall(), 0.75) << score.found << " of " << score.truth << " pixels";
}

TEST(HandSegmentation, AFingerSlidingFlatOnTheTableKeepsItsWidth) {
    // A sliding finger lies low along its whole last phalanx, whose blocks then show the table's code well
    // inside the finger, where the table beyond the reach lies up to a finger's width away: their colour
    // still keeps them.
    const DiskScore score = scoreTouchingEnds("drag", SegmentationOptions{}, 15.0);
    ASSERT_GT(score.truth, 10000) << "the test needs a sliding finger in view";
    // 0.84 when the table's colour was sampled only just beyond the reach (none found inside such a finger);
    // 0.91 then, and 0.88 since pixels deep inside the hand also need projector light, as measured: a
    // sliding finger's edges, where the two frames differ, count as unlit.
    EXPECT_GE(score.recall(), 0.86) << score.found << " of " << score.truth << " pixels";
}

TEST(HandSegmentation, AFingerPassingHighIsFoundInEveryPair) {
    // A finger passing high above the table casts the projector's shadow beside itself, as wide as the code's
    // parallax at that height, and sweeps it over the table between the two frames of a pair. The blocks
    // there see the finger's code in their windows, but the pixels get no projector light: kept, they widened
    // the silhouette beyond a finger's width, and the fingertip was lost in every other pair or so.
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    const Calibration& calibration = simulator.calibration();
    HandSegmenter segmenter(SegmentationOptions{});
    segmenter.setRig(calibration, simulator.pattern());
    const FingertipOptions fingertipOptions = rigFingertipOptions(calibration);
    const double radiusPx = 16.0 * segmenter.pixelsPerMm();
    FingertipScratch scratch;
    Fingertips fingertips;

    int presented = 0, found = 0;
    DiskScore score;
    segmentSampledPairs(
        simulator, segmenter, 480, [](const sim::FrameTruth&) { return true; },
        [&](const sim::FrameTruth& truth, const cv::Mat& mask) {
            findFingertips(mask, fingertipOptions, scratch, fingertips, segmenter.judgedRegion());
            for (const sim::FingertipTruth& finger : truth.fingertips) {
                if (!finger.presented || finger.heightMm < 25.0)
                    continue;
                const Eigen::Vector2d pad =
                    projectPoint(calibration.cameraMatrix, calibration.tableToCamera, finger.pad);
                // A finger entering over the display's edge shows its end alone: it counts once its last
                // joint is over the display.
                bool wellInside = true;
                for (int k = 0; k < 8; ++k) {
                    const double angle = k * M_PI / 4, reach = 2.0 * fingertipOptions.fingerWidthPx;
                    const cv::Point pixel(static_cast<int>(pad.x() + reach * std::cos(angle)),
                                          static_cast<int>(pad.y() + reach * std::sin(angle)));
                    wellInside = wellInside && cv::Rect(0, 0, mask.cols, mask.rows).contains(pixel) &&
                                 segmenter.judgedRegion().at<uchar>(pixel);
                }
                if (!wellInside)
                    continue;
                ++presented;
                found += std::any_of(fingertips.begin(), fingertips.end(), [&](const Fingertip& tip) {
                    return (tip.pad - pad).norm() <= fingertipOptions.fingerWidthPx;
                });
                addDisk(truth.handMask, mask, pad, radiusPx, score);
            }
        });
    ASSERT_GT(presented, 100) << "the test needs fingers passing high over the display";
    // 101 of 118 and a precision of 0.93 within 16 mm of the pads when only the outline's pixels needed
    // projector light; 109 and 0.96 as measured. The recall there fell from 0.92 to 0.83: a moving finger's
    // edges, where the two frames differ, are taken for unlit too.
    EXPECT_GE(found, 0.9 * presented) << found << " of " << presented << " fingers found";
    EXPECT_GE(score.precision(), 0.95) << score.found << " of " << score.marked << " pixels marked";
}

TEST(HandSegmentation, ACameraFramedOnTheProjectionStillTellsTheTableFromTheHand) {
    // A camera zoomed in on the projection sees nothing beyond it, where the noise of S is measured. The
    // blocks at the image's edge, whose windows the edge cuts short, are no view beyond it: taken for one,
    // they set the noise at 19 DN^2 instead of 1.4 and the expected correlations so low that a band of
    // table along the image's top became hand: precision 0.62 and recall 0.48 here then, 0.95 and 0.85 as
    // measured.
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    parameters.cameraFocalMm = 9.0;  // the display fills the frame and reaches beyond it
    const DiskScore score = scoreJudgedRegion(parameters, 60);
    ASSERT_GT(score.truth, 100000) << "the test needs a hand in view";
    EXPECT_GE(score.precision(), 0.92) << score.found << " of " << score.marked << " pixels marked";
    EXPECT_GE(score.recall(), 0.8) << score.found << " of " << score.truth << " hand pixels";
}

TEST(HandSegmentation, AHandOverDarkContentIsToldFromItsShadowByTheRoomsLight) {
    // Where the content is near black, the projector lights neither the table nor the hand, and the code
    // shows nothing of either. The table in the hand's shadow looks like the table beyond the projection,
    // which the room alone lights too; the hand over the dark content does not. Without projector light
    // every pixel was taken for shadow: a recall of 0.72 here then (precision 0.89), 0.78 with the rule
    // (precision 0.88), 0.77 (precision 0.90) as measured since the pixels of faint blocks joined to the hand
    // by colour need light too (ANoisyCameraKeepsTheShadowBesideTheHandOut). Deep inside the hand only: on
    // its outline as well it was 0.89 (0.87), but the fingers' silhouettes widened, which moved their heights
    // (docs/detection.md, step 5).
    sim::SimParameters parameters;
    parameters.scenario = "multitouch";
    const DiskScore score = scoreJudgedRegion(parameters, 60);
    ASSERT_GT(score.truth, 100000) << "the test needs a hand in view";
    EXPECT_GE(score.recall(), 0.76) << score.found << " of " << score.truth << " hand pixels";
    EXPECT_GE(score.precision(), 0.86) << score.found << " of " << score.marked << " pixels marked";
}

TEST(HandSegmentation, ANoisyCameraKeepsTheShadowBesideTheHandOut) {
    // Faint blocks beside the hand join it by their colour; the shadow the hand casts beside itself is such
    // a block, and with a noisier camera (6 dB of gain: half the light's electrons for the same levels) more
    // of them join. Their pixels need the projector's light, or the room's light on skin, like any other
    // pixel of the hand's blocks: when every pixel of such a block counted as lit, the precision here was
    // 0.943 (recall 0.894); 0.958 as measured (recall 0.885).
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    parameters.gainDb = 6.0;
    const DiskScore score = scoreJudgedRegion(parameters, 60);
    ASSERT_GT(score.truth, 100000) << "the test needs a hand in view";
    EXPECT_GE(score.precision(), 0.95) << score.found << " of " << score.marked << " pixels marked";
    EXPECT_GE(score.recall(), 0.87) << score.found << " of " << score.truth << " hand pixels";
}

TEST(HandSegmentation, AHandMovingAboveTheTableIsNotTakenForItByAChancePeak) {
    // A hand moving above the table leaves its shading in S. Whether a region lies on the table is asked of
    // the best of two dozen heights, and in this pair of grid35 (the hand on its way between two circles,
    // the finger 35 mm up) the best was 2 mm, at 3.2 standard deviations of chance: the whole hand was taken
    // for the table and lost. Such a search must clear the same 4 deviations as the search over shifts.
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    HandSegmenter segmenter(SegmentationOptions{});
    segmenter.setRig(simulator.calibration(), simulator.pattern());
    FramePair pair;
    sim::FrameTruth truth;
    simulator.render(800, pair.positive, truth);
    simulator.render(801, pair.negative, truth);
    ASSERT_EQ(pair.positive.polarity, Polarity::Positive);
    cv::Mat subtraction, texture, mask;
    computeSubtractionAndTexture(pair, subtraction, texture);
    segmenter.segment(texture, subtraction, mask);
    DiskScore score;
    addJudgedRegion(truth.handMask, mask, segmenter.judgedRegion(), score);
    ASSERT_GT(score.truth, 10000) << "the test needs a hand over the display";
    // None of its pixels were found before; 0.97 of them as measured.
    EXPECT_GE(score.recall(), 0.8) << score.found << " of " << score.truth << " hand pixels";
}

// The fraction of the judged region a segmenter marks as hand on an empty table, in the median of pairs
// sampled across the idle scenario's content, when the camera was turned by `knockDeg` after the
// calibration.
double markedOnAKnockedEmptyTable(const SegmentationOptions& options, double knockDeg) {
    sim::SimParameters parameters;
    parameters.scenario = "idle";
    parameters.knockS = 0.0;
    parameters.knockDeg = knockDeg;
    parameters.knockMm = 0.0;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    HandSegmenter segmenter(options);
    segmenter.setRig(simulator.calibration(), simulator.pattern());
    const double judged = cv::countNonZero(segmenter.judgedRegion());
    std::vector<double> marked;
    segmentSampledPairs(
        simulator, segmenter, 24, [](const sim::FrameTruth&) { return true; },
        [&](const sim::FrameTruth&, const cv::Mat& mask) {
            marked.push_back(cv::countNonZero(mask) / judged);
        });
    std::nth_element(marked.begin(), marked.begin() + marked.size() / 2, marked.end());
    return marked[marked.size() / 2];
}

TEST(HandSegmentation, AnEmptyTableTheCalibrationPutsALittleOffStaysTable) {
    // Turned by 0.15 degrees, the camera sees the table's code up to about 2 px (1.2 projector px) from where
    // the calibration predicts it, and block by block it fails the table's test: whole regions of table
    // became hand, read at no height, and the daemon reported a thousand touching frames a minute on it.
    SegmentationOptions exact;
    exact.misregistrationPx = 0.0;
    ASSERT_GT(markedOnAKnockedEmptyTable(exact, 0.15), 0.1) << "the test needs a calibration that is off";
    // 1.0 % as measured, against 15 % sought without a shift (0.4 % on the table before the knock: specks
    // below a finger's size, content changing within a pair).
    EXPECT_LT(markedOnAKnockedEmptyTable(SegmentationOptions{}, 0.15), 0.03);
}

}  // namespace
}  // namespace everytouch::core

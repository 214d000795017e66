#include "eval/segmentation_evaluation.h"

#include <chrono>

#include <opencv2/core.hpp>

#include "eval/display_region.h"
#include "eval/recording_pairs.h"

namespace everytouch::eval {

namespace {

void scoreFingertips(const PairWithTruth& pair, const cv::Mat& mask, const cv::Mat& judged,
                     const FingertipFinder& findFingertips, std::vector<Eigen::Vector2d>& tips,
                     FingertipScore& score) {
    findFingertips(mask, judged, tips);
    score.add(pair.fingers.size(), tips.size(), matchFingertips(pair.fingers, tips));
}

}  // namespace

SegmentationReport evaluateSegmentation(const io::Recording& recording, const std::string& recordingName,
                                        const std::vector<SegmentationMethod>& methods,
                                        const FingertipFinder& findFingertips,
                                        const TruthToCamera& truthToCamera, double fingerWidthMm) {
    SegmentationReport report;
    report.recording = recordingName;
    report.cameraSize = recording.rig().calibration.cameraSize;
    report.fingertipTruth = recording.hasTruth();
    report.fingerWidthMm = fingerWidthMm;
    report.fingerWidthPx = truthToCamera.fingerWidthPxAtCentre();
    for (const SegmentationMethod& method : methods)
        report.methods.push_back({method.name, method.description, method.unavailable, {}, {}, {}, 0.0});
    const cv::Mat display = displayRegion(recording.rig().calibration);

    RecordingPairs pairs(recording, truthToCamera);
    PairWithTruth pair;
    cv::Mat mask;
    std::vector<Eigen::Vector2d> tips;
    while (pairs.next(pair)) {
        ++report.pairs;
        report.channels = pair.texture.channels();
        if (cv::countNonZero(pair.truthMask) > 0) {
            ++report.pairsWithHand;
            report.handPositions.push_back(pair.position);
        }
        if (cv::countNonZero(pair.truthMask & display) > 0)
            ++report.pairsWithHandOnDisplay;
        if (report.fingertipTruth)
            scoreFingertips(pair, pair.truthMask, cv::Mat(), findFingertips, tips,
                            report.truthMaskFingertips);
        for (std::size_t m = 0; m < methods.size(); ++m) {
            if (methods[m].unavailable)
                continue;
            MethodResult& result = report.methods[m];
            const auto start = std::chrono::steady_clock::now();
            methods[m].segment({pair.texture, pair.subtraction, pair.pair}, mask);
            result.secondsSegmenting +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            CV_Assert(mask.type() == CV_8UC1 && mask.size() == pair.truthMask.size());
            result.pixels.add(countPixels(mask, pair.truthMask));
            result.displayPixels.add(countPixels(mask, pair.truthMask, display));
            if (report.fingertipTruth)
                scoreFingertips(pair, mask, methods[m].judged, findFingertips, tips, result.fingertips);
        }
    }
    return report;
}

}  // namespace everytouch::eval

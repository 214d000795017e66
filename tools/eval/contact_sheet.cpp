#include "eval/contact_sheet.h"

#include <cstdio>
#include <string>

#include <opencv2/imgproc.hpp>

#include "eval/recording_pairs.h"
#include "eval/segmentation_metrics.h"

namespace everytouch::eval {

namespace {

constexpr int kHeaderPx = 28;
constexpr int kGapPx = 4;
const cv::Scalar kTextColour(255, 255, 255);
const cv::Scalar kPrecisionColour(0, 255, 255);  // yellow, as in Fig. 13
const cv::Scalar kRecallColour(0, 255, 0);       // green, as in Fig. 13
const cv::Scalar kTruthColour(0, 255, 255);
const cv::Scalar kTipColour(0, 255, 0);
const cv::Vec3b kBoth(255, 255, 255);
const cv::Vec3b kMarkedOnly(0, 0, 255);
const cv::Vec3b kMissed(255, 96, 0);

void putLabel(cv::Mat& image, const std::string& text, cv::Point at, const cv::Scalar& colour) {
    cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
}

std::string twoDecimals(const std::optional<double>& value) {
    if (!value)
        return "-";
    char text[16];
    std::snprintf(text, sizeof text, "%.2f", *value);
    return text;
}

cv::Mat errorImage(const cv::Mat& mask, const cv::Mat& truth) {
    cv::Mat image(mask.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x) {
            const bool marked = mask.at<uchar>(y, x) != 0, hand = truth.at<uchar>(y, x) != 0;
            if (marked && hand)
                image.at<cv::Vec3b>(y, x) = kBoth;
            else if (marked)
                image.at<cv::Vec3b>(y, x) = kMarkedOnly;
            else if (hand)
                image.at<cv::Vec3b>(y, x) = kMissed;
        }
    return image;
}

// Scales `image` into the sheet's cell at (row, column) and returns the cell for drawing on.
cv::Mat placeCell(cv::Mat& sheet, const cv::Mat& image, int row, int column, cv::Size cell) {
    const cv::Rect where(column * (cell.width + kGapPx), kHeaderPx + row * (cell.height + kGapPx), cell.width,
                         cell.height);
    cv::Mat target = sheet(where);
    cv::Mat bgr;
    if (image.channels() == 1)
        cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
    else
        bgr = image;
    cv::resize(bgr, target, cell, 0, 0, cv::INTER_AREA);
    return target;
}

void drawTruth(cv::Mat& cell, const std::vector<TruthPoint>& fingers, double scale) {
    for (const TruthPoint& finger : fingers)
        cv::circle(cell, cv::Point2d(finger.camera.x() * scale, finger.camera.y() * scale),
                   std::max(2, cvRound(finger.fingerWidthPx * scale)), kTruthColour, 1, cv::LINE_AA);
}

void drawTips(cv::Mat& cell, const std::vector<Eigen::Vector2d>& tips, double scale) {
    for (const Eigen::Vector2d& tip : tips)
        cv::drawMarker(cell, cv::Point2d(tip.x() * scale, tip.y() * scale), kTipColour, cv::MARKER_CROSS, 9,
                       2);
}

}  // namespace

std::optional<std::string> ContactSheetOptions::validate() const {
    if (rows < 1)
        return "rows: at least one";
    if (!(scale > 0.0 && scale <= 1.0))
        return "scale: must be in (0, 1]";
    return std::nullopt;
}

cv::Mat renderContactSheet(const io::Recording& recording, const std::vector<std::size_t>& positions,
                           const std::vector<SegmentationMethod>& methods,
                           const FingertipFinder& findFingertips, const TruthToCamera& truthToCamera,
                           const ContactSheetOptions& options) {
    std::vector<std::size_t> rows;
    const int count = std::min<int>(options.rows, static_cast<int>(positions.size()));
    for (int row = 0; row < count; ++row)
        rows.push_back(positions[(2 * row + 1) * positions.size() / (2 * count)]);

    const cv::Size camera = recording.rig().calibration.cameraSize;
    const cv::Size cell(cvRound(camera.width * options.scale), cvRound(camera.height * options.scale));
    std::vector<std::string> titles{"texture T", "truth"};
    for (const SegmentationMethod& method : methods)
        if (!method.unavailable)
            titles.push_back(method.name);
    const int columns = static_cast<int>(titles.size());
    cv::Mat sheet(kHeaderPx + std::max(1, count) * (cell.height + kGapPx), columns * (cell.width + kGapPx),
                  CV_8UC3, cv::Scalar(48, 48, 48));
    for (int column = 0; column < columns; ++column)
        putLabel(sheet, titles[column], cv::Point(column * (cell.width + kGapPx) + 6, kHeaderPx - 9),
                 kTextColour);

    const RecordingPairs pairs(recording, truthToCamera);
    PairWithTruth pair;
    cv::Mat mask;
    std::vector<Eigen::Vector2d> tips;
    for (int row = 0; row < count; ++row) {
        if (!pairs.at(rows[row], pair))
            continue;
        cv::Mat texture = placeCell(sheet, pair.texture, row, 0, cell);
        drawTruth(texture, pair.fingers, options.scale);
        putLabel(texture, "frame " + std::to_string(pair.pair.latest().index), cv::Point(6, 18), kTextColour);

        cv::Mat truth = placeCell(sheet, pair.truthMask, row, 1, cell);
        findFingertips(pair.truthMask, cv::Mat(), tips);
        drawTips(truth, tips, options.scale);
        drawTruth(truth, pair.fingers, options.scale);

        int column = 2;
        for (const SegmentationMethod& method : methods) {
            if (method.unavailable)
                continue;
            method.segment({pair.texture, pair.subtraction, pair.pair}, mask);
            cv::Mat target = placeCell(sheet, errorImage(mask, pair.truthMask), row, column++, cell);
            findFingertips(mask, method.judged, tips);
            drawTips(target, tips, options.scale);
            drawTruth(target, pair.fingers, options.scale);
            const PixelCounts counts = countPixels(mask, pair.truthMask);
            putLabel(target, "p " + twoDecimals(counts.precision()), cv::Point(6, 18), kPrecisionColour);
            putLabel(target, "r " + twoDecimals(counts.recall()), cv::Point(cell.width - 62, 18),
                     kRecallColour);
        }
    }
    return sheet;
}

}  // namespace everytouch::eval

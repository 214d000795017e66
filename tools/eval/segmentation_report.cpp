#include "eval/segmentation_report.h"

#include <cstdio>
#include <optional>

#include "eval/optional_json.h"

namespace everytouch::eval {

namespace {

nlohmann::json scoreJson(const SegmentationScore& score) {
    const PixelCounts& total = score.total();
    return {{"precision", orNull(total.precision())},
            {"recall", orNull(total.recall())},
            {"f_beta", orNull(total.fBeta())},
            {"pixels",
             {{"true_positive", total.truePositive},
              {"false_positive", total.falsePositive},
              {"false_negative", total.falseNegative}}},
            {"per_pair_mean",
             {{"precision", orNull(score.meanPrecision())},
              {"recall", orNull(score.meanRecall())},
              {"f_beta", orNull(score.meanFBeta())},
              {"pairs", score.pairsWithHand()}}}};
}

nlohmann::json fingertipJson(const FingertipScore& score) {
    return {{"truth_fingers", score.truth()},
            {"detections", score.detections()},
            {"matched", score.matched()},
            {"detection_rate", orNull(score.detectionRate())},
            {"mean_error_px", orNull(score.meanErrorPx())},
            {"unmatched_per_pair", orNull(score.unmatchedPerPair())}};
}

std::string number(const std::optional<double>& value, const char* format = "%.3f") {
    if (!value)
        return "-";
    char text[32];
    std::snprintf(text, sizeof text, format, *value);
    return text;
}

template <typename... Arguments>
void appendf(std::string& out, const char* format, Arguments... arguments) {
    char line[512];
    std::snprintf(line, sizeof line, format, arguments...);
    out += line;
}

void appendScore(std::string& out, const SegmentationScore& score) {
    const PixelCounts& total = score.total();
    appendf(out, " %9s %6s %6s %6s |", number(total.precision()).c_str(), number(total.recall()).c_str(),
            number(total.fBeta()).c_str(), number(score.meanFBeta()).c_str());
}

void appendFingertips(std::string& out, const FingertipScore& score) {
    char found[32];
    std::snprintf(found, sizeof found, "%lld/%lld", static_cast<long long>(score.matched()),
                  static_cast<long long>(score.truth()));
    appendf(out, " %11s %5s %6s %5s |", found, number(score.detectionRate(), "%.2f").c_str(),
            number(score.meanErrorPx(), "%.1f").c_str(), number(score.unmatchedPerPair(), "%.2f").c_str());
}

double msPerPair(const SegmentationReport& report, const MethodResult& method) {
    return report.pairs > 0 ? 1e3 * method.secondsSegmenting / report.pairs : 0.0;
}

}  // namespace

nlohmann::json segmentationJson(const SegmentationReport& report) {
    nlohmann::json methods = nlohmann::json::array();
    for (const MethodResult& method : report.methods) {
        nlohmann::json entry = {{"name", method.name}, {"description", method.description}};
        if (method.unavailable) {
            entry["available"] = false;
            entry["unavailable"] = *method.unavailable;
            methods.push_back(entry);
            continue;
        }
        entry["available"] = true;
        entry.update(scoreJson(method.pixels));
        entry["within_display"] = scoreJson(method.displayPixels);
        if (report.fingertipTruth)
            entry["fingertips"] = fingertipJson(method.fingertips);
        entry["ms_per_pair"] = msPerPair(report, method);
        methods.push_back(entry);
    }
    nlohmann::json json = {
        {"recording", report.recording},
        {"camera_size", {report.cameraSize.width, report.cameraSize.height}},
        {"channels", report.channels},
        {"pairs", report.pairs},
        {"pairs_with_hand", report.pairsWithHand},
        {"pairs_with_hand_on_display", report.pairsWithHandOnDisplay},
        {"beta_squared", kBetaSquared},
        {"averaging",
         "precision, recall, f_beta: pixel counts summed over all pairs (micro average); per_pair_mean: "
         "averaged over the pairs with a hand in the truth"},
        {"methods", methods},
    };
    if (report.fingertipTruth)
        json["fingertips"] = {{"finger_width_mm", report.fingerWidthMm},
                              {"finger_width_px_at_display_centre", report.fingerWidthPx},
                              {"match_radius", "one finger width at the truth point"},
                              {"on_truth_masks", fingertipJson(report.truthMaskFingertips)}};
    return json;
}

std::string segmentationTable(const SegmentationReport& report) {
    std::string out;
    appendf(out, "%s: %d pairs, %d with a hand in the truth (%d on the display); camera %dx%d, %s\n",
            report.recording.c_str(), report.pairs, report.pairsWithHand, report.pairsWithHandOnDisplay,
            report.cameraSize.width, report.cameraSize.height, report.channels == 3 ? "colour" : "gray");
    appendf(
        out,
        "P, R, F: pixels summed over all pairs (micro average), F_beta with beta^2 = %.1f (paper eq. 23); "
        "mean F: per pair, over the pairs with a hand.\n",
        kBetaSquared);
    if (report.fingertipTruth)
        appendf(out,
                "Fingertips: found on each mask, matched one to one to truth.csv's fingers within a finger's "
                "width (%.0f mm, %.1f px at the display centre); found/truth, rate, mean error in camera px, "
                "extra detections per pair.\n",
                report.fingerWidthMm, report.fingerWidthPx);
    appendf(out, "\n%-8s|%-32s|%-32s|", "", " whole frame", " within the display");
    if (report.fingertipTruth)
        appendf(out, "%-32s|", " fingertips");
    appendf(out, "\n%-8s|", "method");
    for (int region = 0; region < 2; ++region)
        appendf(out, " %9s %6s %6s %6s |", "precision", "recall", "F", "mean F");
    if (report.fingertipTruth)
        appendf(out, " %11s %5s %6s %5s |", "found", "rate", "err px", "extra");
    out += " ms/pair\n";
    for (const MethodResult& method : report.methods) {
        if (method.unavailable) {
            appendf(out, "%-8s| not run: %s\n", method.name.c_str(), method.unavailable->c_str());
            continue;
        }
        appendf(out, "%-8s|", method.name.c_str());
        appendScore(out, method.pixels);
        appendScore(out, method.displayPixels);
        if (report.fingertipTruth)
            appendFingertips(out, method.fingertips);
        appendf(out, " %7.1f\n", msPerPair(report, method));
    }
    if (report.fingertipTruth) {
        appendf(out, "%-8s| %-64s|", "truth", "(the fingertip finder on the truth masks)");
        appendFingertips(out, report.truthMaskFingertips);
        out += "\n";
    }
    out += "\n";
    for (const MethodResult& method : report.methods)
        appendf(out, "%s: %s\n", method.name.c_str(), method.description.c_str());
    return out;
}

}  // namespace everytouch::eval

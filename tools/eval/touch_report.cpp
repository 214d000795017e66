#include "eval/touch_report.h"

#include <algorithm>
#include <cstdio>

#include "eval/optional_json.h"

namespace everytouch::eval {

namespace {

nlohmann::json meanJson(const Mean& mean) {
    return {{"mean", orNull(mean.value())}, {"count", mean.count}};
}

std::string fixed(const std::optional<double>& value, int decimals) {
    if (!value)
        return "-";
    char text[32];
    std::snprintf(text, sizeof text, "%.*f", decimals, *value);
    return text;
}

std::string line(const char* label, const std::string& value, const std::string& note) {
    char text[256];
    std::snprintf(text, sizeof text, "%-34s %10s", label, value.c_str());
    return std::string(text) + (note.empty() ? "" : "  " + note) + "\n";
}

}  // namespace

nlohmann::json touchJson(const TouchSource& source, const TouchScore& score) {
    nlohmann::json bands = nlohmann::json::array();
    for (std::size_t b = 0; b < kHoverBandsMm.size(); ++b)
        bands.push_back({{"from_mm", kHoverBandsMm[b][0]},
                         {"to_mm", kHoverBandsMm[b][1]},
                         {"mean", orNull(score.hoverBandErrorMm[b].value())},
                         {"count", score.hoverBandErrorMm[b].count},
                         {"finger_frames", score.hoverBandFrames[b]}});
    nlohmann::json trials = nlohmann::json::array();
    for (const TrialOutcome& outcome : score.trials) {
        nlohmann::json trial = {{"finger", outcome.trial.finger},   {"first", outcome.trial.first},
                                {"last", outcome.trial.last},       {"truth_x", outcome.truthDown.x()},
                                {"truth_y", outcome.truthDown.y()}, {"found", outcome.found},
                                {"id_swaps", outcome.idSwaps}};
        if (outcome.found) {
            trial["latency_frames"] = outcome.touchDown - outcome.trial.first;
            trial["detected_x"] = outcome.detectedDown.x();
            trial["detected_y"] = outcome.detectedDown.y();
            trial["error_px"] = outcome.downErrorPx;
        }
        trials.push_back(trial);
    }
    nlohmann::json phantoms = nlohmann::json::array();
    for (const PhantomTouch& phantom : score.phantoms)
        phantoms.push_back({{"position", phantom.position},
                            {"id", phantom.id},
                            {"x", phantom.point.x()},
                            {"y", phantom.point.y()}});
    return {{"recording", source.recording},
            {"log", source.log.empty() ? nlohmann::json(nullptr) : nlohmann::json(source.log)},
            {"frames", score.frames},
            {"match_radius_mm", source.matchRadiusMm},
            {"match_radius_px", score.matchRadiusPx},
            {"trials", score.trials.size()},
            {"rejected", score.rejected()},
            {"frr", orNull(score.frr())},
            {"touch_downs", score.touchDowns},
            {"false_touch_downs", score.phantoms.size()},
            {"far", orNull(score.far())},
            {"high_hover_mm", score.highHoverMm},
            {"high_hover_frames", score.highHoverFrames},
            {"high_hover_touch_frames", score.highHoverTouchFrames},
            {"epsilon_touch_down_px", meanJson(score.downErrorPx)},
            {"epsilon_touching_px", meanJson(score.touchingErrorPx)},
            {"drag_trials", score.dragTrials},
            {"drag_deviation_px", meanJson(score.dragDeviationPx)},
            {"latency_frames", meanJson(score.latencyFrames)},
            {"max_latency_frames", score.maxLatencyFrames},
            {"hover_error_mm", meanJson(score.hoverErrorMm)},
            {"hover_finger_frames", score.hoverFrames},
            {"hover_error_bands", bands},
            {"id_swaps", score.idSwaps},
            {"per_trial", trials},
            {"false_touches", phantoms}};
}

std::string touchTable(const TouchSource& source, const TouchScore& score) {
    std::string text = source.recording + ": " + std::to_string(score.frames) + " frames, " +
                       std::to_string(score.trials.size()) + " true touches, contacts from " +
                       (source.log.empty() ? std::string("the pipeline") : source.log) + "; match radius " +
                       fixed(source.matchRadiusMm, 1) + " mm = " + fixed(score.matchRadiusPx, 1) +
                       " display px\n";
    const auto count = [](std::int64_t value) { return std::to_string(value); };
    const std::string trials = std::to_string(score.trials.size());
    text += line("FRR (rejected trials)", fixed(score.frr(), 3), count(score.rejected()) + "/" + trials);
    text += line("FAR (false touch-downs per trial)", fixed(score.far(), 3),
                 count(static_cast<std::int64_t>(score.phantoms.size())) + " of " + count(score.touchDowns) +
                     " touch-downs");
    text += line(("touching while >= " + fixed(score.highHoverMm, 0) + " mm").c_str(),
                 count(score.highHoverTouchFrames), "of " + count(score.highHoverFrames) + " finger frames");
    text += line("epsilon at touch-down, px", fixed(score.downErrorPx.value(), 2),
                 count(score.downErrorPx.count) + " trials (paper eq. 24)");
    text += line("epsilon over touching frames, px", fixed(score.touchingErrorPx.value(), 2),
                 count(score.touchingErrorPx.count) + " frames");
    text +=
        line("drag deviation from path, px", fixed(score.dragDeviationPx.value(), 2),
             count(score.dragDeviationPx.count) + " frames of " + count(score.dragTrials) + " moving trials");
    const std::optional<double> latency = score.latencyFrames.value();
    text += line("touch-down latency, frames", fixed(latency, 2),
                 "max " + count(score.maxLatencyFrames) +
                     (latency && source.frameRate > 0
                          ? ", mean " + fixed(*latency * 1000.0 / source.frameRate, 1) + " ms"
                          : std::string()));
    text += line("id swaps", count(score.idSwaps), "");
    text += line("hover height error, mm", fixed(score.hoverErrorMm.value(), 2),
                 count(score.hoverErrorMm.count) + " of " + count(score.hoverFrames) + " finger frames");
    for (std::size_t b = 0; b < kHoverBandsMm.size(); ++b) {
        const std::string label =
            "  " + fixed(kHoverBandsMm[b][0], 0) + "-" + fixed(kHoverBandsMm[b][1], 0) + " mm";
        text += line(label.c_str(), fixed(score.hoverBandErrorMm[b].value(), 2),
                     count(score.hoverBandErrorMm[b].count) + " of " + count(score.hoverBandFrames[b]) +
                         " finger frames");
    }
    return text;
}

void writeTouchTrace(std::ostream& out, const TruthFrames& truth, const DetectedFrames& detected,
                     double radiusPx) {
    out << "position,finger,truth_height_mm,truth_x,truth_y,contact_id,height_mm,touching,x,y\n";
    char row[160];
    const std::size_t frames = std::min(truth.size(), detected.size());
    for (std::size_t p = 0; p < frames; ++p) {
        const std::vector<int> matched = matchFrame(truth[p], detected[p], radiusPx);
        for (std::size_t f = 0; f < truth[p].size(); ++f) {
            const core::FingerTruth& finger = truth[p][f];
            std::snprintf(row, sizeof row, "%zu,%u,%.2f,%.2f,%.2f,", p, finger.id, finger.heightMm, finger.x,
                          finger.y);
            out << row;
            if (matched[f] < 0) {
                out << ",,,,\n";
                continue;
            }
            const core::Contact& contact = detected[p][static_cast<std::size_t>(matched[f])];
            std::snprintf(row, sizeof row, "%u,%.2f,%d,%.2f,%.2f\n", contact.id, contact.heightMm,
                          contact.touching ? 1 : 0, contact.x, contact.y);
            out << row;
        }
    }
}

}  // namespace everytouch::eval

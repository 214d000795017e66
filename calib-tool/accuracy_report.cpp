#include "accuracy_report.h"

#include "text_format.h"

namespace everytouch::calib {

namespace {

std::string point(const core::DisplayPoint& p) {
    return format("(%.1f, %.1f)", p.x, p.y);
}

std::string plural(std::int64_t count, const char* one, const char* many) {
    return std::to_string(count) + " " + (count == 1 ? one : many);
}

nlohmann::json orNull(const std::optional<double>& value) {
    return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

nlohmann::json pointJson(const core::DisplayPoint& p) {
    return nlohmann::json::array({p.x, p.y});
}

}  // namespace

std::string describeTap(const AccuracyRun& run, std::size_t index) {
    const CircleOutcome& circle = run.score.circles.at(index);
    if (!circle.tap)
        return format("circle %zu of %zu has no tap", index + 1, run.score.circles.size());
    return format("%7.1f s  circle %zu of %zu tapped: %s, %.1f px (%.1f mm) from its centre",
                  circle.tap->seconds, index + 1, run.score.circles.size(), point(circle.tap->point).c_str(),
                  circle.errorPx, circle.errorMm);
}

void printAccuracyReport(std::FILE* out, const AccuracyRun& run) {
    const TapScore& score = run.score;
    const double mmPerPx = (run.targets.mmPerPxAcross + run.targets.mmPerPxDown) / 2.0;
    std::fprintf(out,
                 "Accuracy test on %s: %zu circles of radius %.1f px (%.1f mm) on a %u x %u px display, "
                 "%.1f x %.1f mm on the table\n",
                 run.rig.c_str(), score.circles.size(), run.targets.radiusPx, run.targets.radiusPx * mmPerPx,
                 run.display.widthPx, run.display.heightPx, run.display.widthMm, run.display.heightMm);
    std::fprintf(out, "circle  centre px         touch-down px     error px  error mm  repeats\n");
    for (std::size_t i = 0; i < score.circles.size(); ++i) {
        const CircleOutcome& circle = score.circles[i];
        if (circle.tap)
            std::fprintf(out, "%6zu  %-16s  %-16s  %8.2f  %8.2f  %7lld\n", i + 1,
                         point(circle.centre).c_str(), point(circle.tap->point).c_str(), circle.errorPx,
                         circle.errorMm, static_cast<long long>(circle.repeats));
        else
            std::fprintf(out, "%6zu  %-16s  none\n", i + 1, point(circle.centre).c_str());
    }
    for (const TouchDown& touchDown : score.falseTouchDowns)
        std::fprintf(out, "false touch-down at %s, %.1f s (on no circle)\n", point(touchDown.point).c_str(),
                     touchDown.seconds);

    const auto circles = static_cast<std::int64_t>(score.circles.size());
    const std::optional<double> epsilonPx = score.epsilonPx(), epsilonMm = score.epsilonMm();
    if (epsilonPx && epsilonMm)
        std::fprintf(out,
                     "epsilon  %8.2f px  %.2f mm   mean distance of the tap to the circle's centre over %s "
                     "(paper eq. 24)\n",
                     *epsilonPx, *epsilonMm,
                     plural(score.tapped(), "tapped circle", "tapped circles").c_str());
    else
        std::fprintf(out, "epsilon         -             no circle was tapped\n");
    std::fprintf(out, "FRR      %8.3f                %lld of %lld circles without a touch-down\n",
                 score.frr(), static_cast<long long>(circles - score.tapped()),
                 static_cast<long long>(circles));
    std::fprintf(
        out, "FAR      %8.3f                %s on no circle, per circle; %s in all\n", score.far(),
        plural(static_cast<std::int64_t>(score.falseTouchDowns.size()), "touch-down", "touch-downs").c_str(),
        plural(score.touchDowns, "touch-down", "touch-downs").c_str());
    std::fprintf(out, "repeats  %8lld                touch-downs on circles already tapped (not false)\n",
                 static_cast<long long>(score.repeats));
    if (score.complete())
        std::fprintf(out, "All %lld circles tapped in %.1f s.\n", static_cast<long long>(circles),
                     run.seconds);
    else
        std::fprintf(out, "%s after %.1f s with %lld of %lld circles tapped.\n",
                     run.seconds < run.timeoutS ? "Interrupted" : "Timed out", run.seconds,
                     static_cast<long long>(score.tapped()), static_cast<long long>(circles));
}

nlohmann::json accuracyReportJson(const AccuracyRun& run) {
    const TapScore& score = run.score;
    nlohmann::json circles = nlohmann::json::array();
    for (const CircleOutcome& circle : score.circles) {
        nlohmann::json entry{{"centre", pointJson(circle.centre)}, {"repeats", circle.repeats}};
        if (circle.tap) {
            entry["tap"] = {{"point", pointJson(circle.tap->point)},
                            {"id", circle.tap->id},
                            {"seconds", circle.tap->seconds}};
            entry["error_px"] = circle.errorPx;
            entry["error_mm"] = circle.errorMm;
        } else {
            entry["tap"] = nullptr;
            entry["error_px"] = nullptr;
            entry["error_mm"] = nullptr;
        }
        circles.push_back(entry);
    }
    nlohmann::json falseTouchDowns = nlohmann::json::array();
    for (const TouchDown& touchDown : score.falseTouchDowns)
        falseTouchDowns.push_back(
            {{"point", pointJson(touchDown.point)}, {"id", touchDown.id}, {"seconds", touchDown.seconds}});
    return {
        {"rig", run.rig},
        {"display_px", {run.display.widthPx, run.display.heightPx}},
        {"display_mm", {run.display.widthMm, run.display.heightMm}},
        {"radius_px", run.targets.radiusPx},
        {"circles", circles},
        {"false_touch_downs", falseTouchDowns},
        {"touch_downs", score.touchDowns},
        {"repeats", score.repeats},
        {"tapped", score.tapped()},
        {"complete", score.complete()},
        {"epsilon_px", orNull(score.epsilonPx())},
        {"epsilon_mm", orNull(score.epsilonMm())},
        {"frr", score.frr()},
        {"far", score.far()},
        {"seconds", run.seconds},
        {"timeout_s", run.timeoutS},
    };
}

}  // namespace everytouch::calib

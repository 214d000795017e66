#include "tap_scoring.h"

#include <algorithm>
#include <cmath>

namespace everytouch::calib {

std::vector<TouchDown> TouchDownFinder::next(double seconds, const std::vector<ContactReading>& contacts) {
    std::vector<TouchDown> found;
    std::set<std::uint32_t> touching;
    for (const ContactReading& contact : contacts) {
        if (!contact.touching)
            continue;
        touching.insert(contact.id);
        if (!first_ && !touching_.contains(contact.id))
            found.push_back({seconds, contact.id, {contact.x, contact.y}});
    }
    touching_ = std::move(touching);
    first_ = false;
    return found;
}

TapTargets accuracyTargets(const DaemonClient::Display& display) {
    const double width = display.widthPx, height = display.heightPx;
    TapTargets targets;
    targets.centres = core::accuracyGridCentres(width, height);
    targets.radiusPx = core::accuracyGridCircleRadius(width, height);
    targets.mmPerPxAcross = width > 0 ? display.widthMm / width : 0.0;
    targets.mmPerPxDown = height > 0 ? display.heightMm / height : 0.0;
    return targets;
}

std::int64_t TapScore::tapped() const {
    return std::count_if(circles.begin(), circles.end(),
                         [](const CircleOutcome& c) { return c.tap.has_value(); });
}

bool TapScore::complete() const {
    return tapped() == static_cast<std::int64_t>(circles.size());
}

std::optional<double> TapScore::meanOverTapped(double CircleOutcome::*error) const {
    const std::int64_t count = tapped();
    if (count == 0)
        return std::nullopt;
    double sum = 0.0;
    for (const CircleOutcome& circle : circles)
        sum += circle.tap ? circle.*error : 0.0;
    return sum / static_cast<double>(count);
}

double TapScore::frr() const {
    if (circles.empty())
        return 0.0;
    return static_cast<double>(static_cast<std::int64_t>(circles.size()) - tapped()) /
           static_cast<double>(circles.size());
}

double TapScore::far() const {
    if (circles.empty())
        return 0.0;
    return static_cast<double>(falseTouchDowns.size()) / static_cast<double>(circles.size());
}

TapScore scoreTaps(const TapTargets& targets, const std::vector<TouchDown>& touchDowns) {
    TapScore score;
    for (const core::DisplayPoint& centre : targets.centres)
        score.circles.push_back({centre, std::nullopt, 0.0, 0.0, 0});
    for (const TouchDown& touchDown : touchDowns) {
        ++score.touchDowns;
        CircleOutcome* nearest = nullptr;
        double nearestPx = targets.radiusPx;
        for (CircleOutcome& circle : score.circles) {
            const double distance =
                std::hypot(touchDown.point.x - circle.centre.x, touchDown.point.y - circle.centre.y);
            if (distance <= nearestPx) {
                nearest = &circle;
                nearestPx = distance;
            }
        }
        if (!nearest) {
            score.falseTouchDowns.push_back(touchDown);
            continue;
        }
        if (nearest->tap) {
            ++nearest->repeats;
            ++score.repeats;
            continue;
        }
        nearest->tap = touchDown;
        nearest->errorPx = nearestPx;
        nearest->errorMm = std::hypot((touchDown.point.x - nearest->centre.x) * targets.mmPerPxAcross,
                                      (touchDown.point.y - nearest->centre.y) * targets.mmPerPxDown);
    }
    return score;
}

}  // namespace everytouch::calib

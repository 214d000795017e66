#include "eval/touch_scoring.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace everytouch::eval {

namespace {

Eigen::Vector2d pointOf(const core::FingerTruth& finger) {
    return {finger.x, finger.y};
}
Eigen::Vector2d pointOf(const core::Contact& contact) {
    return {contact.x, contact.y};
}

double distanceToSegment(const Eigen::Vector2d& point, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d ab = b - a;
    const double length2 = ab.squaredNorm();
    const double t = length2 > 0 ? std::clamp((point - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
    return (point - (a + t * ab)).norm();
}

double distanceToPath(const Eigen::Vector2d& point, const std::vector<Eigen::Vector2d>& path) {
    if (path.size() == 1)
        return (point - path[0]).norm();
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 1; i < path.size(); ++i)
        best = std::min(best, distanceToSegment(point, path[i - 1], path[i]));
    return best;
}

bool wasTouching(const core::Contacts& contacts, std::uint32_t id) {
    return std::any_of(contacts.begin(), contacts.end(),
                       [&](const core::Contact& c) { return c.id == id && c.touching && !c.palm; });
}

}  // namespace

std::vector<int> matchFrame(const std::vector<core::FingerTruth>& fingers, const core::Contacts& contacts,
                            double radiusPx) {
    std::vector<std::tuple<double, std::size_t, std::size_t>> candidates;
    for (std::size_t f = 0; f < fingers.size(); ++f)
        for (std::size_t c = 0; c < contacts.size(); ++c) {
            if (contacts[c].palm)
                continue;
            const double distance = (pointOf(fingers[f]) - pointOf(contacts[c])).norm();
            if (distance <= radiusPx)
                candidates.emplace_back(distance, f, c);
        }
    std::sort(candidates.begin(), candidates.end());
    std::vector<int> matched(fingers.size(), -1);
    std::vector<bool> taken(contacts.size(), false);
    for (const auto& [distance, f, c] : candidates)
        if (matched[f] < 0 && !taken[c]) {
            matched[f] = static_cast<int>(c);
            taken[c] = true;
        }
    return matched;
}

std::optional<std::string> TouchScoringOptions::validate() const {
    if (!(matchRadiusPx > 0.0) || !std::isfinite(matchRadiusPx))
        return "the match radius must be a positive number of display pixels";
    if (!(touchHeightMm >= 0.0) || !std::isfinite(touchHeightMm))
        return "the touch height must be a non-negative number of mm";
    if (!(highHoverMm > 0.0) || !std::isfinite(highHoverMm))
        return "the high hover height must be a positive number of mm";
    return std::nullopt;
}

double matchRadiusPx(const core::Calibration& calibration, double radiusMm) {
    const cv::Size2d sizeMm = calibration.displaySizeMm();
    const double pxPerMm =
        (calibration.displaySize.width / sizeMm.width + calibration.displaySize.height / sizeMm.height) / 2.0;
    return radiusMm * pxPerMm;
}

std::int64_t TouchScore::rejected() const {
    return std::count_if(trials.begin(), trials.end(), [](const TrialOutcome& t) { return !t.found; });
}

std::optional<double> TouchScore::frr() const {
    if (trials.empty())
        return std::nullopt;
    return static_cast<double>(rejected()) / static_cast<double>(trials.size());
}

std::optional<double> TouchScore::far() const {
    if (trials.empty())
        return std::nullopt;
    return static_cast<double>(phantoms.size()) / static_cast<double>(trials.size());
}

TouchScore scoreTouches(const TruthFrames& truth, const DetectedFrames& detected,
                        const TouchScoringOptions& options) {
    TouchScore score;
    score.matchRadiusPx = options.matchRadiusPx;
    score.highHoverMm = options.highHoverMm;
    score.frames = std::min(truth.size(), detected.size());
    const double radius = options.matchRadiusPx;

    std::vector<std::vector<int>> matches(score.frames);
    const core::Contacts none;
    for (std::size_t p = 0; p < score.frames; ++p) {
        const std::vector<core::FingerTruth>& fingers = truth[p];
        const core::Contacts& contacts = detected[p];
        matches[p] = matchFrame(fingers, contacts, radius);
        for (std::size_t f = 0; f < fingers.size(); ++f) {
            const core::FingerTruth& finger = fingers[f];
            const core::Contact* contact = matches[p][f] >= 0 ? &contacts[matches[p][f]] : nullptr;
            if (finger.heightMm >= options.highHoverMm) {
                ++score.highHoverFrames;
                if (contact && contact->touching)
                    ++score.highHoverTouchFrames;
            }
            if (finger.heightMm > 0.0) {
                ++score.hoverFrames;
                for (std::size_t b = 0; b < kHoverBandsMm.size(); ++b)
                    if (finger.heightMm >= kHoverBandsMm[b][0] && finger.heightMm < kHoverBandsMm[b][1])
                        ++score.hoverBandFrames[b];
            }
            if (finger.heightMm > 0.0 && contact) {
                const double error = std::abs(contact->heightMm - finger.heightMm);
                score.hoverErrorMm.add(error);
                for (std::size_t b = 0; b < kHoverBandsMm.size(); ++b)
                    if (finger.heightMm >= kHoverBandsMm[b][0] && finger.heightMm < kHoverBandsMm[b][1])
                        score.hoverBandErrorMm[b].add(error);
            }
            if (finger.heightMm == 0.0 && contact && contact->touching)
                score.touchingErrorPx.add((pointOf(*contact) - pointOf(finger)).norm());
        }
        // Touch-downs: a contact touching now that did not touch in the frame before.
        const core::Contacts& before = p > 0 ? detected[p - 1] : none;
        for (const core::Contact& contact : contacts) {
            if (!contact.touching || contact.palm || wasTouching(before, contact.id))
                continue;
            ++score.touchDowns;
            const bool explained =
                std::any_of(fingers.begin(), fingers.end(), [&](const core::FingerTruth& f) {
                    return f.heightMm <= options.touchHeightMm &&
                           (pointOf(f) - pointOf(contact)).norm() <= radius;
                });
            if (!explained)
                score.phantoms.push_back({p, contact.id, pointOf(contact)});
        }
    }

    for (const TouchTrial& trial : touchTrials(truth)) {
        if (trial.first >= score.frames)
            continue;
        TrialOutcome outcome;
        outcome.trial = trial;
        outcome.truthDown = pointOf(*findFinger(truth[trial.first], trial.finger));
        std::vector<Eigen::Vector2d> path;
        double reach = 0.0;
        const std::size_t last = std::min(trial.last, score.frames - 1);
        for (std::size_t p = trial.first; p <= last; ++p) {
            path.push_back(pointOf(*findFinger(truth[p], trial.finger)));
            reach = std::max(reach, (path.back() - outcome.truthDown).norm());
        }
        const bool drag = reach > radius;
        score.dragTrials += drag ? 1 : 0;
        std::optional<std::uint32_t> lastId;
        for (std::size_t p = trial.first; p <= last; ++p) {
            const std::vector<core::FingerTruth>& fingers = truth[p];
            const auto f = static_cast<std::size_t>(findFinger(fingers, trial.finger) - fingers.data());
            if (matches[p][f] < 0)
                continue;
            const core::Contact& contact = detected[p][matches[p][f]];
            if (!contact.touching)
                continue;
            if (!outcome.found) {
                outcome.found = true;
                outcome.touchDown = p;
                outcome.detectedDown = pointOf(contact);
                outcome.downErrorPx = (pointOf(contact) - pointOf(fingers[f])).norm();
            }
            if (lastId && *lastId != contact.id)
                ++outcome.idSwaps;
            lastId = contact.id;
            if (drag)
                score.dragDeviationPx.add(distanceToPath(pointOf(contact), path));
        }
        if (outcome.found) {
            score.downErrorPx.add(outcome.downErrorPx);
            const auto latency = static_cast<std::int64_t>(outcome.touchDown - trial.first);
            score.latencyFrames.add(static_cast<double>(latency));
            score.maxLatencyFrames = std::max(score.maxLatencyFrames, latency);
        }
        score.idSwaps += outcome.idSwaps;
        score.trials.push_back(outcome);
    }
    return score;
}

}  // namespace everytouch::eval

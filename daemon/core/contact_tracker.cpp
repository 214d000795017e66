#include "core/contact_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace everytouch::core {

namespace {

// The travel gate's allowance for position noise, in standard deviations of the difference of two noisy
// positions (sqrt 2 times the noise of one).
constexpr double kGateNoiseSigmas = 3.0;

bool finite(const Eigen::Vector2d& v) {
    return std::isfinite(v.x()) && std::isfinite(v.y());
}

}  // namespace

std::optional<std::string> TrackerOptions::validate() const {
    if (!(maxSpeedMmPerS > 0.0) || !std::isfinite(maxSpeedMmPerS))
        return "maxSpeedMmPerS: must be a positive speed in mm/s";
    if (maxMissedFrames < 0)
        return "maxMissedFrames: must not be negative";
    if (maxUnmeasuredFrames < 0)
        return "maxUnmeasuredFrames: must not be negative";
    if (!(positionNoiseMm >= 0.0) || !std::isfinite(positionNoiseMm))
        return "positionNoiseMm: must be a non-negative number of millimetres";
    if (!(minHysteresisMm > 0.0) || !std::isfinite(minHysteresisMm))
        return "minHysteresisMm: must be a positive number of millimetres";
    if (!(hysteresisSigmas >= 0.0) || !std::isfinite(hysteresisSigmas))
        return "hysteresisSigmas: must be a non-negative number";
    if (!(decisiveSigmas >= 0.0) || !std::isfinite(decisiveSigmas))
        return "decisiveSigmas: must be a non-negative number";
    if (!(minCutoffHz > 0.0) || !std::isfinite(minCutoffHz))
        return "minCutoffHz: must be a positive frequency";
    if (!(betaHzPerMmPerS >= 0.0) || !std::isfinite(betaHzPerMmPerS))
        return "betaHzPerMmPerS: must be a non-negative number";
    if (!(derivativeCutoffHz > 0.0) || !std::isfinite(derivativeCutoffHz))
        return "derivativeCutoffHz: must be a positive frequency";
    if (restingReadings < 2)
        return "restingReadings: must be at least 2, for a spread";
    if (maxTracks < kMaxContacts)
        return "maxTracks: must be at least " + std::to_string(kMaxContacts) + ", the contacts reported";
    return std::nullopt;
}

ContactTracker::ContactTracker(const TrackerOptions& options) : options_(options) {
    if (auto problem = options.validate())
        throw std::invalid_argument("tracker options: " + *problem);
    const auto n = static_cast<std::size_t>(options_.maxTracks);
    tracks_.reserve(n);
    assignment_.reserve(options_.maxTracks, options_.maxTracks);
    cost_.reserve(n * n);
    allowed_.reserve(n * n);
    trackToObservation_.reserve(n);
    observationTaken_.reserve(n);
}

void ContactTracker::reset() {
    tracks_.clear();
    lastTimestampUs_.reset();
}

void ContactTracker::checkInputs(std::int64_t timestampUs, const std::vector<FingerObservation>& fingers,
                                 double touchHeightMm, double displayPixelsPerMm) const {
    if (lastTimestampUs_ && timestampUs <= *lastTimestampUs_)
        throw std::invalid_argument("contact tracker: timestamp " + std::to_string(timestampUs) +
                                    " us is not after the previous frame's " +
                                    std::to_string(*lastTimestampUs_) + " us");
    if (!std::isfinite(touchHeightMm))
        throw std::invalid_argument("contact tracker: the touch height is not a number");
    if (!(displayPixelsPerMm > 0.0) || !std::isfinite(displayPixelsPerMm))
        throw std::invalid_argument("contact tracker: the display scale " +
                                    std::to_string(displayPixelsPerMm) + " px/mm is not positive");
    for (std::size_t i = 0; i < fingers.size(); ++i) {
        const FingerObservation& finger = fingers[i];
        const char* problem = nullptr;
        if (!finite(finger.display))
            problem = " has a non-finite position";
        else if (!std::isfinite(finger.padHeightMm))
            problem = " has a non-finite pad height";
        else if (!(finger.heightUncertaintyMm >= 0.0) || !std::isfinite(finger.heightUncertaintyMm))
            problem = " has a height uncertainty that is negative or not finite";
        if (problem)
            throw std::invalid_argument("contact tracker: observation " + std::to_string(i) + problem);
    }
}

void ContactTracker::update(std::int64_t timestampUs, const std::vector<FingerObservation>& fingers,
                            double touchHeightMm, double displayPixelsPerMm, Contacts& contacts) {
    checkInputs(timestampUs, fingers, touchHeightMm, displayPixelsPerMm);
    lastTimestampUs_ = timestampUs;

    // The filter works in display pixels; its options are in millimetres.
    const OneEuroParameters filter{options_.minCutoffHz, options_.betaHzPerMmPerS / displayPixelsPerMm,
                                   options_.derivativeCutoffHz,
                                   options_.positionNoiseMm * displayPixelsPerMm};

    assign(timestampUs, fingers, displayPixelsPerMm);
    for (std::size_t t = 0; t < tracks_.size(); ++t) {
        Track& track = tracks_[t];
        if (trackToObservation_[t] >= 0)
            observe(track, timestampUs, fingers[trackToObservation_[t]], touchHeightMm, filter);
        else
            ++track.missedFrames;
    }
    std::erase_if(tracks_, [&](const Track& track) { return track.missedFrames > options_.maxMissedFrames; });

    for (std::size_t o = 0; o < fingers.size(); ++o) {
        // Without a height nothing says whether a new finger touches: it waits for one.
        if (observationTaken_[o] || !fingers[o].heightKnown ||
            tracks_.size() >= static_cast<std::size_t>(options_.maxTracks))
            continue;
        Track& track = tracks_.emplace_back();
        track.id = nextId_;
        track.seenUs = timestampUs;
        nextId_ = nextId_ == std::numeric_limits<std::uint32_t>::max() ? 1 : nextId_ + 1;
        observe(track, timestampUs, fingers[o], touchHeightMm, filter);
    }

    contacts.clear();
    contacts.reserve(kMaxContacts);
    for (const Track& track : tracks_) {
        if (contacts.size() == static_cast<std::size_t>(kMaxContacts))
            break;
        // A hovering finger is placed by its height, which its code tells only while the finger holds
        // still between a pair's two frames: one rising from a tap at 0.3 m/s shows none for ten frames.
        // Its last height and place would be reported long after they stopped being true (0.7 mm for a
        // finger at 30 mm); it is reported again once its height is read, under the same id.
        if (!track.confirmed || (!track.touching && track.unmeasuredFrames > options_.maxUnmeasuredFrames))
            continue;
        const Eigen::Vector2d& position = track.filter.value();
        contacts.push_back(
            {track.id, position.x(), position.y(), track.touching, track.heightMm, track.palm});
    }
}

void ContactTracker::assign(std::int64_t timestampUs, const std::vector<FingerObservation>& fingers,
                            double displayPixelsPerMm) {
    const int rows = static_cast<int>(tracks_.size());
    const int columns = static_cast<int>(fingers.size());
    cost_.assign(static_cast<std::size_t>(rows) * columns, 0.0);
    allowed_.assign(cost_.size(), 0);
    observationTaken_.assign(fingers.size(), 0);
    trackToObservation_.assign(tracks_.size(), -1);
    if (rows == 0 || columns == 0)
        return;

    const double gateNoiseMm = kGateNoiseSigmas * std::sqrt(2.0) * options_.positionNoiseMm;
    double allowedTotal = 0.0;
    for (int t = 0; t < rows; ++t) {
        const Track& track = tracks_[t];
        const double sinceSeenS = static_cast<double>(timestampUs - track.seenUs) * 1e-6;
        const double gateMm = options_.maxSpeedMmPerS * sinceSeenS + gateNoiseMm;
        const Eigen::Vector2d predicted = track.filter.value() + track.filter.velocity() * sinceSeenS;
        for (int o = 0; o < columns; ++o) {
            const std::size_t k = static_cast<std::size_t>(t) * columns + o;
            const Eigen::Vector2d& seen = fingers[o].display;
            if ((seen - track.observed).norm() / displayPixelsPerMm > gateMm)
                continue;
            allowed_[k] = 1;
            cost_[k] = (seen - predicted).norm() / displayPixelsPerMm;
            allowedTotal += cost_[k];
        }
    }
    // A pair outside the gate costs more than all allowed pairs together: the solver then matches as many
    // tracks as the gate allows before it looks at distances, and such a pair, if it must take one, is
    // undone.
    const double forbidden = allowedTotal + 1.0;
    for (std::size_t k = 0; k < cost_.size(); ++k)
        if (!allowed_[k])
            cost_[k] = forbidden;

    assignment_.solve(rows, columns, cost_, trackToObservation_);
    for (int t = 0; t < rows; ++t) {
        int& o = trackToObservation_[t];
        if (o < 0)
            continue;
        if (!allowed_[static_cast<std::size_t>(t) * columns + o])
            o = -1;
        else
            observationTaken_[o] = 1;
    }
}

void ContactTracker::observe(Track& track, std::int64_t timestampUs, const FingerObservation& finger,
                             double touchHeightMm, const OneEuroParameters& filter) {
    track.palm = track.palm || finger.palm;
    if (!plausibleHeight(track, timestampUs, finger)) {
        track.missedFrames = 0;
        // A touching finger whose code still favours the table was not seen to rise; one whose last height
        // was above the touch height and whose code now shows nothing near the table was seen to leave it.
        const bool touchingWithoutHeight = track.touching && !finger.heightKnown;
        const bool stillDown = touchingWithoutHeight && finger.codeFavoursTable;
        const bool leaving = touchingWithoutHeight && !finger.codeFavoursTable &&
                             track.unmeasuredFrames == 0 && track.heightMm > touchHeightMm;
        if (!stillDown)
            ++track.unmeasuredFrames;
        // A touch-down pending through more frames without a height than a touch survives is forgotten: a
        // low height read that long ago says nothing of where the finger is now (a hand's outline passing
        // high shows a fingertip now and then, and its track may next be matched far away).
        if (!track.touching && track.unmeasuredFrames > options_.maxUnmeasuredFrames)
            track.pending = false;
        if (track.touching && (leaving || track.unmeasuredFrames > options_.maxUnmeasuredFrames)) {
            track.touching = false;
            track.pending = false;
        }
        // Only a touching finger lies on the table, where an observation without a height places it; a
        // height that was no reading placed it nowhere.
        if (!track.touching || finger.heightKnown)
            return;
    } else {
        track.unmeasuredFrames = 0;
        updateTouch(track, finger, touchHeightMm);
        track.heightMm = finger.padHeightMm;
        track.heightSeenUs = timestampUs;
    }
    // A new track's first observation is placed here too (seenUs is its start): only a second one confirms
    // it.
    track.confirmed = track.confirmed || timestampUs != track.seenUs;
    const double sinceSeenS = static_cast<double>(timestampUs - track.seenUs) * 1e-6;
    track.filter.filter(finger.display, sinceSeenS, filter);
    track.observed = finger.display;
    track.seenUs = timestampUs;
    track.missedFrames = 0;
}

bool ContactTracker::plausibleHeight(const Track& track, std::int64_t timestampUs,
                                     const FingerObservation& finger) const {
    if (!finger.heightKnown)
        return false;
    if (track.heightSeenUs == kNever)
        return true;
    // No finger rises or falls faster than it travels across the table: a height further from the last one
    // than that allows (and its uncertainty) is a false reading, such as a correlation peak of chance.
    const double sinceS = static_cast<double>(timestampUs - track.heightSeenUs) * 1e-6;
    const double reachMm =
        options_.maxSpeedMmPerS * sinceS + options_.hysteresisSigmas * finger.heightUncertaintyMm;
    return std::abs(finger.padHeightMm - track.heightMm) <= reachMm;
}

void ContactTracker::updateTouch(Track& track, const FingerObservation& finger, double touchHeightMm) const {
    const double sigma = finger.heightUncertaintyMm;
    const double decisiveMm = std::max(options_.minHysteresisMm, options_.decisiveSigmas * sigma);
    if (!track.touching) {
        const double belowMm = touchHeightMm - finger.padHeightMm;
        const bool down = !track.palm && belowMm >= 0.0;
        if (down && (track.pending || belowMm >= decisiveMm)) {
            track.touching = true;
            track.pending = false;
            // The touch starts at its measured point, not where the hovering finger's filter has got to.
            track.filter.reset();
        } else {
            track.pending = down;
        }
        return;
    }
    double liftMm = touchHeightMm + std::max(options_.minHysteresisMm, options_.hysteresisSigmas * sigma);
    // Once learned, only readings within the band of the resting level are of the finger at rest: a finger
    // rising slowly must not carry its level up with it.
    bool resting = finger.padHeightMm <= liftMm;
    if (track.resting.count >= options_.restingReadings) {
        const double bandMm =
            std::max(options_.minHysteresisMm, options_.hysteresisSigmas * track.resting.spreadMm());
        liftMm = std::max(touchHeightMm, track.resting.meanMm) + bandMm;
        resting = finger.padHeightMm <= track.resting.meanMm + bandMm;
    }
    if (resting)
        track.resting.add(finger.padHeightMm);
    // A lift always takes two frames running: a resting fingertip whose end the segmentation loses for a
    // frame (over pale content, several times a tap) is read on the finger further back, 8-11 mm up, far
    // beyond any band.
    const bool up = finger.padHeightMm > liftMm;
    if (up && track.pending) {
        track.touching = false;
        track.pending = false;
    } else {
        track.pending = up;
    }
}

void ContactTracker::RestingLevel::add(double heightMm) {
    ++count;
    const double delta = heightMm - meanMm;
    meanMm += delta / count;
    sumSquaresMm2 += delta * (heightMm - meanMm);
}

double ContactTracker::RestingLevel::spreadMm() const {
    return count > 1 ? std::sqrt(sumSquaresMm2 / (count - 1)) : 0.0;
}

}  // namespace everytouch::core

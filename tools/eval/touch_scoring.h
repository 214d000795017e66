#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/calibration.h"
#include "eval/detected_contacts.h"
#include "eval/touch_trials.h"

namespace everytouch::eval {

struct TouchScoringOptions {
    // How far a detected contact may lie from a true finger's contact point and still be that finger,
    // display pixels. Set it from a physical length with matchRadiusPx().
    double matchRadiusPx = 0.0;
    // A true finger hovering at least this high must never be reported touching, mm (the paper's claim: no
    // touch is reported at 8 mm or more).
    double highHoverMm = 8.0;
    // The touch height the contacts were detected with, mm: a finger whose pad is this close to the table
    // touches by the product's own definition (TouchHeightMm, the paper's elevated plane), so a touch-down
    // while a true pad within the radius is this low is early at worst, not false.
    double touchHeightMm = 0.0;

    std::optional<std::string> validate() const;
};

// `radiusMm` on the table in display pixels, by the calibration's display size: half a finger width (8 mm)
// lies between the contact points of two fingers side by side, so a wider radius would credit a neighbour.
double matchRadiusPx(const core::Calibration& calibration, double radiusMm);

// The hover bands the height error is given for, mm: [lower, upper).
inline constexpr std::array<std::array<double, 2>, 4> kHoverBandsMm{{{2, 5}, {5, 10}, {10, 20}, {20, 40}}};

struct Mean {
    double sum = 0.0;
    std::int64_t count = 0;

    void add(double value) {
        sum += value;
        ++count;
    }
    std::optional<double> value() const { return count ? std::optional(sum / count) : std::nullopt; }
};

struct TrialOutcome {
    TouchTrial trial;
    Eigen::Vector2d truthDown = Eigen::Vector2d::Zero();  // the true contact point at the trial's first frame
    bool found = false;                                   // a matching contact touched during the trial
    std::size_t touchDown = 0;                            // position where it first touched, when found
    Eigen::Vector2d detectedDown = Eigen::Vector2d::Zero();  // its point there, display pixels
    double downErrorPx = 0.0;  // to the true contact point of that frame (paper eq. 24)
    int idSwaps = 0;           // changes of the matched touching contact's id within the trial
};

// A detected touch-down no true touching finger explains.
struct PhantomTouch {
    std::size_t position = 0;
    std::uint32_t id = 0;
    Eigen::Vector2d point = Eigen::Vector2d::Zero();  // display pixels
};

struct TouchScore {
    double matchRadiusPx = 0.0;
    double highHoverMm = 0.0;
    std::size_t frames = 0;
    std::vector<TrialOutcome> trials;
    std::int64_t touchDowns = 0;  // contacts going to touching (or appearing touching)
    std::vector<PhantomTouch> phantoms;
    std::int64_t highHoverFrames = 0;       // frame x finger with the finger at highHoverMm or more
    std::int64_t highHoverTouchFrames = 0;  // ... matched to a touching contact
    Mean downErrorPx;                       // ε at touch-down, over the found trials
    Mean touchingErrorPx;         // ε over every frame a true touching finger matches a touching contact
    Mean dragDeviationPx;         // distance to the true path, over touching frames of moving trials
    std::int64_t dragTrials = 0;  // trials whose finger moves by more than the match radius
    Mean latencyFrames;           // touch-down latency, over the found trials
    std::int64_t maxLatencyFrames = 0;
    Mean hoverErrorMm;  // |height - truth| of hovering fingers matched to a contact
    std::array<Mean, kHoverBandsMm.size()> hoverBandErrorMm;
    // Frame x finger hovering in each band, whether a contact was matched to it or not: the errors above
    // cover only those a contact was reported for.
    std::array<std::int64_t, kHoverBandsMm.size()> hoverBandFrames{};
    std::int64_t hoverFrames = 0;
    std::int64_t idSwaps = 0;

    std::int64_t rejected() const;
    std::optional<double> frr() const;  // rejected trials / trials
    std::optional<double> far() const;  // phantom touch-downs / true trials
};

// The contact matched to each true finger of a frame (index into the frame's contacts), one to one, nearest
// pairs first, palms left out; -1 where none lies within the radius.
std::vector<int> matchFrame(const std::vector<core::FingerTruth>& fingers, const core::Contacts& contacts,
                            double radiusPx);

// Scores a detector's contacts against the truth, frame by frame. In each frame the true fingers and the
// detected contacts (palms left out) are matched one to one, the nearest pairs first, within the radius.
TouchScore scoreTouches(const TruthFrames& truth, const DetectedFrames& detected,
                        const TouchScoringOptions& options);

}  // namespace everytouch::eval

#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <vector>

#include "core/accuracy_grid.h"
#include "daemon_client.h"

namespace everytouch::calib {

// A contact going to touching as the Contacts signals show it: touching in one signal, not touching or absent
// in the one before.
struct TouchDown {
    double seconds = 0.0;  // since following began
    std::uint32_t id = 0;
    core::DisplayPoint point;  // display pixels
};

// Finds the touch-downs in a run of Contacts signals. The daemon sends the contacts of its latest frame at
// most about 30 times a second, so a touch-down is seen in the first signal after the frame it happened in,
// at that signal's point, and a lift shorter than the gap between two signals goes unseen. A contact touching
// in the first signal may have touched down before anyone listened, so it is not taken for a touch-down.
class TouchDownFinder {
public:
    std::vector<TouchDown> next(double seconds, const std::vector<ContactReading>& contacts);

private:
    bool first_ = true;
    std::set<std::uint32_t> touching_;  // ids touching in the previous signal
};

// What the taps of the accuracy test are scored against.
struct TapTargets {
    std::vector<core::DisplayPoint> centres;  // display pixels
    // A touch-down this close to a centre, display pixels, is a tap on that circle: the drawn circle's
    // radius. A touch-down outside every circle is not where anyone was asked to touch, so it is false; half
    // the gap between circles would instead credit a circle with touches it does not hold.
    double radiusPx = 0.0;
    double mmPerPxAcross = 0.0;  // the display's scale on the table along its rows, mm per display pixel
    double mmPerPxDown = 0.0;    // ... along its columns
};

// The paper's 35 circles on `display`, scaled by its size on the table.
TapTargets accuracyTargets(const DaemonClient::Display& display);

struct CircleOutcome {
    core::DisplayPoint centre;     // display pixels
    std::optional<TouchDown> tap;  // the first touch-down on the circle
    double errorPx = 0.0;          // from the tap's point to the centre (the paper's eq. 24), when tapped
    double errorMm = 0.0;          // the same on the table
    std::int64_t repeats = 0;      // later touch-downs on the circle
};

// The paper's scores of its tap trials (Table II), one trial per circle, with the definitions of
// `everytouch-eval touches` (docs/evaluation.md): ε the mean distance of the touch-down to the target, FRR
// the trials without a touch-down, FAR the touch-downs no target explains per trial.
struct TapScore {
    std::vector<CircleOutcome> circles;      // in the order of the targets
    std::vector<TouchDown> falseTouchDowns;  // on no circle
    std::int64_t touchDowns = 0;             // all of them
    // Touch-downs on a circle that already has its tap: the finger tapping it again, or one tap seen twice
    // (a short lift in the detection). The finger is on a target either way, as a true finger within the
    // match radius explains a touch-down in `everytouch-eval touches`, so these are not false.
    std::int64_t repeats = 0;

    std::int64_t tapped() const;
    bool complete() const;  // every circle has its tap
    // Mean error over the tapped circles; none before a tap.
    std::optional<double> epsilonPx() const { return meanOverTapped(&CircleOutcome::errorPx); }
    std::optional<double> epsilonMm() const { return meanOverTapped(&CircleOutcome::errorMm); }
    double frr() const;  // circles without a tap / circles
    double far() const;  // false touch-downs / circles

private:
    std::optional<double> meanOverTapped(double CircleOutcome::*error) const;
};

// Each touch-down, in the order given, goes to the nearest circle whose radius holds it: the first on a
// circle is its tap, later ones repeats; one on no circle is false.
TapScore scoreTaps(const TapTargets& targets, const std::vector<TouchDown>& touchDowns);

}  // namespace everytouch::calib

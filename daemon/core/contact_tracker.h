#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/assignment.h"
#include "core/contact.h"
#include "core/one_euro_filter.h"

namespace everytouch::core {

// The most contacts reported at once: the virtual touchscreen's slots (io::MultitouchEncoder::kSlotCount).
inline constexpr int kMaxContacts = 10;

// One fingertip, palm or forearm the detection found in a frame.
struct FingerObservation {
    Eigen::Vector2d display = Eigen::Vector2d::Zero();  // contact point, display pixels
    double padHeightMm = 0.0;                           // estimated height of the finger pad above the table
    double heightUncertaintyMm = 0.0;  // one standard deviation of that estimate (large before evidence)
    bool palm = false;                 // a palm, fist or forearm resting: reported as a palm, never a touch
    // False when the fingertip was found but the code on it was not seen well enough for a height: the
    // observation keeps its track, and `display` is the point on the table (padHeightMm is not used).
    bool heightKnown = true;
    // Without a height: the code on the fingertip still matches the heights a touching fingertip shows
    // better than any higher one (SurfaceHeight::favoursPadUpTo). A touching finger stays down through such
    // frames: they do not count towards maxUnmeasuredFrames.
    bool codeFavoursTable = false;
};

struct TrackerOptions {
    // Fastest a finger plausibly travels across the table, mm/s (2 m/s: a quick flick): an observation
    // further from a track than this covers since the track was last seen is another finger.
    double maxSpeedMmPerS = 2000.0;
    // Frames a track lives on without an observation, holding its touch: a detection that misses a finger in
    // a frame or two must not end a touch. A finger that really vanishes is released this many frames late.
    int maxMissedFrames = 2;
    // Frames running a touching finger may show no height before it lifts: the fingertip is found while the
    // code on it is too faint to measure (a darker finger, a slide), or the height read is one no finger
    // reaches in the time (maxSpeedMmPerS). As for a missed frame, a finger that really rose is released
    // this many frames late; the track and its id stay.
    int maxUnmeasuredFrames = 2;
    // One standard deviation of a resting fingertip's detected contact point, mm. It widens the travel gate
    // and tells the position filter which speeds are jitter.
    double positionNoiseMm = 0.5;

    // Least width of the hysteresis band, mm: a finger touches once its pad is at most the touch height above
    // the table and lifts only above the touch height plus the band.
    double minHysteresisMm = 1.0;
    // The band is at least this many standard deviations of the height estimate: a finger resting exactly at
    // the touch height then shows a lift (two frames running above the band) once in 5 * 10^5 frames.
    double hysteresisSigmas = 3.0;
    // One frame suffices for a touch-down when the height is below the touch height by this many standard
    // deviations and by at least minHysteresisMm; otherwise two frames running are needed. A finger hovering
    // just above the touch height dips 4 sigma below it once in 3 * 10^4 frames. A lift always needs two:
    // a resting fingertip whose end the segmentation loses for a frame reads 8-11 mm up, beyond any
    // Gaussian tail, several times a tap over pale printed content.
    double decisiveSigmas = 4.0;
    // Pad heights read while a finger rests, after which the lift is judged against that finger's own
    // resting level and scatter instead of the observation's uncertainty. The pad height subtracts a prior
    // thickness, so a thicker finger rests above zero, and the uncertainty must cover every finger's
    // thickness (about 2 mm): a band three times that let a rising finger pass 8 mm before it lifted. A
    // finger's own readings at rest measure both its offset and its noise; 8 frames (67 ms at 120 Hz) give
    // their spread to within a third.
    int restingReadings = 8;

    // The position filter (core/one_euro_filter.h): its cutoff at rest, Hz. At 120 Hz, 1 Hz cuts a resting
    // finger's jitter of positionNoiseMm about fivefold (jitter twice that opens the filter now and then).
    double minCutoffHz = 1.0;
    // How fast the cutoff rises with the speed above the jitter's, Hz per mm/s: at 0.5 m/s the filter is all
    // but open, so a moving finger lags by a fraction of a millimetre.
    double betaHzPerMmPerS = 1.0;
    // Cutoff of the filter's speed estimate, Hz: high enough that the filter opens within two or three frames
    // of a start, low enough that jitter rarely opens it at rest.
    double derivativeCutoffHz = 5.0;

    // Tracks kept at once, the reported ones included: room is reserved for them and for as many
    // observations a frame. Observations beyond it start no track (the older tracks win).
    int maxTracks = 20;

    std::optional<std::string> validate() const;
};

// Turns each frame's observations into contacts with stable ids, a debounced touch state and a smoothed
// position. Pure: time is the timestamps it is given.
//
// - Ids: each frame, observations are assigned to tracks by the least total distance from each track's
//   predicted position (its filtered position moved on by its filtered velocity), among pairs no further
//   apart than maxSpeedMmPerS covers in the time since the track was last seen (plus the position noise of
//   both ends). As many tracks as possible are matched, then the distance is least. An observation left over
//   starts a track with the next id (ids increase, 1, 2, ...; not reused within 2^32 - 1 tracks). A track
//   without an observation keeps its state for maxMissedFrames frames, then ends. The prediction is what
//   keeps two fingers passing each other at speed apart; fingers turning back abruptly within a finger's
//   width of each other can swap when each moves more than half their gap a frame (0.6 m/s at 10 mm).
// - Touch, with T the touch height and sigma the frame's height uncertainty: a finger goes down when its pad
//   height h <= T, and lifts when h > T + max(minHysteresisMm, hysteresisSigmas * sigma). Once a touching
//   finger has given restingReadings heights, it lifts when h > max(T, m) + max(minHysteresisMm,
//   hysteresisSigmas * s), m and s being the mean and standard deviation of its readings at rest: its own
//   resting level and its own noise. Readings at rest are those below the lift line while it is learned,
//   then those within the band above m.
// - Heights: an observation without a height, or with one further from the track's last than a finger moves
//   at maxSpeedMmPerS in the time (plus three sigma), keeps its track but changes no touch state; after
//   maxUnmeasuredFrames such frames running a touching finger lifts, not counting frames whose code still
//   favours the table. A frame without a height whose code does not favour the table, right after a height
//   above the touch height, lifts a touching finger at once: it was seen leaving the table, and nothing
//   puts it back (the two frames running of the debouncing). An observation without a height moves only a
//   touching track (its point lies on the table) and starts no track; an implausible one moves none. A
//   hovering track without a height for more than maxUnmeasuredFrames frames running is not reported until
//   one is read again: neither its place nor its height is known.
// - Debouncing: a change needs its condition in two observed frames running; a touch-down also in one frame
//   when the height is below the touch height by max(minHysteresisMm, decisiveSigmas * sigma). So a
//   touch-down is reported in the first frame that meets its condition when the evidence is decisive, and
//   otherwise, like a lift, in the second frame running that meets it: at most one frame (8.3 ms at 120 Hz)
//   late. A single frame that meets the condition without deciding changes nothing. A frame without an
//   observation neither confirms nor cancels, so a missed frame in between adds its own frame; so do frames
//   without a height, but after more than maxUnmeasuredFrames of them running a pending touch-down is
//   forgotten.
// - Position: the One Euro filter per track on display pixels, started afresh at touch-down so that a touch
//   begins at its measured point. A track without an observation stays where it was.
// - Palms: a track that has been matched to a palm observation is a palm for the rest of its life and never
//   goes down (libinput cannot take a cancelled touch back either, and a palm misread as a finger for a frame
//   must not tap). A palm that was a touching finger keeps touching = true until it lifts or ends, so the
//   touchscreen holds its slot and turns it into MT_TOOL_PALM, which cancels the touch; a touch released
//   instead would be a tap.
// - A new track is reported from the second frame that places it (an observation with a plausible height,
//   or any observation of a touching finger), like any change of state: a fingertip found in one pair
//   alone (the projected content changing between the pair's two frames draws edges in S that nothing on
//   the table shows) is no finger. A finger that appears touching is thus reported at most one frame late,
//   like a touch-down.
// - At most kMaxContacts contacts are reported, the oldest tracks first; hovering fingers and palms count.
// - After construction no update allocates while the observations fit maxTracks.
class ContactTracker {
public:
    // Throws std::invalid_argument when the options are not valid.
    explicit ContactTracker(const TrackerOptions& options);

    // Called once per camera frame pair, in order of strictly increasing timestamps. touchHeightMm: T above.
    // displayPixelsPerMm: the display's scale on the table (from the calibration), which puts every distance
    // option in millimetres. `contacts` is replaced by the current contacts, oldest first. Throws
    // std::invalid_argument, naming the input, on a timestamp not after the previous one, a scale that is not
    // positive, a non-finite touch height or observation, or a negative uncertainty.
    void update(std::int64_t timestampUs, const std::vector<FingerObservation>& fingers, double touchHeightMm,
                double displayPixelsPerMm, Contacts& contacts);

    // Forgets every track (after a pipeline error, say): the next update starts from nothing, with new ids,
    // and accepts any timestamp.
    void reset();

    const TrackerOptions& options() const { return options_; }

private:
    static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();
    // Mean and spread of a touching finger's pad height readings (Welford's running sums).
    struct RestingLevel {
        int count = 0;
        double meanMm = 0.0;
        double sumSquaresMm2 = 0.0;  // of the differences from the mean
        void add(double heightMm);
        double spreadMm() const;  // sample standard deviation
    };
    struct Track {
        std::uint32_t id = 0;
        Eigen::Vector2d observed = Eigen::Vector2d::Zero();  // last observation, display pixels
        std::int64_t seenUs = 0;                             // when it was last observed
        int missedFrames = 0;                                // frames since then
        int unmeasuredFrames = 0;                            // observed frames running without a height
        double heightMm = 0.0;                               // last plausible pad height
        std::int64_t heightSeenUs = kNever;                  // when it was measured
        bool touching = false;
        bool palm = false;
        bool pending = false;  // the last observation met the condition for the other touch state, undecided
        bool confirmed = false;  // placed in a second frame since it began: reported from then on
        RestingLevel resting;    // the pad heights read while it touched
        OneEuroFilter filter;
    };

    void checkInputs(std::int64_t timestampUs, const std::vector<FingerObservation>& fingers,
                     double touchHeightMm, double displayPixelsPerMm) const;
    void assign(std::int64_t timestampUs, const std::vector<FingerObservation>& fingers,
                double displayPixelsPerMm);
    void observe(Track& track, std::int64_t timestampUs, const FingerObservation& finger,
                 double touchHeightMm, const OneEuroParameters& filter);
    void updateTouch(Track& track, const FingerObservation& finger, double touchHeightMm) const;
    bool plausibleHeight(const Track& track, std::int64_t timestampUs, const FingerObservation& finger) const;

    TrackerOptions options_;
    std::vector<Track> tracks_;  // oldest first
    std::optional<std::int64_t> lastTimestampUs_;
    std::uint32_t nextId_ = 1;

    // Per-frame scratch, reserved for maxTracks x maxTracks.
    LinearAssignment assignment_;
    std::vector<double> cost_;             // tracks x observations, mm
    std::vector<char> allowed_;            // the pair is within the travel gate
    std::vector<int> trackToObservation_;  // the assignment, -1 for none
    std::vector<char> observationTaken_;   // observed by an existing track
};

}  // namespace everytouch::core

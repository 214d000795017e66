#include "core/contact_tracker.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/allocation_counter.h"

namespace everytouch::core {
namespace {

// The paper-like rig: 1280 px over 276.5 mm; a 120 Hz camera; the daemon's default touch height.
constexpr double kPxPerMm = 1280.0 / 276.5;
constexpr std::int64_t kFrameUs = 8333;
constexpr double kFrameS = kFrameUs * 1e-6;
constexpr double kTouchMm = 3.0;
constexpr double kSigmaMm = 0.5;  // height uncertainty the observations report, unless a test says otherwise

// Tests place fingers in table millimetres; the tracker sees display pixels.
FingerObservation finger(const Eigen::Vector2d& mm, double heightMm, double sigmaMm = kSigmaMm) {
    return {mm * kPxPerMm, heightMm, sigmaMm, false};
}

FingerObservation palm(const Eigen::Vector2d& mm, double heightMm = 0.0) {
    return {mm * kPxPerMm, heightMm, kSigmaMm, true};
}

Eigen::Vector2d millimetres(const Contact& contact) {
    return Eigen::Vector2d(contact.x, contact.y) / kPxPerMm;
}

// A tracker fed one frame at a time, 120 frames a second.
class Feed {
public:
    explicit Feed(const TrackerOptions& options = {}) : tracker_(options) {}

    const Contacts& operator()(const std::vector<FingerObservation>& fingers,
                               double touchHeightMm = kTouchMm) {
        timeUs_ += kFrameUs;
        tracker_.update(timeUs_, fingers, touchHeightMm, kPxPerMm, contacts_);
        return contacts_;
    }

    // Fingers come into view: seen in two frames running, as a new track must be before it is reported.
    const Contacts& appear(const std::vector<FingerObservation>& fingers, double touchHeightMm = kTouchMm) {
        (*this)(fingers, touchHeightMm);
        return (*this)(fingers, touchHeightMm);
    }

    const Contacts& contacts() const { return contacts_; }
    ContactTracker& tracker() { return tracker_; }
    std::int64_t timeUs() const { return timeUs_; }

private:
    ContactTracker tracker_;
    std::int64_t timeUs_ = 0;
    Contacts contacts_;
};

const Contact* withId(const Contacts& contacts, std::uint32_t id) {
    auto found = std::find_if(contacts.begin(), contacts.end(), [&](const Contact& c) { return c.id == id; });
    return found == contacts.end() ? nullptr : &*found;
}

// Feeds fingers along `paths` (table mm at frame f) with position noise and checks, every frame, that each
// finger's contact keeps the id it got in the first frame it was reported in and lies nearer its own finger
// than any other.
template <typename Paths>
void expectIdsKept(int fingerCount, int frames, Paths paths, unsigned seed, double noiseMm = 0.5) {
    std::mt19937 random(seed);
    std::normal_distribution<double> jitter(0.0, noiseMm);
    Feed feed;
    std::vector<std::uint32_t> ids;
    std::vector<Eigen::Vector2d> truth(static_cast<std::size_t>(fingerCount));
    std::vector<FingerObservation> observations;
    for (int f = 0; f < frames; ++f) {
        observations.clear();
        for (int i = 0; i < fingerCount; ++i) {
            truth[i] = paths(i, f);
            observations.push_back(finger(truth[i] + Eigen::Vector2d(jitter(random), jitter(random)), 0.0));
        }
        // The tracker must not lean on the order the detection lists fingers in.
        std::shuffle(observations.begin(), observations.end(), random);
        const Contacts& contacts = feed(observations);
        // New fingers are reported from the second frame they are seen in.
        if (f == 0) {
            ASSERT_TRUE(contacts.empty());
            continue;
        }
        ASSERT_EQ(contacts.size(), static_cast<std::size_t>(fingerCount)) << "frame " << f;
        if (f == 1) {
            for (int i = 0; i < fingerCount; ++i) {
                auto nearest = std::min_element(
                    contacts.begin(), contacts.end(), [&](const Contact& a, const Contact& b) {
                        return (millimetres(a) - truth[i]).norm() < (millimetres(b) - truth[i]).norm();
                    });
                ids.push_back(nearest->id);
            }
            continue;
        }
        for (int i = 0; i < fingerCount; ++i) {
            const Contact* contact = withId(contacts, ids[i]);
            ASSERT_NE(contact, nullptr)
                << "finger " << i << " lost its id at frame " << f << ", seed " << seed;
            const double own = (millimetres(*contact) - truth[i]).norm();
            for (int j = 0; j < fingerCount; ++j)
                ASSERT_TRUE(j == i || own < (millimetres(*contact) - truth[j]).norm())
                    << "finger " << i << "'s id went to finger " << j << " at frame " << f << ", seed "
                    << seed;
        }
    }
}

TEST(TrackerOptions, DefaultsAreValidAndMistakesAreNamed) {
    EXPECT_EQ(TrackerOptions{}.validate(), std::nullopt);
    auto problem = [](auto change) {
        TrackerOptions options;
        change(options);
        return options.validate().value_or("");
    };
    using ::testing::StartsWith;
    EXPECT_THAT(problem([](TrackerOptions& o) { o.maxSpeedMmPerS = 0; }), StartsWith("maxSpeedMmPerS:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.maxMissedFrames = -1; }), StartsWith("maxMissedFrames:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.maxUnmeasuredFrames = -1; }),
                StartsWith("maxUnmeasuredFrames:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.positionNoiseMm = NAN; }), StartsWith("positionNoiseMm:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.minHysteresisMm = 0; }), StartsWith("minHysteresisMm:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.hysteresisSigmas = -1; }), StartsWith("hysteresisSigmas:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.decisiveSigmas = INFINITY; }),
                StartsWith("decisiveSigmas:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.restingReadings = 1; }), StartsWith("restingReadings:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.minCutoffHz = 0; }), StartsWith("minCutoffHz:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.betaHzPerMmPerS = -1; }), StartsWith("betaHzPerMmPerS:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.derivativeCutoffHz = 0; }),
                StartsWith("derivativeCutoffHz:"));
    EXPECT_THAT(problem([](TrackerOptions& o) { o.maxTracks = kMaxContacts - 1; }), StartsWith("maxTracks:"));
    TrackerOptions bad;
    bad.maxTracks = 3;
    EXPECT_THROW(ContactTracker{bad}, std::invalid_argument);
}

TEST(ContactTracker, BadInputIsNamed) {
    Feed feed;
    feed({finger({10, 10}, 5)});
    Contacts contacts;
    ContactTracker& tracker = feed.tracker();
    auto message = [&](auto call) -> std::string {
        try {
            call();
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "no exception";
    };
    using ::testing::HasSubstr;
    EXPECT_THAT(message([&] { tracker.update(feed.timeUs(), {}, kTouchMm, kPxPerMm, contacts); }),
                HasSubstr("is not after the previous frame's"));
    const std::int64_t next = feed.timeUs() + kFrameUs;
    EXPECT_THAT(message([&] { tracker.update(next, {}, kTouchMm, 0.0, contacts); }),
                HasSubstr("display scale"));
    EXPECT_THAT(message([&] { tracker.update(next, {}, NAN, kPxPerMm, contacts); }),
                HasSubstr("touch height"));
    EXPECT_THAT(
        message([&] {
            tracker.update(next, {finger({1, 1}, 0), finger({NAN, 1}, 0)}, kTouchMm, kPxPerMm, contacts);
        }),
        HasSubstr("observation 1 has a non-finite position"));
    EXPECT_THAT(message([&] {
                    tracker.update(next, {finger({1, 1}, INFINITY)}, kTouchMm, kPxPerMm, contacts);
                }),
                HasSubstr("observation 0 has a non-finite pad height"));
    EXPECT_THAT(message([&] {
                    tracker.update(next, {finger({1, 1}, 0, -1)}, kTouchMm, kPxPerMm, contacts);
                }),
                HasSubstr("observation 0 has a height uncertainty"));
    // Rejected frames change nothing: the next good one goes on from the first frame.
    tracker.update(next, {finger({10, 10}, 5)}, kTouchMm, kPxPerMm, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_EQ(contacts[0].id, 1u);
}

TEST(ContactTracker, NewFingersGetIncreasingIdsThatLastWhileTracked) {
    Feed feed;
    EXPECT_THAT(feed.appear({finger({50, 50}, 8)}), ::testing::SizeIs(1));
    EXPECT_EQ(feed.contacts()[0].id, 1u);
    // A second finger is reported from the second frame it is seen in.
    EXPECT_THAT(feed({finger({51, 50}, 8), finger({120, 80}, 8)}), ::testing::SizeIs(1));
    feed({finger({51, 50}, 8), finger({120, 80}, 8)});
    ASSERT_EQ(feed.contacts().size(), 2u);
    EXPECT_EQ(feed.contacts()[0].id, 1u);
    EXPECT_EQ(feed.contacts()[1].id, 2u);
    EXPECT_FALSE(feed.contacts()[0].touching);
    EXPECT_DOUBLE_EQ(feed.contacts()[0].heightMm, 8.0);
    // The first finger leaves for good; coming back later it is a new finger.
    for (int f = 0; f < 5; ++f)
        feed({finger({120, 80}, 8)});
    ASSERT_EQ(feed.contacts().size(), 1u);
    EXPECT_EQ(feed.contacts()[0].id, 2u);
    feed.appear({finger({120, 80}, 8), finger({51, 50}, 8)});
    EXPECT_EQ(feed.contacts()[1].id, 3u);
}

TEST(ContactTracker, AFingertipSeenInOneFrameAloneIsNoContact) {
    // The projected content changing between a pair's two frames draws edges in S that the segmentation may
    // take for a fingertip, in that pair alone: hovering or touching, nothing is reported.
    Feed feed;
    EXPECT_TRUE(feed({finger({50, 50}, 8)}).empty());
    for (int f = 0; f < 4; ++f)
        EXPECT_TRUE(feed({}).empty()) << "frame " << f;
    EXPECT_TRUE(feed({finger({90, 50}, 0)}).empty());
    for (int f = 0; f < 4; ++f)
        EXPECT_TRUE(feed({}).empty()) << "frame " << f;
    // Seen again within the frames a track outlives unseen, it is reported: a finger missed for a frame.
    feed({finger({50, 50}, 8)});
    feed({});
    EXPECT_THAT(feed({finger({50, 50}, 8)}), ::testing::SizeIs(1));
}

TEST(ContactTracker, AMissedDetectionDoesNotEndATouch) {
    Feed feed;
    feed.appear({finger({60, 40}, 0)});
    ASSERT_TRUE(feed.contacts()[0].touching);
    const Contact before = feed.contacts()[0];
    // Two frames without the finger (maxMissedFrames): it is still there, touching, where it was.
    for (int f = 0; f < 2; ++f) {
        ASSERT_EQ(feed({}).size(), 1u);
        EXPECT_EQ(feed.contacts()[0], before);
    }
    feed({finger({61, 40}, 0)});
    ASSERT_EQ(feed.contacts().size(), 1u);
    EXPECT_EQ(feed.contacts()[0].id, before.id);
    EXPECT_TRUE(feed.contacts()[0].touching);
    // A third missed frame in a row ends it.
    feed({});
    feed({});
    EXPECT_EQ(feed({}).size(), 0u);
}

FingerObservation unmeasured(const Eigen::Vector2d& mm) {
    FingerObservation observation = finger(mm, 0.0);
    observation.heightKnown = false;
    return observation;
}

TEST(ContactTracker, AFingertipWithoutAHeightKeepsItsTouchForAFewFramesThenLifts) {
    Feed feed;
    feed.appear({finger({60, 40}, 0)});
    ASSERT_TRUE(feed.contacts()[0].touching);
    const std::uint32_t id = feed.contacts()[0].id;
    // Found, but the code on it too faint for a height: it slides on, touching, for maxUnmeasuredFrames.
    for (int f = 1; f <= 2; ++f) {
        ASSERT_EQ(feed({unmeasured({60.0 + 5 * f, 40})}).size(), 1u);
        EXPECT_EQ(feed.contacts()[0].id, id);
        EXPECT_TRUE(feed.contacts()[0].touching) << "frame " << f;
        EXPECT_GT(millimetres(feed.contacts()[0]).x(), 60.0 + 5 * f - 5) << "it follows the finger";
    }
    // One more and it lifts; neither its height nor its place known, it is not reported.
    EXPECT_TRUE(feed({unmeasured({75, 40})}).empty());
    // Measured on the table again: a touch again, of the same finger, which kept its id.
    feed({finger({76, 40}, 0)});
    feed({finger({77, 40}, 0)});
    EXPECT_EQ(feed.contacts()[0].id, id);
    EXPECT_TRUE(feed.contacts()[0].touching);
}

TEST(ContactTracker, AFingertipWhoseCodeFavoursTheTableStaysDownWithoutAHeight) {
    Feed feed;
    feed.appear({finger({60, 40}, 0)});
    ASSERT_TRUE(feed.contacts()[0].touching);
    // A slide whose code is too faint for a height but still matches the table better than anything higher:
    // it does not count towards the frames that lift a touch.
    for (int f = 1; f <= 6; ++f) {
        FingerObservation sliding = unmeasured({60.0 + 2 * f, 40});
        sliding.codeFavoursTable = true;
        ASSERT_EQ(feed({sliding}).size(), 1u);
        EXPECT_TRUE(feed.contacts()[0].touching) << "frame " << f;
    }
    // Without that lean, three such frames lift it (and, without a height, it is no longer reported).
    for (int f = 1; f <= 2; ++f)
        feed({unmeasured({72.0 + 2 * f, 40})});
    ASSERT_EQ(feed.contacts().size(), 1u);
    EXPECT_TRUE(feed.contacts()[0].touching);
    EXPECT_TRUE(feed({unmeasured({78, 40})}).empty());
}

TEST(ContactTracker, AHoveringFingerWithoutAHeightIsReportedAgainOnlyOnceItHasOne) {
    Feed feed;
    feed.appear({finger({60, 40}, 10.0)});
    ASSERT_EQ(feed.contacts().size(), 1u);
    const std::uint32_t id = feed.contacts()[0].id;
    // A rising finger whose code the pair's two frames do not agree on: its last height holds for as many
    // frames as a touch outlives without one...
    for (int f = 1; f <= TrackerOptions{}.maxUnmeasuredFrames; ++f) {
        ASSERT_EQ(feed({unmeasured({60, 40})}).size(), 1u) << "frame " << f;
        EXPECT_EQ(feed.contacts()[0].heightMm, 10.0);
    }
    // ...and then it is not reported at that height any more, however long it stays in view.
    for (int f = 0; f < 10; ++f)
        EXPECT_TRUE(feed({unmeasured({60, 40})}).empty()) << "frame " << f;
    // Its height read again, it is back, as the same finger.
    ASSERT_EQ(feed({finger({60, 40}, 30.0)}).size(), 1u);
    EXPECT_EQ(feed.contacts()[0].id, id);
    EXPECT_EQ(feed.contacts()[0].heightMm, 30.0);
    EXPECT_FALSE(feed.contacts()[0].touching);
}

TEST(ContactTracker, AHeightAboveTheTouchHeightThenNoCodeNearTheTableLiftsAtOnce) {
    Feed feed;
    feed.appear({finger({60, 40}, 0)});
    ASSERT_TRUE(feed.contacts()[0].touching);
    // Above the touch height but within the band: still touching.
    feed({finger({60, 40}, kTouchMm + 1.0)});
    ASSERT_TRUE(feed.contacts()[0].touching);
    // A lean to the table keeps it down.
    FingerObservation leaning = unmeasured({60, 40});
    leaning.codeFavoursTable = true;
    feed({leaning});
    EXPECT_TRUE(feed.contacts()[0].touching);
    // Seen above the touch height again, then no code near the table: it has left.
    feed({finger({60, 40}, kTouchMm + 1.0)});
    ASSERT_TRUE(feed.contacts()[0].touching);
    feed({unmeasured({60, 40})});
    EXPECT_FALSE(feed.contacts()[0].touching);
}

TEST(ContactTracker, APendingTouchDownOutlivesNoMoreFramesWithoutAHeightThanATouchDoes) {
    const int frames = TrackerOptions{}.maxUnmeasuredFrames;
    // One frame just below the touch height does not decide; a second low frame within as many frames
    // without a height as a touch outlives confirms it.
    Feed near;
    near({finger({60, 40}, 20)});
    near({finger({60, 40}, kTouchMm - 0.5)});
    ASSERT_FALSE(near.contacts()[0].touching);
    for (int f = 0; f < frames; ++f)
        near({unmeasured({60, 40})});
    near({finger({61, 40}, kTouchMm - 0.5)});
    EXPECT_TRUE(near.contacts()[0].touching);

    // One frame more without a height and the low frame is forgotten: the track, matched 40 mm away (a
    // fingertip of a hand's outline passing high), needs two low frames of its own.
    Feed far;
    far({finger({60, 40}, 20)});
    far({finger({60, 40}, kTouchMm - 0.5)});
    for (int f = 0; f <= frames; ++f)
        far({unmeasured({60, 40})});
    far({finger({100, 40}, kTouchMm - 0.5)});
    ASSERT_EQ(far.contacts().size(), 1u);
    EXPECT_FALSE(far.contacts()[0].touching);
    far({finger({100, 40}, kTouchMm - 0.5)});
    EXPECT_TRUE(far.contacts()[0].touching);
}

TEST(ContactTracker, AFingertipWithoutAHeightStartsNoContact) {
    Feed feed;
    EXPECT_TRUE(feed.appear({unmeasured({60, 40})}).empty());
    EXPECT_TRUE(feed({unmeasured({60, 40})}).empty());
    EXPECT_EQ(feed.appear({finger({60, 40}, 20)}).size(), 1u);
}

TEST(ContactTracker, AJumpFasterThanAFingerIsAnotherFinger) {
    Feed feed;
    feed.appear({finger({60, 40}, 0)});
    // 2 m/s for one frame is 16.7 mm; 40 mm is no finger's move.
    feed.appear({finger({100, 40}, 0)});
    ASSERT_EQ(feed.contacts().size(), 2u);
    EXPECT_EQ(feed.contacts()[0].id, 1u);  // held for its grace frames
    EXPECT_EQ(feed.contacts()[1].id, 2u);
    EXPECT_TRUE(millimetres(feed.contacts()[1]).isApprox(Eigen::Vector2d(100, 40)));
}

TEST(ContactTracker, TwoFingersApproachingTo10MmAndPartingKeepTheirIds) {
    // A pinch and spread: the gap closes from 80 to 10 mm and opens again, 0.2 s a cycle, each finger up to
    // 0.55 m/s, slowing to a stop at the closest point as real fingers do.
    auto pinch = [](int i, int f) -> Eigen::Vector2d {
        const double gap = 45.0 + 35.0 * std::cos(2.0 * std::numbers::pi * f * kFrameS / 0.2);
        return Eigen::Vector2d(150.0 + (i == 0 ? -gap : gap) / 2.0, 100.0);
    };
    for (unsigned seed = 1; seed <= 10; ++seed)
        expectIdsKept(2, 240, pinch, seed);
    // The same with an abrupt turn at the closest point, at 0.3 m/s each way.
    auto abrupt = [](int i, int f) -> Eigen::Vector2d {
        const double travel = 0.3 * 1000.0 * kFrameS * std::abs(f - 60);  // closest (10 mm) at frame 60
        return Eigen::Vector2d(150.0 + (i == 0 ? -1.0 : 1.0) * (5.0 + travel), 100.0);
    };
    for (unsigned seed = 1; seed <= 10; ++seed)
        expectIdsKept(2, 120, abrupt, seed);
}

TEST(ContactTracker, FingersPassingEachOtherKeepTheirIds) {
    // Two hands swiping past each other on lines 12 mm apart (a finger's width), at up to 1.5 m/s each and
    // at every phase against the frames. At speed the pair swapped is nearer than the pair kept: each finger
    // moves 12.5 mm a frame, more than the 12 mm between the lines.
    for (const double speed : {750.0, 1500.0}) {
        for (const double phase : {0.0, 0.25, 0.5, 0.75}) {
            auto passing = [=](int i, int f) -> Eigen::Vector2d {
                const double x = speed * kFrameS * (f - 20 + phase);
                return Eigen::Vector2d(150.0 + (i == 0 ? x : -x), i == 0 ? 94.0 : 106.0);
            };
            for (unsigned seed = 1; seed <= 5; ++seed)
                expectIdsKept(2, 40, passing, seed);
        }
    }
    // Paths crossing at right angles, the second finger 17 mm behind the first, so that they pass the
    // crossing 12 mm apart (a finger's width), at up to 1.5 m/s and at every phase against the frames.
    for (const double speed : {500.0, 1000.0, 1500.0}) {
        for (const double phase : {0.0, 0.25, 0.5, 0.75}) {
            auto crossing = [=](int i, int f) -> Eigen::Vector2d {
                const double s = speed * kFrameS * (f - 20 + phase) - (i == 0 ? 0.0 : 17.0);
                return i == 0 ? Eigen::Vector2d(150.0 + s, 100.0) : Eigen::Vector2d(150.0, 100.0 + s);
            };
            for (unsigned seed = 1; seed <= 5; ++seed)
                expectIdsKept(2, 40, crossing, seed);
        }
    }
}

TEST(ContactTracker, TenFingersSpreadingKeepTheirIds) {
    // Ten fingertips on a circle 18 mm apart, spreading at 1 m/s to a circle four times as large.
    auto spread = [](int i, int f) -> Eigen::Vector2d {
        const double radius = std::min(29.0 + 1000.0 * kFrameS * f, 116.0);
        const double angle = 2.0 * std::numbers::pi * i / 10.0;
        return Eigen::Vector2d(140.0 + radius * std::cos(angle), 125.0 + radius * std::sin(angle));
    };
    for (unsigned seed = 1; seed <= 10; ++seed)
        expectIdsKept(10, 30, spread, seed);
}

TEST(ContactTracker, FastMovesSideBySideKeepTheirIds) {
    // Two fingers 18 mm apart moving together at 1.5 m/s (12.5 mm a frame), along the line joining them,
    // across it and diagonally, from rest.
    for (const double direction :
         {0.0, 0.25 * std::numbers::pi, 0.5 * std::numbers::pi, 0.8 * std::numbers::pi}) {
        auto fast = [direction](int i, int f) -> Eigen::Vector2d {
            const Eigen::Vector2d step =
                1500.0 * kFrameS * Eigen::Vector2d(std::cos(direction), std::sin(direction));
            return Eigen::Vector2d(60.0 + 18.0 * i, 120.0) + step * std::max(0, f - 5);
        };
        for (unsigned seed = 1; seed <= 5; ++seed)
            expectIdsKept(2, 20, fast, seed);
    }
}

TEST(ContactTracker, AFastFingerMissedForAFrameKeepsItsId) {
    // Side by side along the direction of travel at 1.5 m/s, the rear finger unseen for one frame: two
    // frames' travel (25 mm) is more than one frame's gate, so the gate must grow with the time since it was
    // seen.
    Feed feed;
    const double step = 1500.0 * kFrameS;
    std::uint32_t rearId = 0, frontId = 0;
    for (int f = 0; f < 30; ++f) {
        const Eigen::Vector2d rear(20.0 + step * f, 100.0), front = rear + Eigen::Vector2d(18.0, 0.0);
        if (f == 20)
            feed({finger(front, 0)});
        else
            feed({finger(rear, 0), finger(front, 0)});
        if (f == 0)
            continue;  // new fingers are reported from the second frame they are seen in
        ASSERT_EQ(feed.contacts().size(), 2u);
        if (f == 1) {
            rearId = feed.contacts()[0].id;
            frontId = feed.contacts()[1].id;
        }
        if (f == 20)
            continue;
        ASSERT_LT((millimetres(*withId(feed.contacts(), rearId)) - rear).norm(), 1.5) << "frame " << f;
        ASSERT_LT((millimetres(*withId(feed.contacts(), frontId)) - front).norm(), 1.5) << "frame " << f;
    }
}

TEST(ContactTracker, AtMostTenContactsAndTheOldestWin) {
    Feed feed;
    std::vector<FingerObservation> fingers;
    for (int i = 0; i < 12; ++i) {
        fingers.push_back(finger({20.0 + 20.0 * i, 50.0}, 0));
        feed(fingers);
    }
    ASSERT_EQ(feed.contacts().size(), 10u);
    for (std::uint32_t i = 0; i < 10; ++i)
        EXPECT_EQ(feed.contacts()[i].id, i + 1);
    // The second finger leaves: once its grace is over the eleventh takes its place.
    fingers.erase(fingers.begin() + 1);
    for (int f = 0; f < 3; ++f)
        feed(fingers);
    ASSERT_EQ(feed.contacts().size(), 10u);
    EXPECT_EQ(feed.contacts()[1].id, 3u);
    EXPECT_EQ(feed.contacts()[9].id, 11u);
    // More observations than tracks: the tracks already there go on, the rest start nothing.
    for (int i = 0; i < 20; ++i)
        fingers.push_back(finger({20.0 + 10.0 * i, 150.0}, 8));
    feed(fingers);
    ASSERT_EQ(feed.contacts().size(), 10u);
    EXPECT_EQ(feed.contacts()[0].id, 1u);
    EXPECT_EQ(feed.contacts()[9].id, 11u);
}

// Frames in which the first contact's touching state differs from the frame before.
int touchChanges(Feed& feed, const std::vector<double>& heights, double sigmaMm,
                 std::vector<bool>* states = nullptr) {
    int changes = 0;
    bool touching = false;
    // The finger came into view a frame before: a new track is reported from its second frame.
    if (!heights.empty())
        feed({finger({100, 100}, heights.front(), sigmaMm)});
    for (const double height : heights) {
        const Contacts& contacts = feed({finger({100, 100}, height, sigmaMm)});
        const bool now = !contacts.empty() && contacts[0].touching;
        changes += now != touching;
        touching = now;
        if (states)
            states->push_back(now);
    }
    return changes;
}

TEST(ContactTracker, AFingerRestingAtTheTouchHeightDoesNotFlicker) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
        std::mt19937 random(seed);
        std::normal_distribution<double> noise(kTouchMm, kSigmaMm);
        std::vector<double> heights;
        int crossings = 0;
        for (int f = 0; f < 1200; ++f) {
            heights.push_back(noise(random));
            crossings += f > 0 && (heights[f] <= kTouchMm) != (heights[f - 1] <= kTouchMm);
        }
        ASSERT_GT(crossings, 300) << "the heights should cross the threshold all the time";
        Feed feed;
        std::vector<bool> states;
        EXPECT_EQ(touchChanges(feed, heights, kSigmaMm, &states), 1) << "seed " << seed;
        EXPECT_TRUE(states.back());
    }
}

TEST(ContactTracker, ASingleFrameBlipDoesNotTouch) {
    // 2.5 mm is below the 3 mm touch height but not by a decisive 4 sigma = 2 mm.
    Feed feed;
    EXPECT_EQ(touchChanges(feed, {8, 8, 2.5, 8, 8, 2.5, 7, 2.5, 8}, kSigmaMm), 0);
    // Nor a single frame above the lift height (3 + 3 sigma = 4.5 mm) but not by 2 mm more.
    Feed resting;
    std::vector<bool> states;
    touchChanges(resting, {0, 0, 5.5, 0, 0, 6, 0.5}, kSigmaMm, &states);
    EXPECT_THAT(states, ::testing::Each(true));
}

TEST(ContactTracker, ATouchDownNeedsTwoFramesOrDecisiveEvidence) {
    std::vector<bool> states;
    Feed twoFrames;
    touchChanges(twoFrames, {8, 2.5, 2.5, 2.5}, kSigmaMm, &states);
    EXPECT_THAT(states, ::testing::ElementsAre(false, false, true, true));
    states.clear();
    Feed decisive;
    touchChanges(decisive, {8, 0.8, 0.8}, kSigmaMm, &states);  // 2.2 mm below: more than 4 sigma
    EXPECT_THAT(states, ::testing::ElementsAre(false, true, true));
    states.clear();
    // The same height with a vaguer estimate is not decisive.
    Feed vague;
    touchChanges(vague, {8, 0.8, 0.8}, 1.0, &states);
    EXPECT_THAT(states, ::testing::ElementsAre(false, false, true));
    states.clear();
    // A frame without the finger neither confirms nor cancels.
    Feed missed;
    missed({finger({100, 100}, 8)});
    missed({finger({100, 100}, 2.5)});
    EXPECT_FALSE(missed({})[0].touching);
    EXPECT_TRUE(missed({finger({100, 100}, 2.5)})[0].touching);
}

TEST(ContactTracker, ALiftNeedsTwoFramesRunning) {
    std::vector<bool> states;
    Feed twoFrames;
    touchChanges(twoFrames, {0, 5.0, 5.0, 5.0}, kSigmaMm, &states);  // above 4.5 mm
    EXPECT_THAT(states, ::testing::ElementsAre(true, true, false, false));
    states.clear();
    // However far above the band, one frame alone is no lift: a resting fingertip read 10 mm up for a
    // frame stays down.
    Feed far;
    touchChanges(far, {0, 0, 10.0, 0, 0, 10.0, 10.0}, kSigmaMm, &states);
    EXPECT_THAT(states, ::testing::ElementsAre(true, true, true, true, true, true, false));
    states.clear();
    // Between the touch height and the lift height the finger stays down.
    Feed band;
    touchChanges(band, {0, 4.0, 4.4, 3.5, 4.5}, kSigmaMm, &states);
    EXPECT_THAT(states, ::testing::Each(true));
}

TEST(ContactTracker, AHeightNoFingerReachesInTheTimeIsIgnored) {
    std::vector<bool> states;
    // 35 mm within a frame is 4 m/s: a false reading, not a lift (two of them running would be one).
    // The second, two frames after the last plausible height, would still be 2.1 m/s.
    Feed feed;
    touchChanges(feed, {0, 35.0, 35.5, 0}, kSigmaMm, &states);
    EXPECT_THAT(states, ::testing::Each(true));
    // A finger rising at 1.2 m/s lifts.
    states.clear();
    Feed rising;
    touchChanges(rising, {0, 10.0, 20.0, 30.0}, kSigmaMm, &states);
    EXPECT_THAT(states, ::testing::ElementsAre(true, true, false, false));
}

TEST(ContactTracker, TheTouchHeightIsTakenEachFrame) {
    Feed feed;
    feed.appear({finger({100, 100}, 5, 0.2)});
    EXPECT_FALSE(feed.contacts()[0].touching);
    // A more sensitive setting: 5 mm is now 5 mm below it.
    EXPECT_TRUE(feed({finger({100, 100}, 5, 0.2)}, 10.0)[0].touching);
}

// Heights of a finger coming down at 150 mm/s (1.25 mm a frame) from 15 mm onto the table, then resting
// there.
std::vector<double> landing(int frames) {
    std::vector<double> heights;
    for (int f = 0; f < frames; ++f)
        heights.push_back(std::max(0.0, 15.0 - 1.25 * f));
    return heights;
}

TEST(ContactTracker, ATouchIsReportedAtMostOneFrameLate) {
    const std::vector<double> truth = landing(40);
    const int crossed = static_cast<int>(
        std::find_if(truth.begin(), truth.end(), [](double h) { return h <= kTouchMm; }) - truth.begin());
    const int landed = static_cast<int>(std::find(truth.begin(), truth.end(), 0.0) - truth.begin());
    ASSERT_LT(crossed, landed);

    // Exact heights: the first frame at or below the touch height is not decisive, the next confirms it.
    Feed exact;
    std::vector<bool> states;
    touchChanges(exact, truth, kSigmaMm, &states);
    const int reported = static_cast<int>(std::find(states.begin(), states.end(), true) - states.begin());
    EXPECT_EQ(reported, crossed + 1);

    // Noisy heights: the finger is reported touching by the frame after it lands, whatever the noise.
    for (unsigned seed = 1; seed <= 200; ++seed) {
        std::mt19937 random(seed);
        std::normal_distribution<double> noise(0.0, kSigmaMm);
        std::vector<double> heights = truth;
        for (double& h : heights)
            h += noise(random);
        Feed feed;
        states.clear();
        touchChanges(feed, heights, kSigmaMm, &states);
        const int first = static_cast<int>(std::find(states.begin(), states.end(), true) - states.begin());
        EXPECT_LE(first, landed + 1) << "seed " << seed;
        EXPECT_TRUE(std::all_of(states.begin() + first, states.end(), [](bool s) { return s; }))
            << "seed " << seed;
    }
}

TEST(ContactTracker, ALiftIsReportedAtMostOneFrameLate) {
    std::vector<double> truth = landing(40);
    std::reverse(truth.begin(), truth.end());
    const double liftMm = kTouchMm + 3.0 * kSigmaMm;
    const int crossed = static_cast<int>(
        std::find_if(truth.begin(), truth.end(), [&](double h) { return h > liftMm; }) - truth.begin());
    Feed feed;
    std::vector<bool> states;
    touchChanges(feed, truth, kSigmaMm, &states);
    const int lifted = static_cast<int>(std::find(states.begin(), states.end(), false) - states.begin());
    EXPECT_GE(lifted, crossed);
    EXPECT_LE(lifted, crossed + 1);
}

// The pipeline's uncertainty covers every finger's thickness (2 mm, one standard deviation), so the band of
// three of them would hold a rising finger down to past 9 mm. Resting, a finger's own readings here lie at
// 0.8 mm with 0.4 mm of noise; rising at 2 mm a frame it lifts at the second frame above 0.8 + 3 + 1.2 mm
// instead.
TEST(ContactTracker, ARestedFingerLiftsAgainstItsOwnLevelAndNoise) {
    constexpr double kPipelineSigmaMm = 2.1;
    std::mt19937 random(5);
    std::normal_distribution<double> noise(0.8, 0.4);
    std::vector<double> heights;
    for (int f = 0; f < 40; ++f)
        heights.push_back(noise(random));
    for (int f = 1; f <= 8; ++f)
        heights.push_back(0.8 + 2.0 * f);  // 2.8, 4.8, 6.8, ...
    std::vector<bool> states;
    Feed feed;
    EXPECT_EQ(touchChanges(feed, heights, kPipelineSigmaMm, &states), 2);
    const int lifted = static_cast<int>(std::find(states.begin() + 1, states.end(), false) - states.begin());
    EXPECT_EQ(heights[lifted], 6.8) << "lifted at frame " << lifted;

    // Before it has rested long enough to tell, the pipeline's uncertainty rules: the band is 6.3 mm.
    TrackerOptions unlearned;
    unlearned.restingReadings = 100;
    Feed early(unlearned);
    states.clear();
    touchChanges(early, heights, kPipelineSigmaMm, &states);
    const int liftedEarly =
        static_cast<int>(std::find(states.begin() + 1, states.end(), false) - states.begin());
    EXPECT_GT(heights[liftedEarly], 3.0 + 3.0 * kPipelineSigmaMm);
}

// A finger resting with noisy readings stays down for a minute at 120 Hz: its band follows its noise.
TEST(ContactTracker, ARestingFingerWithItsOwnNoiseDoesNotLift) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
        std::mt19937 random(seed);
        std::normal_distribution<double> noise(1.5, 1.0);
        std::vector<double> heights;
        for (int f = 0; f < 7200; ++f)
            heights.push_back(std::max(0.0, noise(random)));
        heights[0] = 0.0;
        Feed feed;
        EXPECT_EQ(touchChanges(feed, heights, 2.2), 1) << "seed " << seed;
    }
}

TEST(ContactTracker, JitterOfARestingFingerIsCutThreefold) {
    std::mt19937 random(5);
    std::normal_distribution<double> jitter(0.0, 0.5);
    Feed feed;
    double observedSquares = 0.0, reportedSquares = 0.0;
    int frames = 0;
    const Eigen::Vector2d rest(130.0, 90.0);
    for (int f = 0; f < 2400; ++f) {
        const Eigen::Vector2d seen = rest + Eigen::Vector2d(jitter(random), jitter(random));
        const Contacts& contacts = feed({finger(seen, 0.0)});
        if (f == 0)
            continue;  // reported from the second frame it is seen in
        ASSERT_EQ(contacts.size(), 1u);
        ASSERT_EQ(contacts[0].id, 1u);
        if (f < 120)
            continue;
        ++frames;
        observedSquares += (seen - rest).squaredNorm();
        reportedSquares += (millimetres(contacts[0]) - rest).squaredNorm();
    }
    const double reduction = std::sqrt(observedSquares / reportedSquares);
    EXPECT_GE(reduction, 3.0);
}

// Lag behind the truth along the direction of travel, mm, in each frame of a 0.5 m/s move that starts
// `restFrames` after the touch-down.
std::vector<double> lagOfAMove(int restFrames) {
    Feed feed;
    std::vector<double> lag;
    const Eigen::Vector2d start(40.0, 60.0), direction = Eigen::Vector2d(3.0, 4.0).normalized();
    for (int f = -restFrames; f < 20; ++f) {
        const Eigen::Vector2d truth = start + direction * 500.0 * kFrameS * std::max(0, f);
        const Contacts& contacts = feed({finger(truth, 0.0)});
        if (f > 0)
            lag.push_back((truth - millimetres(contacts[0])).dot(direction));
    }
    return lag;
}

TEST(ContactTracker, AFingerMovingAtHalfAMetreASecondLagsLessThan1MmAfterFiveFrames) {
    for (const int restFrames : {0, 1, 60}) {
        const std::vector<double> lag = lagOfAMove(restFrames);
        for (std::size_t f = 5; f < lag.size(); ++f)
            EXPECT_LT(lag[f - 1], 1.0) << "frame " << f << " of the move, after " << restFrames << " at rest";
    }
}

TEST(ContactTracker, ATouchStartsAtItsMeasuredPoint) {
    std::mt19937 random(9);
    std::normal_distribution<double> jitter(0.0, 0.5);
    Feed feed;
    for (int f = 0; f < 60; ++f)
        feed({finger(Eigen::Vector2d(80, 80) + Eigen::Vector2d(jitter(random), jitter(random)), 8.0)});
    // The hovering finger's filter sits at its mean; the touch starts where the finger is seen now.
    const Eigen::Vector2d down(82.0, 79.0);
    const Contacts& contacts = feed({finger(down, 0.0)});
    ASSERT_TRUE(contacts[0].touching);
    EXPECT_EQ(contacts[0].x, down.x() * kPxPerMm);
    EXPECT_EQ(contacts[0].y, down.y() * kPxPerMm);
}

TEST(ContactTracker, APalmIsNeverATouch) {
    Feed feed;
    for (int f = 0; f < 30; ++f) {
        // Resting on the table, and for a few frames read as a finger.
        const bool misread = f >= 10 && f < 14;
        const Contacts& contacts =
            feed.appear({misread ? finger({150, 180}, 0.0) : palm({150, 180}), finger({60, 60}, 10.0)});
        ASSERT_EQ(contacts.size(), 2u);
        EXPECT_EQ(contacts[0].id, 1u);
        EXPECT_TRUE(contacts[0].palm) << "frame " << f;
        EXPECT_FALSE(contacts[0].touching) << "frame " << f;
        EXPECT_DOUBLE_EQ(contacts[0].heightMm, 0.0);
        EXPECT_FALSE(contacts[1].palm);
    }
}

TEST(ContactTracker, ATouchTurningIntoAPalmKeepsItsSlotAsAPalm) {
    Feed feed;
    feed.appear({finger({150, 180}, 0.0)});
    ASSERT_TRUE(feed.contacts()[0].touching);
    const std::uint32_t id = feed.contacts()[0].id;
    // The hand flattens: the detection now sees a palm there.
    for (int f = 0; f < 10; ++f) {
        const Contacts& contacts = feed({palm({152, 184})});
        ASSERT_EQ(contacts.size(), 1u);
        EXPECT_EQ(contacts[0].id, id);
        EXPECT_TRUE(contacts[0].palm);
        EXPECT_TRUE(contacts[0].touching);
    }
    // Read as a finger again, it stays a palm; lifted, it is released like any touch.
    EXPECT_TRUE(feed({finger({152, 184}, 0.0)})[0].palm);
    feed({palm({152, 184}, 9.0)});
    const Contacts& lifted = feed({palm({152, 184}, 9.0)});
    EXPECT_TRUE(lifted[0].palm);
    EXPECT_FALSE(lifted[0].touching);
    EXPECT_FALSE(feed({palm({152, 184}, 0.0)})[0].touching);
}

TEST(ContactTracker, ResetForgetsEveryContact) {
    Feed feed;
    feed.appear({finger({50, 50}, 0), finger({90, 50}, 0)});
    feed.tracker().reset();
    Contacts contacts;
    // Any timestamp is taken after a reset, even an earlier one; the fingers come back with new ids.
    feed.tracker().update(1000, {finger({50, 50}, 0)}, kTouchMm, kPxPerMm, contacts);
    EXPECT_TRUE(contacts.empty());
    feed.tracker().update(1000 + kFrameUs, {finger({50, 50}, 0)}, kTouchMm, kPxPerMm, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_EQ(contacts[0].id, 3u);
}

TEST(ContactTracker, AllocatesNothingOnceRunning) {
    std::mt19937 random(2);
    std::normal_distribution<double> jitter(0.0, 0.5);
    Feed feed;
    std::vector<FingerObservation> fingers;
    fingers.reserve(16);
    auto frame = [&](int f) {
        fingers.clear();
        for (int i = 0; i < 10; ++i) {
            // Fingers circling; one at a time lifts out of view for a while, and a palm comes and goes.
            if ((f / 40) % 10 == i && f % 40 >= 20)
                continue;
            const double angle = 2.0 * std::numbers::pi * i / 10.0 + 0.01 * f;
            const Eigen::Vector2d at(140.0 + 60.0 * std::cos(angle), 120.0 + 60.0 * std::sin(angle));
            fingers.push_back(finger(at + Eigen::Vector2d(jitter(random), jitter(random)),
                                     kTouchMm + 2.0 * std::sin(0.05 * f + i)));
        }
        if (f % 100 < 50)
            fingers.push_back(palm({140.0, 120.0}));
        feed(fingers);
    };
    for (int f = 0; f < 200; ++f)
        frame(f);
    const std::uint64_t before = test::allocationCount();
    for (int f = 200; f < 1200; ++f)
        frame(f);
    EXPECT_EQ(test::allocationCount() - before, 0u);
}

}  // namespace
}  // namespace everytouch::core

// The tracker's contacts through the touchscreen's encoder: what a desktop makes of palms.
#include <linux/input.h>

#include <array>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/contact_tracker.h"
#include "io/multitouch_encoder.h"

namespace everytouch::io {
namespace {

static_assert(core::kMaxContacts == MultitouchEncoder::kSlotCount,
              "the tracker reports as many contacts as the touchscreen has slots");

// The paper-like rig: 1280 x 960 px over 276.5 x 251.6 mm, a 120 Hz camera, a 3 mm touch height.
constexpr double kPxPerMm = 1280.0 / 276.5;
constexpr std::int64_t kFrameUs = 8333;
constexpr double kTouchMm = 3.0;

core::FingerObservation observedFinger(double xMm, double yMm, double heightMm) {
    return {Eigen::Vector2d(xMm, yMm) * kPxPerMm, heightMm, 0.5, false};
}

core::FingerObservation observedPalm(double xMm, double yMm, double heightMm = 0.0) {
    return {Eigen::Vector2d(xMm, yMm) * kPxPerMm, heightMm, 0.5, true};
}

// Reads the events the way libinput's touchscreen handling does: a tracking id arriving in a slot whose tool
// is a finger is a touch down, one arriving as a palm is ignored; a finger's slot turning into a palm cancels
// its touch; the release of a finger's slot is a touch up.
class TouchReader {
public:
    void read(const std::vector<EvdevEvent>& events) {
        for (const EvdevEvent& event : events) {
            if (event.type == EV_KEY && event.code == BTN_TOUCH)
                buttonTouch = event.value;
            if (event.type != EV_ABS)
                continue;
            Slot& slot = slots_[current_];
            switch (event.code) {
                case ABS_MT_SLOT:
                    current_ = event.value;
                    break;
                case ABS_MT_TOOL_TYPE:
                    slot.tool = event.value;
                    if (slot.down && slot.tool == MT_TOOL_PALM) {
                        slot.down = false;
                        ++cancels;
                    }
                    break;
                case ABS_MT_TRACKING_ID:
                    if (event.value >= 0 && slot.tool == MT_TOOL_FINGER) {
                        slot.down = true;
                        ++downs;
                    } else if (event.value < 0 && slot.down) {
                        slot.down = false;
                        ++ups;
                    }
                    break;
                default:
                    break;
            }
        }
    }

    int downs = 0;
    int ups = 0;
    int cancels = 0;
    int buttonTouch = 0;

private:
    struct Slot {
        int tool = MT_TOOL_FINGER;
        bool down = false;  // a touch libinput has reported and not yet ended
    };
    std::array<Slot, MultitouchEncoder::kSlotCount> slots_{};
    int current_ = 0;
};

class TrackerToTouchscreen {
public:
    void frame(const std::vector<core::FingerObservation>& fingers) {
        timeUs_ += kFrameUs;
        tracker_.update(timeUs_, fingers, kTouchMm, kPxPerMm, contacts_);
        reader.read(encoder_.encode(timeUs_, contacts_));
        everButtonTouch = everButtonTouch || reader.buttonTouch;
    }

    TouchReader reader;
    bool everButtonTouch = false;

private:
    core::ContactTracker tracker_{core::TrackerOptions{}};
    MultitouchEncoder encoder_{TouchscreenAxes::forDisplay({1280, 960}, {276.5, 251.6})};
    core::Contacts contacts_;
    std::int64_t timeUs_ = 0;
};

TEST(ContactTrackerOnTheTouchscreen, APalmNeverTouches) {
    std::mt19937 random(4);
    std::normal_distribution<double> jitter(0.0, 1.0);
    TrackerToTouchscreen screen;
    for (int f = 0; f < 240; ++f) {
        // A palm resting on the table, read as a finger in a few frames; it then slides away and leaves.
        const double x = 150.0 + jitter(random) + (f > 200 ? 3.0 * (f - 200) : 0.0);
        const double y = 180.0 + jitter(random);
        const bool misread = f % 50 == 25 || f % 50 == 26;
        screen.frame({misread ? observedFinger(x, y, 0.0) : observedPalm(x, y)});
    }
    screen.frame({});
    EXPECT_EQ(screen.reader.downs, 0);
    EXPECT_FALSE(screen.everButtonTouch);
}

TEST(ContactTrackerOnTheTouchscreen, ATouchTurningIntoAPalmIsCancelledNotLifted) {
    TrackerToTouchscreen screen;
    // A finger comes down beside a resting palm, and a second finger touches elsewhere.
    for (int f = 0; f < 20; ++f)
        screen.frame(
            {observedPalm(60, 200), observedFinger(150, 120, 6.0 - 0.5 * f), observedFinger(220, 90, 0.0)});
    EXPECT_EQ(screen.reader.downs, 2);
    EXPECT_EQ(screen.reader.buttonTouch, 1);
    // The hand flattens: the first finger is now seen as part of a palm, then the hand lifts away.
    for (int f = 0; f < 20; ++f)
        screen.frame({observedPalm(60, 200), observedPalm(151, 121), observedFinger(220, 90, 0.0)});
    EXPECT_EQ(screen.reader.cancels, 1);
    EXPECT_EQ(screen.reader.ups, 0);
    EXPECT_EQ(screen.reader.buttonTouch, 1);  // the other finger still counts
    for (int f = 0; f < 5; ++f)
        screen.frame({observedFinger(220, 90, 0.0)});
    for (int f = 0; f < 5; ++f)
        screen.frame({});
    // Only the finger that stayed a finger was lifted; nothing else ever touched.
    EXPECT_EQ(screen.reader.downs, 2);
    EXPECT_EQ(screen.reader.cancels, 1);
    EXPECT_EQ(screen.reader.ups, 1);
    EXPECT_EQ(screen.reader.buttonTouch, 0);
}

}  // namespace
}  // namespace everytouch::io

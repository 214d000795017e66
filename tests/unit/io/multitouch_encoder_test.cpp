#include "io/multitouch_encoder.h"

#include <libevdev/libevdev.h>
#include <linux/input.h>

#include <map>
#include <random>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace everytouch::io {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;
using ::testing::Not;

// 1000x500 px over 500x250 mm: 50 units per pixel, so a contact at x px is at 50 x units.
TouchscreenAxes testAxes() {
    return TouchscreenAxes::forDisplay({1000, 500}, {500.0, 250.0});
}

core::Contact finger(std::uint32_t id, double x, double y) {
    return {id, x, y, true, 0.0, false};
}

core::Contact palm(std::uint32_t id, double x, double y) {
    return {id, x, y, true, 0.0, true};
}

core::Contact hovering(std::uint32_t id, double x, double y) {
    return {id, x, y, false, 8.0, false};
}

// "ABS_MT_TRACKING_ID 3": readable failures.
std::vector<std::string> named(const std::vector<EvdevEvent>& events) {
    std::vector<std::string> names;
    for (const EvdevEvent& event : events)
        names.push_back(std::string(libevdev_event_code_get_name(event.type, event.code)) + " " +
                        std::to_string(event.value));
    return names;
}

TEST(MultitouchEncoder, FirstTouchSendsOnlyWhatDiffersFromTheFreshDevice) {
    MultitouchEncoder encoder(testAxes());
    // Slot 0 is current and its tool type is already MT_TOOL_FINGER on a new device.
    EXPECT_THAT(
        named(encoder.encode(1000, {finger(7, 10, 20)})),
        ElementsAre("ABS_MT_TRACKING_ID 0", "ABS_MT_POSITION_X 500", "ABS_MT_POSITION_Y 1000", "BTN_TOUCH 1",
                    "BTN_TOOL_FINGER 1", "ABS_X 500", "ABS_Y 1000", "MSC_TIMESTAMP 1000", "SYN_REPORT 0"));
    EXPECT_EQ(encoder.activeSlots(), 1);
}

TEST(MultitouchEncoder, AnUnchangedFrameSendsNothing) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(7, 10, 20)});
    EXPECT_THAT(encoder.encode(8333, {finger(7, 10, 20)}), IsEmpty());
    EXPECT_THAT(encoder.encode(8333, {}), Not(IsEmpty()));
    EXPECT_THAT(encoder.encode(16666, {}), IsEmpty());
    EXPECT_THAT(encoder.encode(16666, {hovering(3, 5, 5)}), IsEmpty());
}

TEST(MultitouchEncoder, AMoveSendsOnlyTheChangedAxis) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(7, 10, 20)});
    EXPECT_THAT(named(encoder.encode(8333, {finger(7, 12, 20)})),
                ElementsAre("ABS_MT_POSITION_X 600", "ABS_X 600", "MSC_TIMESTAMP 8333", "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, ASecondFingerTakesTheNextSlotAndTheCountKey) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(7, 10, 20)});
    EXPECT_THAT(named(encoder.encode(8333, {finger(7, 10, 20), finger(9, 30, 40)})),
                ElementsAre("ABS_MT_SLOT 1", "ABS_MT_TRACKING_ID 1", "ABS_MT_POSITION_X 1500",
                            "ABS_MT_POSITION_Y 2000", "BTN_TOOL_FINGER 0", "BTN_TOOL_DOUBLETAP 1",
                            "MSC_TIMESTAMP 8333", "SYN_REPORT 0"));
    // Both move: slot 0 must be selected again.
    EXPECT_THAT(named(encoder.encode(16666, {finger(7, 11, 20), finger(9, 31, 40)})),
                ElementsAre("ABS_MT_SLOT 0", "ABS_MT_POSITION_X 550", "ABS_MT_SLOT 1",
                            "ABS_MT_POSITION_X 1550", "ABS_X 550", "MSC_TIMESTAMP 16666", "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, AVanishedContactIsReleasedInTheNextFrame) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(7, 10, 20), finger(9, 30, 40)});
    EXPECT_THAT(
        named(encoder.encode(8333, {finger(9, 30, 40)})),
        ElementsAre("ABS_MT_SLOT 0", "ABS_MT_TRACKING_ID -1", "BTN_TOOL_DOUBLETAP 0", "BTN_TOOL_FINGER 1",
                    "ABS_X 1500", "ABS_Y 2000", "MSC_TIMESTAMP 8333", "SYN_REPORT 0"));
    EXPECT_EQ(encoder.activeSlots(), 1);
}

TEST(MultitouchEncoder, AnEmptySetReleasesEverything) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(7, 10, 20), finger(9, 30, 40), palm(2, 90, 90)});
    EXPECT_THAT(named(encoder.encode(8333, {})),
                ElementsAre("ABS_MT_SLOT 0", "ABS_MT_TRACKING_ID -1", "ABS_MT_SLOT 1",
                            "ABS_MT_TRACKING_ID -1", "ABS_MT_SLOT 2", "ABS_MT_TRACKING_ID -1", "BTN_TOUCH 0",
                            "BTN_TOOL_DOUBLETAP 0", "MSC_TIMESTAMP 8333", "SYN_REPORT 0"));
    EXPECT_EQ(encoder.activeSlots(), 0);
}

TEST(MultitouchEncoder, TrackingIdsAreNeverReused) {
    MultitouchEncoder encoder(testAxes());
    std::vector<std::int32_t> ids;
    for (int touch = 0; touch < 5; ++touch) {
        for (const EvdevEvent& event : encoder.encode(touch * 2, {finger(1, 10, 10)}))
            if (event.code == ABS_MT_TRACKING_ID)
                ids.push_back(event.value);
        encoder.encode(touch * 2 + 1, {});
    }
    EXPECT_THAT(ids, ElementsAre(0, 1, 2, 3, 4));
}

TEST(MultitouchEncoder, TrackingIdsWrapAtTheKernelsRange) {
    MultitouchEncoder encoder(testAxes());
    std::int32_t last = -1;
    for (int touch = 0; touch <= MultitouchEncoder::kMaximumTrackingId + 1; ++touch) {
        for (const EvdevEvent& event : encoder.encode(touch * 2, {finger(1, 10, 10)}))
            if (event.code == ABS_MT_TRACKING_ID)
                last = event.value;
        encoder.encode(touch * 2 + 1, {});
        ASSERT_EQ(last, touch % (MultitouchEncoder::kMaximumTrackingId + 1));
    }
    EXPECT_EQ(last, 0);
}

TEST(MultitouchEncoder, ANewTouchInAUsedSlotSendsOnlyValuesThatDiffer) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(1, 10, 20)});
    encoder.encode(1, {});
    // The kernel kept x = 500 in slot 0 and would drop an unchanged value.
    EXPECT_THAT(named(encoder.encode(2, {finger(2, 10, 30)})),
                ElementsAre("ABS_MT_TRACKING_ID 1", "ABS_MT_POSITION_Y 1500", "BTN_TOUCH 1",
                            "BTN_TOOL_FINGER 1", "ABS_Y 1500", "MSC_TIMESTAMP 2", "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, HoveringFingersAreNotTouches) {
    MultitouchEncoder encoder(testAxes());
    EXPECT_THAT(encoder.encode(0, {hovering(1, 10, 10)}), IsEmpty());
    encoder.encode(1, {finger(1, 10, 10)});
    // Lifting into hover releases the slot; touching again is a new touch.
    EXPECT_THAT(named(encoder.encode(2, {hovering(1, 10, 10)})),
                ElementsAre("ABS_MT_TRACKING_ID -1", "BTN_TOUCH 0", "BTN_TOOL_FINGER 0", "MSC_TIMESTAMP 2",
                            "SYN_REPORT 0"));
    EXPECT_THAT(named(encoder.encode(3, {finger(1, 10, 10)})),
                ElementsAre("ABS_MT_TRACKING_ID 1", "BTN_TOUCH 1", "BTN_TOOL_FINGER 1", "MSC_TIMESTAMP 3",
                            "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, AFingerTurningIntoAPalmKeepsItsSlotAndStopsCounting) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(4, 10, 10)});
    EXPECT_THAT(named(encoder.encode(1, {palm(4, 10, 10)})),
                ElementsAre("ABS_MT_TOOL_TYPE 2", "BTN_TOUCH 0", "BTN_TOOL_FINGER 0", "MSC_TIMESTAMP 1",
                            "SYN_REPORT 0"));
    EXPECT_EQ(encoder.activeSlots(), 1);
    EXPECT_THAT(named(encoder.encode(2, {})),
                ElementsAre("ABS_MT_TRACKING_ID -1", "MSC_TIMESTAMP 2", "SYN_REPORT 0"));
    // The slot keeps MT_TOOL_PALM: the next finger there must set it back.
    EXPECT_THAT(named(encoder.encode(3, {finger(5, 10, 10)})),
                ElementsAre("ABS_MT_TOOL_TYPE 0", "ABS_MT_TRACKING_ID 1", "BTN_TOUCH 1", "BTN_TOOL_FINGER 1",
                            "MSC_TIMESTAMP 3", "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, APalmFromTheStartIsNoFinger) {
    MultitouchEncoder encoder(testAxes());
    EXPECT_THAT(named(encoder.encode(0, {palm(4, 10, 10)})),
                ElementsAre("ABS_MT_TOOL_TYPE 2", "ABS_MT_TRACKING_ID 0", "ABS_MT_POSITION_X 500",
                            "ABS_MT_POSITION_Y 500", "MSC_TIMESTAMP 0", "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, TheSingleTouchAxesFollowTheOldestFinger) {
    MultitouchEncoder encoder(testAxes());
    encoder.encode(0, {finger(9, 10, 10)});
    encoder.encode(1, {finger(9, 10, 10), finger(2, 20, 20)});
    EXPECT_THAT(
        named(encoder.encode(2, {finger(2, 20, 20)})),
        ElementsAre("ABS_MT_SLOT 0", "ABS_MT_TRACKING_ID -1", "BTN_TOOL_DOUBLETAP 0", "BTN_TOOL_FINGER 1",
                    "ABS_X 1000", "ABS_Y 1000", "MSC_TIMESTAMP 2", "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, CountKeysGoUpToFiveOrMore) {
    MultitouchEncoder encoder(testAxes());
    core::Contacts contacts;
    const std::vector<std::string> expectedKey = {"BTN_TOOL_FINGER 1", "BTN_TOOL_DOUBLETAP 1",
                                                  "BTN_TOOL_TRIPLETAP 1", "BTN_TOOL_QUADTAP 1",
                                                  "BTN_TOOL_QUINTTAP 1"};
    for (std::uint32_t id = 0; id < 7; ++id) {
        contacts.push_back(finger(id, 10.0 * id, 10));
        const std::vector<std::string> names = named(encoder.encode(id, contacts));
        const std::string& pressed = expectedKey[std::min<std::size_t>(id, 4)];
        EXPECT_EQ(std::count(names.begin(), names.end(), pressed), id < 5 ? 1 : 0) << "fingers: " << id + 1;
    }
}

TEST(MultitouchEncoder, MoreThanTenTouchesKeepTheLowestIdsAndTheRestWaitForAFreeSlot) {
    MultitouchEncoder encoder(testAxes());
    core::Contacts contacts;
    for (std::uint32_t id : {31u, 5u, 17u, 2u, 40u, 11u, 8u, 23u, 3u, 19u, 1u, 29u})
        contacts.push_back(finger(id, id, id));
    encoder.encode(0, contacts);
    EXPECT_EQ(encoder.activeSlots(), 10);
    // Ids 31 and 40 were left out; 40 stays out, 31 gets the slot freed by 1 one frame later.
    std::erase_if(contacts, [](const core::Contact& c) { return c.id == 1 || c.id == 40; });
    const std::vector<std::string> release = named(encoder.encode(1, contacts));
    EXPECT_EQ(std::count(release.begin(), release.end(), "ABS_MT_TRACKING_ID -1"), 1);
    EXPECT_EQ(encoder.activeSlots(), 9);
    const std::vector<std::string> next = named(encoder.encode(2, contacts));
    EXPECT_THAT(next, ::testing::Contains("ABS_MT_TRACKING_ID 10"));
    EXPECT_THAT(next, ::testing::Contains("ABS_MT_POSITION_X 1550"));
    EXPECT_EQ(encoder.activeSlots(), 10);
}

TEST(MultitouchEncoder, TheFirstOfContactsSharingAnIdCounts) {
    MultitouchEncoder encoder(testAxes());
    EXPECT_THAT(named(encoder.encode(0, {finger(3, 10, 10), finger(3, 90, 90)})),
                ::testing::Contains("ABS_MT_POSITION_X 500"));
    EXPECT_EQ(encoder.activeSlots(), 1);
}

TEST(MultitouchEncoder, ContactsWithoutAFinitePositionAreNotReported) {
    MultitouchEncoder encoder(testAxes());
    EXPECT_THAT(encoder.encode(0, {finger(3, std::nan(""), 10), finger(4, 10, INFINITY)}), IsEmpty());
}

TEST(MultitouchEncoder, PositionsAreClampedToTheScreen) {
    MultitouchEncoder encoder(testAxes());
    EXPECT_THAT(named(encoder.encode(0, {finger(3, -5, 900)})),
                ElementsAre("ABS_MT_TRACKING_ID 0", "ABS_MT_POSITION_Y 24999", "BTN_TOUCH 1",
                            "BTN_TOOL_FINGER 1", "ABS_Y 24999", "MSC_TIMESTAMP 0", "SYN_REPORT 0"));
}

TEST(MultitouchEncoder, TimestampsWrapAtThirtyTwoBits) {
    MultitouchEncoder encoder(testAxes());
    const std::vector<EvdevEvent>& events = encoder.encode((std::int64_t{1} << 32) + 5, {finger(1, 1, 1)});
    ASSERT_GE(events.size(), 2u);
    EXPECT_EQ(events[events.size() - 2], (EvdevEvent{EV_MSC, MSC_TIMESTAMP, 5}));
}

// Reads the events back the way the kernel and libevdev keep multitouch state, and checks after every report
// that the device shows exactly the touching contacts: random hands of up to 12 fingers that land, move,
// hover, turn into palms and vanish.
TEST(MultitouchEncoder, AReaderOfTheEventsSeesTheTouchingContactsAfterEveryReport) {
    const TouchscreenAxes axes = testAxes();
    MultitouchEncoder encoder(axes);
    struct ReaderSlot {
        std::int32_t trackingId = -1, x = 0, y = 0, tool = 0;
    };
    std::array<ReaderSlot, MultitouchEncoder::kSlotCount> reader;
    int readerSlot = 0;
    std::set<std::int32_t> trackingIdsSeen;
    std::map<std::int32_t, std::uint32_t> contactOfTrackingId;

    std::mt19937 random(7);
    std::map<std::uint32_t, core::Contact> hand;
    std::uint32_t nextId = 0;
    for (int frame = 0; frame < 3000; ++frame) {
        if (hand.size() < 12 && random() % 6 == 0) {
            const std::uint32_t id = nextId++;
            hand[id] = finger(id, random() % 1000, random() % 500);
        }
        for (auto it = hand.begin(); it != hand.end();) {
            core::Contact& c = it->second;
            const unsigned roll = random() % 100;
            if (roll < 3) {
                it = hand.erase(it);
                continue;
            }
            if (roll < 6)
                c.touching = !c.touching;
            else if (roll < 8)
                c.palm = !c.palm;
            c.x += static_cast<double>(random() % 21) - 10.0;
            c.y += static_cast<double>(random() % 21) - 10.0;
            ++it;
        }
        core::Contacts contacts;
        for (const auto& [id, c] : hand)
            contacts.push_back(c);
        std::shuffle(contacts.begin(), contacts.end(), random);

        const std::vector<EvdevEvent>& events = encoder.encode(frame, contacts);
        int reports = 0;
        int released = 0;
        for (const EvdevEvent& e : events) {
            ASSERT_EQ(reports, 0) << "events after SYN_REPORT in frame " << frame;
            if (e.type == EV_SYN)
                ++reports;
            if (e.type != EV_ABS)
                continue;
            ReaderSlot& slot = reader[readerSlot];
            switch (e.code) {
                case ABS_MT_SLOT:
                    ASSERT_NE(e.value, readerSlot) << "a slot announced twice";
                    readerSlot = e.value;
                    break;
                case ABS_MT_TRACKING_ID:
                    ASSERT_NE(e.value, slot.trackingId) << "an unchanged value was sent";
                    ASSERT_TRUE(e.value == -1 || slot.trackingId == -1) << "a held slot changed hands";
                    ASSERT_TRUE(e.value == -1 || trackingIdsSeen.insert(e.value).second)
                        << "tracking id reused";
                    slot.trackingId = e.value;
                    released += e.value == -1;
                    break;
                case ABS_MT_POSITION_X:
                    ASSERT_NE(e.value, slot.x);
                    slot.x = e.value;
                    break;
                case ABS_MT_POSITION_Y:
                    ASSERT_NE(e.value, slot.y);
                    slot.y = e.value;
                    break;
                case ABS_MT_TOOL_TYPE:
                    ASSERT_NE(e.value, slot.tool);
                    slot.tool = e.value;
                    break;
            }
        }
        ASSERT_EQ(reports, events.empty() ? 0 : 1);

        std::map<std::uint32_t, const core::Contact*> touching;
        for (const auto& [id, c] : hand)
            if (c.touching)
                touching[id] = &c;
        int held = 0;
        for (const ReaderSlot& slot : reader) {
            if (slot.trackingId < 0)
                continue;
            ++held;
            auto [known, added] = contactOfTrackingId.try_emplace(slot.trackingId, 0);
            if (added) {
                // A new touch: find the contact by position among those not yet on the device.
                for (const auto& [id, c] : touching)
                    if (axes.unitsX(c->x) == slot.x && axes.unitsY(c->y) == slot.y)
                        known->second = id;
            }
            const auto contact = touching.find(known->second);
            ASSERT_NE(contact, touching.end()) << "frame " << frame << ": a lifted contact is still down";
            EXPECT_EQ(slot.x, axes.unitsX(contact->second->x));
            EXPECT_EQ(slot.y, axes.unitsY(contact->second->y));
            EXPECT_EQ(slot.tool, contact->second->palm ? MT_TOOL_PALM : MT_TOOL_FINGER);
        }
        EXPECT_EQ(held, encoder.activeSlots());
        // Everything touching is down, except beyond ten touches and where a slot freed in this frame is due.
        const int touches = static_cast<int>(touching.size());
        EXPECT_LE(touches - held, std::max(0, touches - MultitouchEncoder::kSlotCount) + released)
            << "frame " << frame;
    }
    EXPECT_GT(trackingIdsSeen.size(), 200u);
}

}  // namespace
}  // namespace everytouch::io

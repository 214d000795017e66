#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/contact.h"
#include "io/touchscreen_axes.h"

namespace everytouch::io {

// One input event as written to uinput and read from /dev/input/eventN, without its time.
struct EvdevEvent {
    std::uint16_t type = 0;
    std::uint16_t code = 0;
    std::int32_t value = 0;

    bool operator==(const EvdevEvent&) const = default;
};

// Turns the complete set of contacts after each frame into the events of the kernel's multitouch protocol B
// (Documentation/input/multi-touch-protocol.rst) for a direct touchscreen with `kSlotCount` slots.
//
// Only what changed is sent, and exactly as the kernel forwards it: the encoder mirrors the device state the
// kernel keeps (slot values persist after a release, the current slot is announced before the first value
// that changes in it), so a reader of the event node receives these events one for one.
//
// - Touching contacts occupy slots; hovering ones are not part of a touchscreen and are left out.
// - A contact keeps its slot while it touches. Contacts that vanish or lift are released in the same frame.
// - A new touch gets the lowest slot that was free before the frame (a slot is never handed from one contact
//   to another within a frame). With more than `kSlotCount` touches, new contacts are taken in ascending id
//   order and the rest wait, unreported, until a slot is free. Of several contacts sharing an id, the first
//   counts. A contact with a non-finite position is not reported.
// - Every touch gets the next tracking id; they wrap after 65536 touches, so no id repeats within that many
//   touches of the device.
// - A palm keeps its slot with tool type MT_TOOL_PALM: libinput cancels a touch that turns into a palm and
//   ignores one that starts as a palm. A new touch sets the slot's tool type before its tracking id. Palms do
//   not count as fingers: BTN_TOUCH, BTN_TOOL_FINGER ... BTN_TOOL_QUINTTAP (five or more) and the
//   single-touch ABS_X/ABS_Y (the oldest finger) follow fingers.
// - Each frame that changes anything ends with MSC_TIMESTAMP (microseconds, wrapping at 32 bits) and one
//   SYN_REPORT.
class MultitouchEncoder {
public:
    static constexpr int kSlotCount = 10;
    // The kernel gives every multitouch device tracking ids 0..65535, whatever the device asks for.
    static constexpr std::int32_t kMaximumTrackingId = 0xffff;

    explicit MultitouchEncoder(const TouchscreenAxes& axes);

    // The events that take the device from the previous frame to `contacts`; empty when nothing changed.
    // The list is reused by the next call.
    const std::vector<EvdevEvent>& encode(std::int64_t timestampUs, const core::Contacts& contacts);

    // Number of contacts holding a slot.
    int activeSlots() const;

    const TouchscreenAxes& axes() const { return axes_; }

private:
    // One slot as the kernel keeps it, plus which contact holds it.
    struct Slot {
        std::int32_t trackingId = -1;  // -1 while free
        std::uint32_t contactId = 0;   // meaningful while held
        std::uint64_t touchOrder = 0;  // when the touch began, to find the oldest finger
        std::int32_t x = 0;            // last ABS_MT_POSITION_X, units
        std::int32_t y = 0;            // last ABS_MT_POSITION_Y, units
        std::int32_t toolType = 0;     // last ABS_MT_TOOL_TYPE
        bool held() const { return trackingId >= 0; }
    };

    void collectTouches(const core::Contacts& contacts);
    bool touchesContain(std::uint32_t contactId) const;
    void emit(std::uint16_t type, std::uint16_t code, std::int32_t value);
    void emitSlotValue(int slot, std::uint16_t code, std::int32_t value, std::int32_t& current);
    void emitValue(std::uint16_t type, std::uint16_t code, std::int32_t value, std::int32_t& current);
    void moveSlotsTo(const std::array<Slot, kSlotCount>& target);
    void updateSingleTouch();

    TouchscreenAxes axes_;
    std::array<Slot, kSlotCount> slots_;
    int currentSlot_ = 0;  // ABS_MT_SLOT as the kernel last announced it
    std::int32_t nextTrackingId_ = 0;
    std::uint64_t nextTouchOrder_ = 0;
    std::int32_t singleX_ = 0;                   // last ABS_X
    std::int32_t singleY_ = 0;                   // last ABS_Y
    std::int32_t touchKey_ = 0;                  // last BTN_TOUCH
    std::array<std::int32_t, 5> countKeys_{};    // last BTN_TOOL_FINGER ... BTN_TOOL_QUINTTAP
    std::vector<const core::Contact*> touches_;  // this frame's reportable touches by ascending id, reused
    std::vector<EvdevEvent> events_;             // this frame's events, reused
};

}  // namespace everytouch::io

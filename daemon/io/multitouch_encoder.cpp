#include "io/multitouch_encoder.h"

#include <linux/input.h>

#include <algorithm>
#include <cmath>

namespace everytouch::io {

namespace {

// BTN_TOOL_* for one, two, three, four and five or more fingers.
constexpr std::array<std::uint16_t, 5> kFingerCountKeys = {
    BTN_TOOL_FINGER, BTN_TOOL_DOUBLETAP, BTN_TOOL_TRIPLETAP, BTN_TOOL_QUADTAP, BTN_TOOL_QUINTTAP};

bool byId(const core::Contact* a, const core::Contact* b) {
    return a->id < b->id;
}

}  // namespace

MultitouchEncoder::MultitouchEncoder(const TouchscreenAxes& axes) : axes_(axes) {
    touches_.reserve(2 * kSlotCount);
    events_.reserve(16 * kSlotCount);
}

int MultitouchEncoder::activeSlots() const {
    return static_cast<int>(
        std::count_if(slots_.begin(), slots_.end(), [](const Slot& s) { return s.held(); }));
}

void MultitouchEncoder::collectTouches(const core::Contacts& contacts) {
    touches_.clear();
    for (const core::Contact& contact : contacts)
        if (contact.touching && std::isfinite(contact.x) && std::isfinite(contact.y))
            touches_.push_back(&contact);
    // Stable, so that of several contacts sharing an id the first one listed stays.
    std::stable_sort(touches_.begin(), touches_.end(), byId);
    touches_.erase(std::unique(touches_.begin(), touches_.end(),
                               [](const core::Contact* a, const core::Contact* b) { return a->id == b->id; }),
                   touches_.end());
}

bool MultitouchEncoder::touchesContain(std::uint32_t contactId) const {
    core::Contact probe;
    probe.id = contactId;
    return std::binary_search(touches_.begin(), touches_.end(), &probe, byId);
}

const std::vector<EvdevEvent>& MultitouchEncoder::encode(std::int64_t timestampUs,
                                                         const core::Contacts& contacts) {
    events_.clear();
    collectTouches(contacts);

    std::array<Slot, kSlotCount> target = slots_;
    for (Slot& slot : target)
        if (slot.held() && !touchesContain(slot.contactId))
            slot.trackingId = -1;
    for (const core::Contact* touch : touches_) {
        auto held = std::find_if(target.begin(), target.end(),
                                 [&](const Slot& s) { return s.held() && s.contactId == touch->id; });
        if (held == target.end()) {
            // Only a slot free before this frame: a slot released now is not handed over in the same report.
            int free = 0;
            while (free < kSlotCount && (slots_[free].held() || target[free].held()))
                ++free;
            if (free == kSlotCount)
                continue;
            held = target.begin() + free;
            held->trackingId = nextTrackingId_;
            held->contactId = touch->id;
            held->touchOrder = nextTouchOrder_++;
            nextTrackingId_ = nextTrackingId_ == kMaximumTrackingId ? 0 : nextTrackingId_ + 1;
        }
        held->x = axes_.unitsX(touch->x);
        held->y = axes_.unitsY(touch->y);
        held->toolType = touch->palm ? MT_TOOL_PALM : MT_TOOL_FINGER;
    }
    moveSlotsTo(target);
    updateSingleTouch();

    if (!events_.empty()) {
        emit(EV_MSC, MSC_TIMESTAMP, static_cast<std::int32_t>(static_cast<std::uint32_t>(timestampUs)));
        emit(EV_SYN, SYN_REPORT, 0);
    }
    return events_;
}

void MultitouchEncoder::moveSlotsTo(const std::array<Slot, kSlotCount>& target) {
    for (int i = 0; i < kSlotCount; ++i) {
        Slot& slot = slots_[i];
        const Slot& wanted = target[i];
        if (!wanted.held()) {
            emitSlotValue(i, ABS_MT_TRACKING_ID, -1, slot.trackingId);
            continue;
        }
        // The tool type goes first: libinput classifies a new touch by the slot's tool type at the moment the
        // tracking id arrives, so a finger landing where a palm was would otherwise stay a palm.
        emitSlotValue(i, ABS_MT_TOOL_TYPE, wanted.toolType, slot.toolType);
        emitSlotValue(i, ABS_MT_TRACKING_ID, wanted.trackingId, slot.trackingId);
        slot.contactId = wanted.contactId;
        slot.touchOrder = wanted.touchOrder;
        emitSlotValue(i, ABS_MT_POSITION_X, wanted.x, slot.x);
        emitSlotValue(i, ABS_MT_POSITION_Y, wanted.y, slot.y);
    }
}

void MultitouchEncoder::updateSingleTouch() {
    const Slot* oldest = nullptr;
    int fingers = 0;
    for (const Slot& slot : slots_) {
        if (!slot.held() || slot.toolType != MT_TOOL_FINGER)
            continue;
        ++fingers;
        if (!oldest || slot.touchOrder < oldest->touchOrder)
            oldest = &slot;
    }
    emitValue(EV_KEY, BTN_TOUCH, fingers > 0, touchKey_);
    const int countIndex = std::min(fingers, static_cast<int>(kFingerCountKeys.size())) - 1;
    // The previous count is released before the new one is pressed.
    for (int k = 0; k < static_cast<int>(kFingerCountKeys.size()); ++k)
        if (k != countIndex)
            emitValue(EV_KEY, kFingerCountKeys[k], 0, countKeys_[k]);
    if (countIndex >= 0)
        emitValue(EV_KEY, kFingerCountKeys[countIndex], 1, countKeys_[countIndex]);
    if (oldest) {
        emitValue(EV_ABS, ABS_X, oldest->x, singleX_);
        emitValue(EV_ABS, ABS_Y, oldest->y, singleY_);
    }
}

void MultitouchEncoder::emit(std::uint16_t type, std::uint16_t code, std::int32_t value) {
    events_.push_back({type, code, value});
}

void MultitouchEncoder::emitSlotValue(int slot, std::uint16_t code, std::int32_t value,
                                      std::int32_t& current) {
    if (value == current)
        return;
    if (slot != currentSlot_) {
        emit(EV_ABS, ABS_MT_SLOT, slot);
        currentSlot_ = slot;
    }
    emit(EV_ABS, code, value);
    current = value;
}

void MultitouchEncoder::emitValue(std::uint16_t type, std::uint16_t code, std::int32_t value,
                                  std::int32_t& current) {
    if (value == current)
        return;
    emit(type, code, value);
    current = value;
}

}  // namespace everytouch::io

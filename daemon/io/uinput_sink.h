#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/calibration.h"
#include "io/evdev_handles.h"
#include "io/multitouch_encoder.h"
#include "io/touch_sink.h"

namespace everytouch::io {

// The virtual touchscreen: a uinput device that desktop applications see as a direct multitouch screen the
// size of the projected display (docs/virtual-touchscreen.md). The events come from MultitouchEncoder;
// this class only owns the device.
class UinputSink final : public TouchSink {
public:
    static constexpr const char* kDeviceName = "everytouch virtual touchscreen";
    static constexpr std::uint16_t kVendorId = 0x4554;  // "ET"; on BUS_VIRTUAL, apart from USB and PCI ids
    static constexpr std::uint16_t kProductId = 0x0001;
    static constexpr std::uint16_t kVersion = 1;

    // Creates the device for the calibrated display. Throws InputError when the calibration gives no usable
    // size, std::system_error when /dev/uinput cannot create it.
    explicit UinputSink(const core::Calibration& calibration);
    // Releases every contact, then removes the device.
    ~UinputSink() override;
    UinputSink(const UinputSink&) = delete;
    UinputSink& operator=(const UinputSink&) = delete;

    void publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts) override;

    // Replaces the device by one of the new size when the calibration changes the display's pixels or its
    // size on the table, after releasing every contact on the old one; returns whether it did. On failure
    // the old device stays, with no contact down.
    bool applyCalibration(const core::Calibration& calibration);

    const std::string& devnode() const { return devnode_; }  // /dev/input/eventN
    const std::string& syspath() const { return syspath_; }  // /sys/devices/virtual/input/inputN
    const TouchscreenAxes& axes() const { return encoder_->axes(); }

private:
    static UniqueLibevdevUinput createDevice(const TouchscreenAxes& axes);
    void adopt(UniqueLibevdevUinput device, const TouchscreenAxes& axes);
    // Lifts every contact; when any was down, waits for readers to take the lift before the device may go.
    void releaseAll();
    void write(const std::vector<EvdevEvent>& events);

    UniqueLibevdevUinput device_;
    std::unique_ptr<MultitouchEncoder> encoder_;
    std::string devnode_;
    std::string syspath_;
    std::int64_t lastTimestampUs_ = 0;
    bool writeFailing_ = false;  // a failed write was logged; the next success is logged too
};

}  // namespace everytouch::io

#include "io/uinput_sink.h"

#include <linux/input.h>

#include <chrono>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "io/log.h"

namespace everytouch::io {

namespace {

// Readers lose what they have not read when a device goes away (the kernel answers ENODEV at once); a few
// frames of any compositor let them read the lift first.
constexpr std::chrono::milliseconds kLiftDeliveryTime{50};

void enable(libevdev* description, unsigned type, unsigned code, const input_absinfo* absinfo = nullptr) {
    if (libevdev_enable_event_code(description, type, code, absinfo) != 0)
        throw std::logic_error("libevdev refused event type " + std::to_string(type) + " code " +
                               std::to_string(code));
}

input_absinfo axis(int maximum, int resolution) {
    input_absinfo info{};
    info.minimum = 0;
    info.maximum = maximum;
    info.resolution = resolution;
    return info;
}

}  // namespace

UinputSink::UinputSink(const core::Calibration& calibration) {
    const TouchscreenAxes axes =
        TouchscreenAxes::forDisplay(calibration.displaySize, calibration.displaySizeMm());
    adopt(createDevice(axes), axes);
}

UinputSink::~UinputSink() {
    releaseAll();
}

UniqueLibevdevUinput UinputSink::createDevice(const TouchscreenAxes& axes) {
    const UniqueLibevdev description(libevdev_new());
    if (!description)
        throw std::bad_alloc();
    libevdev* d = description.get();
    libevdev_set_name(d, kDeviceName);
    libevdev_set_id_bustype(d, BUS_VIRTUAL);
    libevdev_set_id_vendor(d, kVendorId);
    libevdev_set_id_product(d, kProductId);
    libevdev_set_id_version(d, kVersion);
    // A direct device with BTN_TOUCH and MT positions, and no pen or mouse button: udev's input_id calls that
    // a touchscreen.
    libevdev_enable_property(d, INPUT_PROP_DIRECT);
    for (unsigned key : {BTN_TOUCH, BTN_TOOL_FINGER, BTN_TOOL_DOUBLETAP, BTN_TOOL_TRIPLETAP, BTN_TOOL_QUADTAP,
                         BTN_TOOL_QUINTTAP})
        enable(d, EV_KEY, key);
    const input_absinfo x = axis(axes.maximumX, axes.resolutionX);
    const input_absinfo y = axis(axes.maximumY, axes.resolutionY);
    const input_absinfo slots = axis(MultitouchEncoder::kSlotCount - 1, 0);
    const input_absinfo trackingIds = axis(MultitouchEncoder::kMaximumTrackingId, 0);
    const input_absinfo toolTypes = axis(MT_TOOL_MAX, 0);
    enable(d, EV_ABS, ABS_X, &x);
    enable(d, EV_ABS, ABS_Y, &y);
    enable(d, EV_ABS, ABS_MT_SLOT, &slots);
    enable(d, EV_ABS, ABS_MT_TRACKING_ID, &trackingIds);
    enable(d, EV_ABS, ABS_MT_POSITION_X, &x);
    enable(d, EV_ABS, ABS_MT_POSITION_Y, &y);
    enable(d, EV_ABS, ABS_MT_TOOL_TYPE, &toolTypes);
    enable(d, EV_MSC, MSC_TIMESTAMP);

    libevdev_uinput* created = nullptr;
    const int result = libevdev_uinput_create_from_device(d, LIBEVDEV_UINPUT_OPEN_MANAGED, &created);
    if (result < 0)
        throw std::system_error(
            -result, std::generic_category(),
            "Failed to create the virtual touchscreen through /dev/uinput (needs the uinput "
            "kernel module and write access to /dev/uinput)");
    UniqueLibevdevUinput device(created);
    if (!libevdev_uinput_get_devnode(device.get()))
        throw std::runtime_error("The virtual touchscreen was created without an event node in /dev/input");
    return device;
}

void UinputSink::adopt(UniqueLibevdevUinput device, const TouchscreenAxes& axes) {
    device_ = std::move(device);
    encoder_ = std::make_unique<MultitouchEncoder>(axes);
    devnode_ = libevdev_uinput_get_devnode(device_.get());
    const char* syspath = libevdev_uinput_get_syspath(device_.get());
    syspath_ = syspath ? syspath : "";
    writeFailing_ = false;
}

void UinputSink::publish(std::uint64_t, std::int64_t timestampUs, const core::Contacts& contacts) {
    lastTimestampUs_ = timestampUs;
    write(encoder_->encode(timestampUs, contacts));
}

bool UinputSink::applyCalibration(const core::Calibration& calibration) {
    const TouchscreenAxes axes =
        TouchscreenAxes::forDisplay(calibration.displaySize, calibration.displaySizeMm());
    if (axes == encoder_->axes())
        return false;
    releaseAll();
    UniqueLibevdevUinput replacement = createDevice(axes);
    adopt(std::move(replacement), axes);
    return true;
}

void UinputSink::releaseAll() {
    const std::vector<EvdevEvent>& events = encoder_->encode(lastTimestampUs_, {});
    if (events.empty())
        return;
    write(events);
    std::this_thread::sleep_for(kLiftDeliveryTime);
}

void UinputSink::write(const std::vector<EvdevEvent>& events) {
    for (const EvdevEvent& event : events) {
        const int result = libevdev_uinput_write_event(device_.get(), event.type, event.code, event.value);
        if (result < 0) {
            if (!writeFailing_)
                ET_LOG(Error) << "Failed to write to the virtual touchscreen " << devnode_ << ": "
                              << std::strerror(-result);
            writeFailing_ = true;
            return;
        }
    }
    if (writeFailing_ && !events.empty()) {
        ET_LOG(Notice) << "The virtual touchscreen " << devnode_ << " accepts events again";
        writeFailing_ = false;
    }
}

}  // namespace everytouch::io

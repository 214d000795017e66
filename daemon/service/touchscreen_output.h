#pragma once

#include <functional>
#include <memory>
#include <string>

#include "core/calibration.h"
#include "io/touch_sink.h"
#include "io/uinput_sink.h"

namespace everytouch::service {

// The virtual touchscreen as far as the calibration allows: none while the daemon is uncalibrated (its size
// comes from the calibration), created with the first calibration, replaced when a new one changes the
// display. Used on the pipeline thread.
class TouchscreenOutput final : public io::TouchSink {
public:
    // `onDevice` receives the event node whenever the device appears or is replaced.
    explicit TouchscreenOutput(std::function<void(const std::string& devnode)> onDevice);

    // Creates or resizes the device. Throws as UinputSink does; an existing device then stays.
    void applyCalibration(const core::Calibration& calibration);

    void publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts) override;

private:
    std::function<void(const std::string&)> onDevice_;
    std::unique_ptr<io::UinputSink> device_;
};

}  // namespace everytouch::service

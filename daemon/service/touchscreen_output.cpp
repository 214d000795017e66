#include "service/touchscreen_output.h"

#include "io/log.h"

namespace everytouch::service {

TouchscreenOutput::TouchscreenOutput(std::function<void(const std::string&)> onDevice)
    : onDevice_(std::move(onDevice)) {}

void TouchscreenOutput::applyCalibration(const core::Calibration& calibration) {
    if (device_ && !device_->applyCalibration(calibration))
        return;
    if (!device_)
        device_ = std::make_unique<io::UinputSink>(calibration);
    const cv::Size2d sizeMm = device_->axes().sizeMm();
    ET_LOG(Info) << "virtual touchscreen " << device_->devnode() << ": " << calibration.displaySize.width
                 << "x" << calibration.displaySize.height << " px, " << sizeMm.width << "x" << sizeMm.height
                 << " mm";
    onDevice_(device_->devnode());
}

void TouchscreenOutput::publish(std::uint64_t frameIndex, std::int64_t timestampUs,
                                const core::Contacts& contacts) {
    if (device_)
        device_->publish(frameIndex, timestampUs, contacts);
}

}  // namespace everytouch::service

#include "service/calibration_store.h"

#include <stdexcept>

#include "io/calibration_file.h"
#include "io/input_error.h"

namespace everytouch::service {

CalibrationStore::CalibrationStore(std::filesystem::path path,
                                   std::optional<core::Calibration> rigCalibration)
    : path_(std::move(path)), rigCalibration_(std::move(rigCalibration)) {}

std::optional<std::string> CalibrationStore::load() {
    active_.reset();
    if (path_.empty()) {
        active_ = rigCalibration_;
        return std::nullopt;
    }
    std::error_code error;
    if (!std::filesystem::exists(path_, error))
        return std::nullopt;
    try {
        active_ = io::readCalibrationFile(path_);
    } catch (const io::InputError& problem) {
        return problem.what();
    }
    return std::nullopt;
}

void CalibrationStore::save() const {
    if (path_.empty())
        throw std::logic_error("no calibration file is configured");
    if (!active_)
        throw std::logic_error("there is no calibration to save");
    io::writeCalibrationFile(path_, *active_);
}

}  // namespace everytouch::service

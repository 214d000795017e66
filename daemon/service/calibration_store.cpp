#include "service/calibration_store.h"

#include <fstream>
#include <iterator>
#include <stdexcept>
#include <system_error>

#include "io/atomic_file.h"
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

void CalibrationStore::saveKeepingBackup() const {
    if (path_.empty())
        throw std::logic_error("no calibration file is configured");
    std::error_code error;
    if (std::filesystem::exists(path_, error)) {
        std::ifstream in(path_, std::ios::binary);
        const std::string kept{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        if (!in && !in.eof())
            throw std::system_error(errno, std::generic_category(), path_.string() + ": cannot be read");
        io::writeFileAtomically(backupPath(), kept);
    }
    save();
}

}  // namespace everytouch::service

#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/calibration.h"

namespace everytouch::service {

inline constexpr const char* kDefaultCalibrationPath = "/var/lib/everytouch/calibration.yml";

// The calibration the daemon works with, and the file that keeps it between runs. Sim and replay rigs bring
// their own calibration, used when no file is configured.
class CalibrationStore {
public:
    // `path`: the calibration file; empty to use `rigCalibration` and keep nothing.
    CalibrationStore(std::filesystem::path path, std::optional<core::Calibration> rigCalibration);

    // Makes the stored calibration active: the file's when there is one, otherwise the rig's. A file that is
    // there but unusable is reported (the problem names the file and the field), never replaced, and leaves
    // the daemon uncalibrated.
    std::optional<std::string> load();

    const std::optional<core::Calibration>& active() const { return active_; }
    void activate(const core::Calibration& calibration) { active_ = calibration; }
    void forget() { active_.reset(); }

    // Whether save() has somewhere to write.
    bool keepsFile() const { return !path_.empty(); }
    const std::filesystem::path& path() const { return path_; }

    // Writes the active calibration atomically. Throws std::logic_error when there is no file or nothing is
    // active, std::system_error or io::InputError when writing fails (the old file stays intact).
    void save() const;
    // As save(), after copying the file there (if any) to path() + ".bak", atomically too: a correction the
    // daemon made on its own can be undone by hand.
    void saveKeepingBackup() const;
    std::filesystem::path backupPath() const { return path_.string() + ".bak"; }

private:
    std::filesystem::path path_;
    std::optional<core::Calibration> rigCalibration_;
    std::optional<core::Calibration> active_;
};

}  // namespace everytouch::service

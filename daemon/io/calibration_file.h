#pragma once

#include <filesystem>
#include <string>

#include <opencv2/core/persistence.hpp>

#include "core/calibration.h"

namespace everytouch::io {

inline constexpr const char* kCalibrationFormat = "everytouch-calibration";
inline constexpr int kCalibrationVersion = 1;

// Reads a calibration file (OpenCV FileStorage YAML, docs/architecture.md). Throws InputError naming the file
// and the field on any problem; returns only a complete, validated calibration.
core::Calibration readCalibrationFile(const std::filesystem::path& path);

// Writes the calibration atomically: a temporary file beside `path`, fsync, rename. The old file stays intact
// on any failure (then std::system_error or InputError is thrown).
void writeCalibrationFile(const std::filesystem::path& path, const core::Calibration& calibration);

// The calibration keys, shared by calibration files and a recording's rig.yml.
core::Calibration readCalibrationKeys(const cv::FileNode& root, const std::string& inputName);
void writeCalibrationKeys(cv::FileStorage& storage, const core::Calibration& calibration);

// Header keys "format" and "version"; throws InputError unless `format` is one of `acceptedFormats` and the
// version is `version`.
void checkFormatHeader(const cv::FileNode& root, const std::string& inputName,
                       std::initializer_list<const char*> acceptedFormats, int version);

// Opens a FileStorage document for reading; a parse error becomes an InputError naming the file.
cv::FileStorage openYamlForReading(const std::filesystem::path& path);

}  // namespace everytouch::io

#pragma once

#include <string>
#include <vector>

namespace everytouch::calib {

// A successful calibration's CalibrationFinished message is "calibrated; RMS reprojection error X px",
// followed by remarks for the user, each after "; " (how an unwarped display lands on the table). Returns
// those remarks, each with its first letter capitalised; none for a message without any.
std::vector<std::string> remarksOf(const std::string& message);

}  // namespace everytouch::calib

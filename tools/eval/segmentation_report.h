#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "eval/segmentation_evaluation.h"

namespace everytouch::eval {

// The report as JSON: every number of the table, with null where a value is undefined (no pixel marked, no
// truth finger).
nlohmann::json segmentationJson(const SegmentationReport& report);

// The report as the table printed to the terminal.
std::string segmentationTable(const SegmentationReport& report);

}  // namespace everytouch::eval

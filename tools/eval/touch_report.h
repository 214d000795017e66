#pragma once

#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "eval/touch_scoring.h"

namespace everytouch::eval {

// Where the scored contacts came from, for the report's header.
struct TouchSource {
    std::string recording;
    std::string log;  // empty when the pipeline ran on the recording
    double matchRadiusMm = 0.0;
    double frameRate = 0.0;  // camera frames per second, to give latencies in ms too
};

// Every number of the table, null where undefined (no trial, no match), and each trial's outcome.
nlohmann::json touchJson(const TouchSource& source, const TouchScore& score);

// The score as the table printed to the terminal.
std::string touchTable(const TouchSource& source, const TouchScore& score);

// One CSV row per true finger and frame: the finger's truth and the contact matched to it as the score
// matches them (empty fields where none lies within radiusPx), to study heights and touch states frame by
// frame (a hovering finger's readings before a false touch-down, say).
void writeTouchTrace(std::ostream& out, const TruthFrames& truth, const DetectedFrames& detected,
                     double radiusPx);

}  // namespace everytouch::eval

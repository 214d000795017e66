#pragma once

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "daemon_client.h"
#include "tap_scoring.h"

namespace everytouch::calib {

// One run of `everytouch-calib test`, as it is reported.
struct AccuracyRun {
    std::string rig;  // everytouchd's Rig property
    DaemonClient::Display display;
    TapTargets targets;
    TapScore score;
    double seconds = 0.0;   // how long the taps were collected
    double timeoutS = 0.0;  // the most they would have been
};

// "circle 12 of 35 tapped: (401.3, 239.0), 1.4 px from its centre" for the circle at `index` (from 0).
std::string describeTap(const AccuracyRun& run, std::size_t index);

// The table of circles, the false touch-downs and the scores, for people.
void printAccuracyReport(std::FILE* out, const AccuracyRun& run);

// The same for programs; lengths in display pixels and mm, null where a score is undefined.
nlohmann::json accuracyReportJson(const AccuracyRun& run);

}  // namespace everytouch::calib

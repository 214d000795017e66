#pragma once

#include "core/touch_pipeline.h"
#include "sim/simulator.h"

namespace everytouch::test {

// What the daemon gives the pipeline on the simulated rig.
inline core::PipelineSettings simulatedRigSettings(const sim::Simulator& simulator) {
    core::PipelineSettings settings;
    settings.calibration = simulator.calibration();
    settings.pattern = simulator.pattern();
    settings.touchHeightMm = 3.0;
    return settings;
}

}  // namespace everytouch::test

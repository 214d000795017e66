#include "accuracy_rig.h"

#include "io/input_error.h"
#include "io/rig_spec.h"

namespace everytouch::calib {

std::variant<AccuracyTestRig, std::string> accuracyTestRig(const std::string& rig) {
    io::RigSpec spec;
    try {
        spec = io::RigSpec::parse(rig);
    } catch (const io::InputError& error) {
        return "everytouchd names a rig this tool does not know (" + std::string(error.what()) + ")";
    }
    switch (spec.kind) {
        case io::RigSpec::Kind::Aravis:
        case io::RigSpec::Kind::V4l2:
            return AccuracyTestRig::Camera;
        case io::RigSpec::Kind::Replay:
            return "everytouchd replays " + rig +
                   ", which shows what it recorded and taps no circle this test could show; run it on a "
                   "camera "
                   "rig, whose projector shows the circles for you to tap, or on the simulated session "
                   "(everytouchd --rig sim:grid35)";
        case io::RigSpec::Kind::Sim:
            if (spec.target != "grid35")
                return "everytouchd runs the simulated rig " + rig +
                       ", whose hand does not tap the accuracy test's circles; run everytouchd --rig "
                       "sim:grid35";
            return AccuracyTestRig::SimulatedSession;
    }
    return "everytouchd names a rig this tool does not know (" + rig + ")";
}

}  // namespace everytouch::calib

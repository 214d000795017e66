#include "accuracy_rig.h"

#include "io/input_error.h"
#include "io/rig_spec.h"

namespace everytouch::calib {

namespace {

constexpr const char* kHowToRun = "run everytouchd --rig sim:grid35";

}  // namespace

std::optional<std::string> accuracyTestRigProblem(const std::string& rig) {
    io::RigSpec spec;
    try {
        spec = io::RigSpec::parse(rig);
    } catch (const io::InputError& error) {
        return "everytouchd names a rig this tool does not know (" + std::string(error.what()) + ")";
    }
    if (spec.kind != io::RigSpec::Kind::Sim)
        return "everytouchd runs on " + rig +
               ". The accuracy test shows its circles with the projector, which this build cannot do yet; it "
               "runs on the simulated rig, whose projector shows the circles and whose hand taps them: " +
               kHowToRun;
    if (spec.target != "grid35")
        return "everytouchd runs the simulated rig " + rig +
               ", whose hand does not tap the accuracy test's circles; " + kHowToRun;
    return std::nullopt;
}

}  // namespace everytouch::calib

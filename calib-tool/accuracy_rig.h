#pragma once

#include <string>
#include <variant>

namespace everytouch::calib {

// Who shows the accuracy test's circles and who taps them: the simulated rig's grid35 scenario does both (its
// projector draws them, its hand taps their centres); on a camera rig the daemon's projector output shows
// them (ShowAccuracyTargets) and a person taps them.
enum class AccuracyTestRig { SimulatedSession, Camera };

// How `everytouch-calib test` runs on the rig everytouchd names in its Rig property ("sim:grid35,seed=3",
// "aravis:...", "replay:/path"), or why it cannot: a recording shows what it recorded, and another simulated
// scenario's hand does not tap the circles.
std::variant<AccuracyTestRig, std::string> accuracyTestRig(const std::string& rig);

}  // namespace everytouch::calib

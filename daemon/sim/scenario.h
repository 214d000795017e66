#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/calibration.h"
#include "sim/content.h"
#include "sim/hand.h"
#include "sim/props.h"

namespace everytouch::sim {

// What is on and above the table at one instant.
struct SceneState {
    std::vector<HandPose> hands;
    ContentKind content = ContentKind::White;  // what the desktop shows ...
    int contentVariant = 0;                    // ... and which random layout of it
    Props props;                               // calibration props: a card, a board
};

// A scripted session: hands moving over the table and the content shown, as a pure function of time. Every
// scenario repeats a cycle forever, each cycle varied by the seed and the cycle number.
class Scenario {
public:
    virtual ~Scenario() = default;
    virtual SceneState at(double seconds) const = 0;
    // Length of one cycle, seconds.
    virtual double cycleSeconds() const = 0;
    // Every arrangement of props the scenario holds still (the exposure is metered for the brightest).
    virtual std::vector<Props> stillProps() const { return {}; }
    // The session is a user following the calibration dialogue: it begins when the projector first shows an
    // image (the dialogue's chessboard), and until then the scene is as at its start (Simulator::render).
    virtual bool beginsWithTheProjector() const { return false; }
};

struct ScenarioContext {
    core::Calibration calibration;  // where display pixels land on the table
    std::uint64_t seed = 1;
    double handScale = 1.0;
};

// grid35, drag, multitouch, hover, palm, idle, demo, table-setup, pair-calibration.
const std::vector<std::string>& scenarioNames();

// Throws std::invalid_argument naming the known scenarios when `name` is not one of them.
std::unique_ptr<Scenario> makeScenario(std::string_view name, const ScenarioContext& context);

}  // namespace everytouch::sim

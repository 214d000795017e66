#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sim/sim_parameters.h"

namespace everytouch::sim {

// One key of the rig spec `sim:SCENARIO[,key=value...]`.
struct OptionKey {
    std::string name;
    std::string help;  // what it sets and its syntax
};

// Every key applyOption accepts, in documentation order.
const std::vector<OptionKey>& optionKeys();

// Sets the parameter named by `key` from its text. Vectors are written with ':' between components
// (camera_position=-20:-215:455), sizes as WxH. Preset keys set several parameters: light=dark|normal|change.
// Returns the problem ("unknown key; known keys: ...", "expected a number") or nothing. The parameters are
// not validated as a whole: call SimParameters::validate() after the last option.
std::optional<std::string> applyOption(SimParameters& parameters, std::string_view key,
                                       std::string_view value);

}  // namespace everytouch::sim

#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace everytouch::io {

// The --rig argument: sim[:SCENARIO][,key=value...] | replay:DIR | aravis[:ID] | v4l2:/dev/videoN.
struct RigSpec {
    enum class Kind { Sim, Replay, Aravis, V4l2 };

    Kind kind = Kind::Sim;
    std::string
        target;  // scenario, recording directory, camera id or device node; may be empty for sim/aravis
    std::vector<std::pair<std::string, std::string>> options;  // sim only: key=value in the order given

    // Throws InputError naming "--rig" and what is wrong.
    static RigSpec parse(std::string_view text);
    std::string toString() const;
};

}  // namespace everytouch::io

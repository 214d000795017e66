#include "service/daemon_options.h"

#include "io/input_error.h"
#include "io/rig_spec.h"

namespace everytouch::service {

std::optional<std::string> DaemonOptions::validate() const {
    try {
        if (!rig.empty())
            io::RigSpec::parse(rig);
    } catch (const io::InputError& error) {
        return error.what();
    }
    for (const std::string& output : outputs)
        if (output != "uinput")
            return "--output " + output + ": unknown output; the choice is uinput";
    if (!recordDir.empty() && std::filesystem::exists(recordDir) && !std::filesystem::is_empty(recordDir))
        return "--record " + recordDir.string() +
               ": exists and is not empty; choose a new recording directory";
    return std::nullopt;
}

}  // namespace everytouch::service

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
    try {
        if (!projector.empty()) {
            ProjectorConfig ignored;
            applyProjectorOption(projector, ignored);
        }
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

void applyProjectorOption(const std::string& option, ProjectorConfig& projector) {
    const std::size_t colon = option.find(':');
    const std::string output = option.substr(0, colon);
    if (colon != std::string::npos && output != "window" && output != "overlay")
        throw io::InputError(
            "--projector", "",
            "only a window or an overlay takes a display (window:DISPLAY, overlay:DISPLAY), not \"" + option +
                "\"");
    const std::optional<ProjectorOutput> parsed = parseProjectorOutput(output);
    if (!parsed)
        throw io::InputError(
            "--projector", "",
            "expected none, external, window, window:DISPLAY, overlay or overlay:DISPLAY, found \"" + option +
                "\"");
    projector.output = *parsed;
    if (colon != std::string::npos)
        projector.display = option.substr(colon + 1);
}

}  // namespace everytouch::service

// everytouchd: turns a table seen by a camera and lit by a projector into a multitouch screen.
#include <cstdio>

#include <CLI/CLI.hpp>

#include "io/input_error.h"
#include "io/log.h"
#include "service/daemon.h"
#include "service/daemon_options.h"
#include "version.h"

int main(int argc, char** argv) {
    using namespace everytouch;
    // Before any thread starts, so that every thread leaves these signals to the event loop.
    service::Daemon::prepareSignals();

    service::DaemonOptions options;
    CLI::App app{
        "everytouchd - turns a table lit by a projector and seen by a camera into a multitouch screen"};
    app.set_version_flag("--version", std::string("everytouchd ") + kVersion);
    app.add_option("--config", options.configPath,
                   "Configuration file; its drop-ins are read from FILE.d/*.conf")
        ->capture_default_str();
    app.add_option("--rig", options.rig,
                   "Frame source: sim[:SCENARIO][,key=value...], replay:DIR, aravis[:ID] or v4l2:/dev/videoN "
                   "(default: [Camera] Rig= of the configuration, else sim:demo unless --service)");
    app.add_option("--log", options.touchLog, "Write the touch log (JSON Lines) to FILE; - for stdout");
    app.add_option(
           "--output", options.outputs,
           "Send contacts to OUTPUT too: uinput (the virtual touchscreen; overrides [Output] Uinput=)")
        ->delimiter(',');
    app.add_option(
        "--projector", options.projector,
        "Projector output of a camera rig: none, external (it embeds the code itself), window or "
        "window:DISPLAY (a fullscreen window of everytouchd's own), overlay or overlay:DISPLAY (the "
        "code over the X11 desktop, through its compositing manager); overrides [Projector] Output= "
        "and Display=");
    app.add_option("--record", options.recordDir, "Record every frame into the new directory DIR");
    app.add_option("--frames", options.maxFrames, "Stop after N camera frames (0: run until the rig ends)");
    app.add_flag("--fast", options.fast, "Do not pace sim and replay rigs in real time");
    app.add_flag("--service", options.service,
                 "Run as the system service: a camera must be configured, the bus is required");
    app.add_flag("-v,--verbose", options.verbose, "Log debug messages and every contact change");
    app.footer(
        "Exit status: 0 success, 1 runtime failure (camera, pipeline, bus), 2 bad input (option, "
        "configuration, "
        "rig, file), 6 no camera configured for the service.\n"
        "SIGTERM or SIGINT stop it cleanly, SIGHUP reloads the configuration. See everytouchd(8).");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int status = app.exit(error);
        return status == 0 ? 0 : service::kExitBadInput;
    }

    io::setLogVerbose(options.verbose);
    if (auto problem = options.validate()) {
        ET_LOG(Error) << *problem;
        return service::kExitBadInput;
    }
    try {
        service::Daemon daemon(options);
        return daemon.run();
    } catch (const io::InputError& error) {
        ET_LOG(Error) << error.what();
        return service::kExitBadInput;
    } catch (const std::exception& error) {
        ET_LOG(Error) << error.what();
        return service::kExitFailure;
    }
}

// everytouchd: turns a table seen by a camera and lit by a projector into a multitouch screen.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <memory>

#include <CLI/CLI.hpp>

#include "io/console_sink.h"
#include "io/input_error.h"
#include "io/log.h"
#include "io/touch_log.h"
#include "io/uinput_sink.h"
#include "service/daemon_options.h"
#include "service/frame_loop.h"
#include "service/frame_sources.h"
#include "version.h"

namespace {

std::atomic<bool> stopRequested{false};

void requestStop(int) {
    stopRequested = true;
}

void installStopHandlers() {
    struct sigaction action {};
    action.sa_handler = requestStop;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

int run(const everytouch::service::DaemonOptions& options) {
    using namespace everytouch;
    const io::RigSpec spec = io::RigSpec::parse(options.rig);
    std::unique_ptr<io::FrameSource> source = service::openFrameSource(spec, options.fast);
    ET_LOG(Info) << "everytouchd " << kVersion << " on " << source->describe();

    std::unique_ptr<io::RecordingWriter> recorder;
    if (!options.recordDir.empty()) {
        const std::optional<io::RigDescription> rig = source->rig();
        if (!rig)
            throw io::InputError("--record", "", "this rig does not describe itself; calibrate it first");
        recorder = std::make_unique<io::RecordingWriter>(options.recordDir, *rig, false);
    }

    io::ConsoleSink console;
    std::vector<io::TouchSink*> sinks{&console};
    std::unique_ptr<io::TouchLogWriter> touchLog;
    if (!options.touchLog.empty()) {
        touchLog = std::make_unique<io::TouchLogWriter>(options.touchLog);
        sinks.push_back(touchLog.get());
    }

    std::unique_ptr<io::UinputSink> touchscreen;
    if (std::ranges::find(options.outputs, "uinput") != options.outputs.end()) {
        const std::optional<io::RigDescription> rig = source->rig();
        if (!rig)
            throw io::InputError("--output uinput", "",
                                 "this rig does not describe itself; the touchscreen's size comes from its "
                                 "calibration");
        touchscreen = std::make_unique<io::UinputSink>(rig->calibration);
        const cv::Size2d sizeMm = touchscreen->axes().sizeMm();
        ET_LOG(Info) << "virtual touchscreen " << touchscreen->devnode() << ": "
                     << rig->calibration.displaySize.width << "x" << rig->calibration.displaySize.height
                     << " px, " << sizeMm.width << "x" << sizeMm.height << " mm";
        sinks.push_back(touchscreen.get());
    }

    installStopHandlers();
    service::FrameLoop loop(*source, sinks, recorder.get(), options.maxFrames);
    const service::LoopStatistics statistics = loop.run(stopRequested);
    ET_LOG(Info) << "processed " << statistics.frames << " frames (" << statistics.pairs << " pairs) in "
                 << statistics.seconds << " s";
    ET_LOG(Notice) << "touch detection is not part of this build yet: frames are paired and recorded, "
                      "no contacts are reported";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace everytouch;
    service::DaemonOptions options;
    CLI::App app{
        "everytouchd - turns a table lit by a projector and seen by a camera into a multitouch screen"};
    app.set_version_flag("--version", std::string("everytouchd ") + kVersion);
    app.add_option("--config", options.configPath, "Configuration file")->capture_default_str();
    app.add_option("--rig", options.rig,
                   "Frame source: sim[:SCENARIO][,key=value...], replay:DIR, aravis[:ID] or v4l2:/dev/videoN")
        ->capture_default_str();
    app.add_option("--log", options.touchLog, "Write the touch log (JSON Lines) to FILE; - for stdout");
    app.add_option("--output", options.outputs,
                   "Send contacts to OUTPUT too: uinput (the virtual touchscreen)")
        ->delimiter(',');
    app.add_option("--record", options.recordDir, "Record every frame into the new directory DIR");
    app.add_option("--frames", options.maxFrames, "Stop after N camera frames (0: run until the rig ends)");
    app.add_flag("--fast", options.fast, "Do not pace sim and replay rigs in real time");
    app.add_flag("-v,--verbose", options.verbose, "Log debug messages and every contact change");
    CLI11_PARSE(app, argc, argv);

    io::setLogVerbose(options.verbose);
    if (auto problem = options.validate()) {
        ET_LOG(Error) << *problem;
        return 2;
    }
    try {
        return run(options);
    } catch (const io::InputError& error) {
        ET_LOG(Error) << error.what();
        return 2;
    } catch (const std::exception& error) {
        ET_LOG(Error) << error.what();
        return 1;
    }
}

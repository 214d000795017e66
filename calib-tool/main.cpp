// everytouch-calib: calibrates everytouchd and shows its status and contacts, over D-Bus.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "accuracy_report.h"
#include "accuracy_rig.h"
#include "calibration_remarks.h"
#include "contacts_view.h"
#include "daemon_client.h"
#include "io/handles.h"
#include "service/bus_names.h"
#include "tap_scoring.h"
#include "text_format.h"
#include "version.h"

namespace {

using namespace everytouch;
using calib::DaemonClient;
using calib::Failure;

int report(const Failure& failure) {
    std::fprintf(stderr, "%s\n", failure.message.c_str());
    return failure.exitStatus;
}

// One line per property, in words.
std::string describe(const std::string& name, const calib::PropertyValue& value) {
    if (const auto* text = std::get_if<std::string>(&value))
        return text->empty() && name == bus::kPropertyDevicePath ? "(none)" : *text;
    if (const auto* flag = std::get_if<bool>(&value))
        return *flag ? "yes" : "no";
    if (const auto* number = std::get_if<double>(&value)) {
        if (name == bus::kPropertyFrameRate)
            return calib::format("%.1f frames/s", *number);
        if (name == bus::kPropertyLatencyMs)
            return calib::format("%.1f ms", *number);
        if (name == bus::kPropertyCalibrationErrorPx)
            return std::isnan(*number) ? "not measured yet" : calib::format("%.2f projector px", *number);
        return calib::format("%.1f mm", *number);
    }
    if (const auto* count = std::get_if<std::uint64_t>(&value))
        return std::to_string(*count) + " frames";
    return std::to_string(std::get<std::uint32_t>(value));
}

int status() {
    auto client = DaemonClient::connect();
    if (auto* failure = std::get_if<Failure>(&client))
        return report(*failure);
    auto properties = std::get<DaemonClient>(client).allProperties();
    if (auto* failure = std::get_if<Failure>(&properties))
        return report(*failure);
    const auto& values = std::get<0>(properties);
    const std::pair<const char*, const char*> rows[] = {
        {bus::kPropertyState, "State"},
        {bus::kPropertyStateReason, "Why"},
        {bus::kPropertyRig, "Rig"},
        {bus::kPropertyProjector, "Projector"},
        {bus::kPropertyCalibrated, "Calibrated"},
        {bus::kPropertyTouchHeightMm, "Touch height"},
        {bus::kPropertyFrameRate, "Frame rate"},
        {bus::kPropertyLatencyMs, "Latency"},
        {bus::kPropertyDroppedFrames, "Dropped"},
        {bus::kPropertyCalibrationErrorPx, "Calibration error"},
        {bus::kPropertyDevicePath, "Touch device"},
    };
    for (const auto& [property, label] : rows) {
        const auto it = values.find(property);
        if (it == values.end())
            continue;
        // A property with nothing to say (no reason while running) takes no line.
        if (const std::string text = describe(property, it->second); !text.empty())
            std::printf("%-19s %s\n", (std::string(label) + ":").c_str(), text.c_str());
    }
    return calib::kExitOk;
}

int sensitivity(const std::optional<double>& heightMm) {
    auto client = DaemonClient::connect();
    if (auto* failure = std::get_if<Failure>(&client))
        return report(*failure);
    DaemonClient& daemon = std::get<DaemonClient>(client);
    if (heightMm) {
        if (auto failure = daemon.setTouchHeightMm(*heightMm))
            return report(*failure);
        std::printf("Fingers at or below %g mm above the table now touch.\n", *heightMm);
        return calib::kExitOk;
    }
    auto properties = daemon.allProperties();
    if (auto* failure = std::get_if<Failure>(&properties))
        return report(*failure);
    const auto& values = std::get<0>(properties);
    if (const auto it = values.find(bus::kPropertyTouchHeightMm); it != values.end())
        std::printf("%g\n", std::get<double>(it->second));
    return calib::kExitOk;
}

int snapshot(const std::string& what, const std::filesystem::path& file) {
    auto client = DaemonClient::connect();
    if (auto* failure = std::get_if<Failure>(&client))
        return report(*failure);
    // The daemon writes into a temporary file beside the target, renamed once complete.
    const std::filesystem::path directory = file.has_parent_path() ? file.parent_path() : ".";
    std::string temporary = (directory / ("." + file.filename().string() + ".XXXXXX")).string();
    io::UniqueFd fd(::mkostemp(temporary.data(), O_CLOEXEC));
    if (!fd)
        return report(
            {calib::kExitFailure, "Cannot create " + file.string() + ": " + std::strerror(errno) + "."});
    ::fchmod(fd.get(), 0644);
    if (auto failure = std::get<DaemonClient>(client).snapshot(what, fd.get())) {
        ::unlink(temporary.c_str());
        return report(*failure);
    }
    // On disk before it takes the name: a crash then leaves the old file or the new one, never an empty one.
    if (::fsync(fd.get()) < 0 || ::rename(temporary.c_str(), file.c_str()) < 0) {
        const int error = errno;
        ::unlink(temporary.c_str());
        return report(
            {calib::kExitFailure, "Cannot write " + file.string() + ": " + std::strerror(error) + "."});
    }
    std::printf("Wrote the %s image to %s.\n", what.c_str(), file.c_str());
    return calib::kExitOk;
}

// A bar on a terminal, plain lines elsewhere (logs, pipes).
void showProgress(const std::string& step, double fraction, const std::string& message) {
    const int percent = static_cast<int>(std::lround(100.0 * std::clamp(fraction, 0.0, 1.0)));
    if (!::isatty(STDERR_FILENO)) {
        std::fprintf(stderr, "%3d%% %s: %s\n", percent, step.c_str(), message.c_str());
        return;
    }
    // A new instruction starts a new line, so that the earlier ones stay readable above it.
    static std::string shown;
    if (!shown.empty() && message != shown)
        std::fprintf(stderr, "\n");
    shown = message;
    constexpr int kWidth = 30;
    const int filled = percent * kWidth / 100;
    std::fprintf(stderr, "\r\033[K[%s%s] %3d%% %s: %s", std::string(filled, '#').c_str(),
                 std::string(kWidth - filled, '-').c_str(), percent, step.c_str(), message.c_str());
    std::fflush(stderr);
}

int calibrate(const std::string& step, const DaemonClient::CalibrationOptions& options, bool save) {
    auto client = DaemonClient::connect();
    if (auto* failure = std::get_if<Failure>(&client))
        return report(*failure);
    DaemonClient& daemon = std::get<DaemonClient>(client);
    auto outcome = daemon.calibrate(step, options, showProgress);
    if (::isatty(STDERR_FILENO))
        std::fprintf(stderr, "\n");
    if (auto* failure = std::get_if<Failure>(&outcome))
        return report(*failure);
    const auto& result = std::get<DaemonClient::CalibrationResult>(outcome);
    if (!result.ok)
        return report({calib::kExitFailure,
                       "Calibration failed: " + result.message + ". The previous calibration stays active."});
    std::printf("Calibrated: RMS reprojection error %.2f px.\n", result.rmsPx);
    for (const std::string& remark : calib::remarksOf(result.message))
        std::printf("%s.\n", remark.c_str());
    if (!save)
        return calib::kExitOk;
    if (auto failure = daemon.saveCalibration())
        return report(
            {failure->exitStatus, "The new calibration is active but was not saved: " + failure->message});
    std::printf("Saved; everytouchd uses it from now on, also after a restart.\n");
    return calib::kExitOk;
}

int monitor(const DaemonClient::ContactsOptions& options) {
    auto client = DaemonClient::connect();
    if (auto* failure = std::get_if<Failure>(&client))
        return report(*failure);
    calib::ContactsView view(stdout, ::isatty(STDOUT_FILENO));
    if (auto failure = std::get<DaemonClient>(client).followContacts(
            options, [&view](const DaemonClient::ContactsUpdate& update) {
                view.show(update);
                return true;
            }))
        return report(*failure);
    return calib::kExitOk;
}

std::string textProperty(const std::map<std::string, calib::PropertyValue>& properties, const char* name) {
    const auto it = properties.find(name);
    const std::string* text = it != properties.end() ? std::get_if<std::string>(&it->second) : nullptr;
    return text ? *text : std::string();
}

// The paper's accuracy test: a tap on each of the 35 circles, scored as it scores its trials.
int accuracyTest(double timeoutS, const std::optional<std::filesystem::path>& jsonFile) {
    auto client = DaemonClient::connect();
    if (auto* failure = std::get_if<Failure>(&client))
        return report(*failure);
    DaemonClient& daemon = std::get<DaemonClient>(client);
    auto properties = daemon.allProperties();
    if (auto* failure = std::get_if<Failure>(&properties))
        return report(*failure);
    const std::string rig = textProperty(std::get<0>(properties), bus::kPropertyRig);
    const auto testRig = calib::accuracyTestRig(rig);
    if (const auto* problem = std::get_if<std::string>(&testRig))
        return report({calib::kExitFailure, *problem + "."});
    const bool camera = std::get<calib::AccuracyTestRig>(testRig) == calib::AccuracyTestRig::Camera;
    if (const std::string state = textProperty(std::get<0>(properties), bus::kPropertyState);
        state != "running")
        return report({calib::kExitFailure, "everytouchd is not detecting touches (it is " + state +
                                                "); \"everytouch-calib status\" shows why."});
    auto display = daemon.display();
    if (auto* failure = std::get_if<Failure>(&display))
        return report(*failure);

    calib::AccuracyRun run;
    run.rig = rig;
    run.display = std::get<DaemonClient::Display>(display);
    run.targets = calib::accuracyTargets(run.display);
    run.timeoutS = timeoutS;
    if (run.display.widthPx == 0 || run.display.heightPx == 0 || !(run.display.widthMm > 0.0) ||
        !(run.display.heightMm > 0.0))
        return report(
            {calib::kExitFailure,
             "everytouchd knows no display: it is not calibrated. Run \"everytouch-calib calibrate\" "
             "first."});
    run.score = calib::scoreTaps(run.targets, {});
    // The daemon shows them until this tool says so or leaves the bus, however it ends.
    if (camera)
        if (const std::optional<Failure> failure = daemon.showAccuracyTargets(true))
            return report(*failure);
    std::fprintf(
        stderr, "Waiting for a tap on each of the %zu circles (%s), at most %g s.\n",
        run.targets.centres.size(),
        camera ? "tap the centre of each circle the projector shows, once" : "the simulated hand taps them",
        timeoutS);

    calib::TouchDownFinder finder;
    std::vector<calib::TouchDown> touchDowns;
    DaemonClient::ContactsOptions options;
    options.durationS = timeoutS;
    const auto started = std::chrono::steady_clock::now();
    const std::optional<Failure> failure =
        daemon.followContacts(options, [&](const DaemonClient::ContactsUpdate& update) {
            if (!update.contactsChanged)
                return true;
            for (const calib::TouchDown& touchDown : finder.next(update.seconds, update.contacts)) {
                touchDowns.push_back(touchDown);
                const calib::TapScore before = std::move(run.score);
                run.score = calib::scoreTaps(run.targets, touchDowns);
                for (std::size_t i = 0; i < run.score.circles.size(); ++i)
                    if (run.score.circles[i].tap && !before.circles[i].tap)
                        std::fprintf(stderr, "%s\n", calib::describeTap(run, i).c_str());
            }
            return !run.score.complete();
        });
    run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (failure)
        return report(*failure);
    if (camera)
        if (const std::optional<Failure> hidden = daemon.showAccuracyTargets(false))
            return report(*hidden);

    calib::printAccuracyReport(stdout, run);
    if (jsonFile) {
        std::ofstream out(*jsonFile);
        out << calib::accuracyReportJson(run).dump(2) << "\n";
        out.close();
        if (!out)
            return report({calib::kExitFailure, "Cannot write " + jsonFile->string() + "."});
    }
    return calib::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"everytouch-calib - calibrate everytouchd and show its status (talks to it over D-Bus)"};
    app.set_version_flag("--version", std::string("everytouch-calib ") + kVersion);
    app.footer(
        "Exit status: 0 success; 1 the operation failed (the message says why); 2 bad usage or a value "
        "everytouchd refused; 3 everytouchd is not running; 4 permission denied (root or the everytouch "
        "group "
        "is needed). See everytouch-calib(1).");
    app.require_subcommand(1);

    CLI::App* statusCommand =
        app.add_subcommand("status", "Show the daemon's state, rig, calibration and rates");

    std::string step = "table";
    DaemonClient::CalibrationOptions options;
    bool noSave = false;
    CLI::App* calibrateCommand = app.add_subcommand(
        "calibrate",
        "Calibrate: projector (once per rig: the card on the table, then on a board in several tilts), "
        "table (a card on the table) or full (both)");
    calibrateCommand->add_option("step", step, "projector, table or full")
        ->check(CLI::IsMember({"projector", "table", "full"}))
        ->capture_default_str();
    calibrateCommand->add_option("--frames", options.frames, "Frame pairs the table step averages (1-120)");
    calibrateCommand->add_option("--card-width-mm", options.cardWidthMm,
                                 "Width of the card's dark stripe the steps look for (default 85.5)");
    calibrateCommand->add_option("--card-height-mm", options.cardHeightMm,
                                 "Height of the card's dark stripe the steps look for (default 12.5)");
    calibrateCommand->add_option("--views", options.views,
                                 "Poses the projector step takes, the table first (3-20, default 6)");
    calibrateCommand->add_option("--view-timeout-s", options.viewTimeoutS,
                                 "The projector step fails when no new pose is taken for this many seconds "
                                 "(1-3600, default 60)");
    calibrateCommand->add_flag("--no-save", noSave,
                               "Keep the new calibration only until everytouchd restarts");

    std::optional<double> heightMm;
    CLI::App* sensitivityCommand = app.add_subcommand(
        "sensitivity",
        "Show or set the touch height: a finger at most MM millimetres above the table touches");
    sensitivityCommand->add_option("MM", heightMm, "The touch height in millimetres, 0 to 30");

    std::string what;
    std::filesystem::path file;
    CLI::App* snapshotCommand = app.add_subcommand(
        "snapshot", "Save what the camera sees as a PNG (needs root or the everytouch group)");
    snapshotCommand->add_option("WHAT", what, "camera, texture, subtraction, mask or overlay")->required();
    snapshotCommand->add_option("FILE", file, "The PNG file to write")->required();

    DaemonClient::ContactsOptions monitorOptions;
    CLI::App* monitorCommand = app.add_subcommand(
        "monitor",
        "Show the contacts live (id, position in display pixels, touching or hover height) and the frame "
        "rate; until Ctrl+C");
    monitorCommand->add_option("--count", monitorOptions.count, "End after N changes of contacts")
        ->check(CLI::PositiveNumber);
    monitorCommand->add_option("--duration", monitorOptions.durationS, "End after S seconds")
        ->check(CLI::Range(0.001, 1e9));

    // The simulated session taps all 35 circles in 53 s where the simulator keeps real time; one started
    // mid-session completes on the hand's next round, and a slower machine takes longer.
    double timeoutS = 300.0;
    std::optional<std::filesystem::path> jsonFile;
    CLI::App* testCommand =
        app.add_subcommand("test",
                           "The paper's accuracy test: one tap on each of 35 circles, scored as epsilon "
                           "(display px and mm), FRR and FAR; on a camera rig its projector shows the "
                           "circles, on the simulated rig (everytouchd --rig sim:grid35) its hand taps them");
    testCommand
        ->add_option("--timeout-s", timeoutS, "Stop after S seconds even when some circles have no tap")
        ->check(CLI::Range(0.001, 1e9))
        ->capture_default_str();
    testCommand->add_option("--json", jsonFile,
                            "Also write every circle's tap and the scores to FILE as JSON");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int status = app.exit(error);
        return status == 0 ? calib::kExitOk : calib::kExitUsage;
    }
    if (statusCommand->parsed())
        return status();
    if (calibrateCommand->parsed())
        return calibrate(step, options, !noSave);
    if (sensitivityCommand->parsed())
        return sensitivity(heightMm);
    if (snapshotCommand->parsed())
        return snapshot(what, file);
    if (monitorCommand->parsed())
        return monitor(monitorOptions);
    if (testCommand->parsed())
        return accuracyTest(timeoutS, jsonFile);
    return calib::kExitUsage;
}

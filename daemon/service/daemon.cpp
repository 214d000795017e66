#include "service/daemon.h"

#include <signal.h>
#include <systemd/sd-daemon.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "core/accuracy_targets.h"
#include "core/keystone.h"
#include "core/pattern.h"
#include "io/input_error.h"
#include "io/log.h"
#include "service/bus_names.h"
#include "service/bus_service.h"
#include "service/frame_sources.h"
#include "version.h"

namespace everytouch::service {

namespace {

using Clock = std::chrono::steady_clock;

// Frames waiting between the camera and the pipeline thread: enough to ride out a slow pair, few enough
// that a late pipeline works on fresh frames.
constexpr std::size_t kQueueFrames = 4;
// A camera that delivers no frame for this long has stalled and its contacts go: 30 frames at 120 Hz, 5 at
// 20 Hz, far longer than a frame's jitter or a pair that the pipeline is slow on.
constexpr std::chrono::milliseconds kCameraStall{250};
// Contacts signals at most this often: enough for a tool that draws them, far below the camera rate.
constexpr auto kContactsSignalInterval = std::chrono::milliseconds(33);
constexpr std::uint64_t kStatusIntervalUsec = 5'000'000;

std::string formatDouble(const char* format, double value) {
    char text[64];
    std::snprintf(text, sizeof text, format, value);
    return text;
}

// How the unwarped display lands on the table, for whoever sets the projector's own keystone.
std::string describeShape(const core::DisplayShape& shape) {
    return "the display lands on the table with sides of " + formatDouble("%.0f", shape.topMm) + " (top), " +
           formatDouble("%.0f", shape.bottomMm) + " (bottom), " + formatDouble("%.0f", shape.leftMm) +
           " (left) and " + formatDouble("%.0f", shape.rightMm) + " mm (right), its corners " +
           formatDouble("%.1f", shape.leastCornerDeg) + " to " +
           formatDouble("%.1f", shape.largestCornerDeg) +
           " degrees: the projector's own keystone makes it an upright rectangle";
}

}  // namespace

const char* toString(DaemonState state) {
    switch (state) {
        case DaemonState::Starting:
            return "starting";
        case DaemonState::Running:
            return "running";
        case DaemonState::Calibrating:
            return "calibrating";
        case DaemonState::Degraded:
            return "degraded";
        case DaemonState::Failed:
            return "failed";
    }
    return "failed";
}

Daemon::Daemon(DaemonOptions options) : options_(std::move(options)) {}

Daemon::~Daemon() {
    if (projector_)
        projector_->onProblemChange({});  // the inbox it posts to goes before the projector
    shutDown();
}

void Daemon::prepareSignals() {
    sigset_t signals;
    sigemptyset(&signals);
    for (int signal : {SIGTERM, SIGINT, SIGHUP})
        sigaddset(&signals, signal);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    std::signal(SIGPIPE, SIG_IGN);
}

int Daemon::run() {
    config_ = loadConfig(options_.configPath, options_.configPath != kDefaultConfigPath);
    if (!options_.projector.empty())
        applyProjectorOption(options_.projector, config_.projector);
    touchHeightMm_ = config_.touchHeightMm;

    std::string rigText = !options_.rig.empty() ? options_.rig : config_.rig;
    if (rigText.empty() && options_.service) {
        const std::string problem = "No camera configured: set [Camera] Rig= in " +
                                    options_.configPath.string() + " (see everytouchd(8))";
        ET_LOG(Error) << problem;
        sd_notifyf(0, "STATUS=%s", problem.c_str());
        return kExitNotConfigured;
    }
    if (rigText.empty())
        rigText = kHandRunRig;
    const io::RigSpec spec = io::RigSpec::parse(rigText);
    rigName_ = spec.toString();
    cameraRig_ = spec.kind == io::RigSpec::Kind::Aravis || spec.kind == io::RigSpec::Kind::V4l2;
    if (cameraRig_ && (config_.projector.output == ProjectorOutput::Window ||
                       config_.projector.output == ProjectorOutput::Overlay)) {
        // At the first start on an output the code pattern is generated before the daemon is ready: under a
        // second at 640x480, about a minute at 1920x1080. systemd's start timeout waits that long.
        sd_notify(0,
                  "EXTEND_TIMEOUT_USEC=300000000\nSTATUS=Opening the projector output (at the first start on "
                  "an output its code pattern takes up to a minute or two on a large panel)");
    }
    if (!cameraRig_ && config_.projector.output != ProjectorOutput::None)
        ET_LOG(Notice) << "[Projector] applies to camera rigs; " << spec.toString()
                       << " brings its own projector and code";
    OpenedRig opened =
        openRig(spec, options_.fast, config_.camera, config_.projector, calibrationPath().parent_path());
    source_ = std::move(opened.source);
    projector_ = std::move(opened.projector);
    pattern_ = std::move(opened.pattern);
    recordedRig_ = spec.kind == io::RigSpec::Kind::Replay;
    projectorName_ = describeProjector();
    ET_LOG(Info) << "everytouchd " << kVersion << " on " << source_->describe()
                 << (projector_ ? ", calibration images on " + projector_->describe() : std::string());
    const std::optional<io::RigDescription> rig = source_->rig();
    if (rig)
        pattern_ = rig->pattern;
    if (!pattern_.empty() && cameraRig_)
        ET_LOG(Info) << "code: the pattern of seed " << config_.projector.seed << " on the projector's "
                     << pattern_.cols << "x" << pattern_.rows << " pixels, " << config_.projector.delta
                     << " levels, embedded by " << projector_->describe();
    if (projector_)
        projectorSize_ = projector_->size();
    else if (rig)
        projectorSize_ = rig->calibration.projectorSize;

    loadCalibration(rig);

    if (!options_.recordDir.empty()) {
        // The rig as it is now, its display drawn through the active calibration's keystone.
        const std::optional<io::RigDescription> recorded = recordedRig();
        if (!recorded)
            throw io::InputError("--record", "",
                                 cameraRig_
                                     ? "a camera rig is recorded once it is calibrated, knows its code "
                                       "([Projector] Output=external) and says its frame rate "
                                       "([Camera] FrameRate=)"
                                     : "this rig does not describe itself; calibrate it first");
        const bool withTruth = source_->truth().has_value();
        const bool withMasks = source_->truthMask().has_value();
        recorder_ =
            std::make_unique<io::RecordingWriter>(options_.recordDir, *recorded, withTruth, withMasks);
    }
    if (const int r = startEventLoop(); r < 0)
        throw std::system_error(-r, std::generic_category(), "Failed to set up the event loop");
    if (projector_)
        projector_->onProblemChange([this] { inbox_.post([this] { refreshState(); }); });
    connectBus();
    startFrameLoop(openOutputs());
    startWatchdog();

    ready_ = true;
    reportedCalibrated_ = calibrated();
    refreshState();
    sd_notify(0, "READY=1");
    notifyStatus();

    const int r = sd_event_loop(event_.get());
    if (r < 0) {
        ET_LOG(Error) << "the event loop failed: " << std::strerror(-r);
        exitStatus_ = kExitFailure;
    } else if (r != kExitSuccess) {
        exitStatus_ = r;
    }
    shutDown();
    return exitStatus_;
}

std::filesystem::path Daemon::calibrationPath() const {
    if (config_.calibrationPath.empty() && cameraRig_)
        return kDefaultCalibrationPath;
    return config_.calibrationPath;
}

void Daemon::loadCalibration(const std::optional<io::RigDescription>& rig) {
    const std::filesystem::path storePath = calibrationPath();
    store_.emplace(storePath, rig ? std::optional(rig->calibration) : std::nullopt);
    if (const std::optional<std::string> problem = store_->load())
        ET_LOG(Error) << *problem
                      << "; running uncalibrated, and the file stays as it is until a new calibration "
                      << "is saved";
    else if (!store_->active())
        ET_LOG(Notice) << "not calibrated yet: run \"everytouch-calib calibrate\"";
    else
        ET_LOG(Info) << "calibration from "
                     << (store_->keepsFile() ? store_->path().string() : std::string("the rig itself"));
    if (store_->active()) {
        drawDisplayThrough(*store_->active());
        adoptExternalCode(*store_->active());
    }
}

std::string Daemon::describeProjector() const {
    if (projector_)
        return projector_->describe();
    if (recordedRig_)
        return "none: a recording shows what it shows";
    if (config_.projector.output == ProjectorOutput::External)
        return "a projector that embeds the code of seed " + std::to_string(config_.projector.seed) +
               " itself, " + std::to_string(config_.projector.delta) + " levels";
    return "none: the code and the calibration images have nowhere to go ([Projector] Output=)";
}

std::optional<io::RigDescription> Daemon::recordedRig() const {
    if (std::optional<io::RigDescription> rig = source_->rig())
        return rig;
    const double frameRate =
        source_->frameRate() > 0.0 ? source_->frameRate() : config_.camera.frameRate.value_or(0.0);
    if (!cameraRig_ || !store_->active() || pattern_.empty() || !(frameRate > 0.0))
        return std::nullopt;
    return io::RigDescription{*store_->active(), config_.projector.delta, frameRate, pattern_};
}

void Daemon::adoptExternalCode(const core::Calibration& calibration) {
    if (!cameraRig_ || config_.projector.output != ProjectorOutput::External ||
        (!pattern_.empty() && pattern_.size() == calibration.projectorSize))
        return;
    core::PatternOptions options;
    options.size = calibration.projectorSize;
    options.seed = config_.projector.seed;
    pattern_ = core::generatePattern(options);
    ET_LOG(Info) << "code: the pattern of seed " << options.seed << " on the projector's "
                 << options.size.width << "x" << options.size.height
                 << " pixels, embedded by the projector itself";
    if (!store_->keepsFile())
        return;
    // Beside the calibration, for the projector's side to show (255 on 1-bits, as a recording's pattern.png).
    const std::filesystem::path file = store_->path().parent_path() / "pattern.png";
    try {
        io::writePatternImage(file, pattern_);
        ET_LOG(Info) << "code: the pattern written to " << file.string();
    } catch (const std::exception& error) {
        ET_LOG(Warning) << "code: the pattern could not be written to " << file.string() << ": "
                        << error.what();
    }
}

void Daemon::drawDisplayThrough(const core::Calibration& calibration) {
    if (!projector_)
        return;
    try {
        projector_->setDisplayToProjector(calibration.displaySize, calibration.displayToProjector);
    } catch (const std::exception& error) {
        ET_LOG(Error) << projector_->describe() << ": " << error.what()
                      << "; the desktop stays where it was drawn";
    }
}

std::vector<io::TouchSink*> Daemon::openOutputs() {
    // The touchscreen first: the desktop waits for it, and what the console and the log show of a frame has
    // then reached the desktop already.
    std::vector<io::TouchSink*> sinks;
    const bool uinputAsked = std::ranges::find(options_.outputs, "uinput") != options_.outputs.end();
    if (uinputAsked || config_.uinput.value_or(cameraRig_)) {
        touchscreen_ = std::make_unique<TouchscreenOutput>([this](const std::string& devnode) {
            inbox_.post([this, devnode] {
                devicePath_ = devnode;
                if (bus_)
                    bus_->propertiesChanged({bus::kPropertyDevicePath});
            });
        });
        if (store_->active())
            touchscreen_->applyCalibration(*store_->active());
        else
            ET_LOG(Notice)
                << "the virtual touchscreen appears once everytouchd is calibrated: its size comes from "
                   "the calibration";
        sinks.push_back(touchscreen_.get());
    }
    // A person at the terminal sees the touches; the journal of a service would only fill up with them.
    if (!options_.service) {
        console_ = std::make_unique<io::ConsoleSink>();
        sinks.push_back(console_.get());
    }
    if (!options_.touchLog.empty()) {
        touchLog_ = std::make_unique<io::TouchLogWriter>(options_.touchLog);
        sinks.push_back(touchLog_.get());
    }
    return sinks;
}

void Daemon::startFrameLoop(std::vector<io::TouchSink*> sinks) {
    LoopOptions loopOptions;
    loopOptions.maxFrames = options_.maxFrames;
    loopOptions.queueCapacity = kQueueFrames;
    // Sim and replay running fast can wait for the pipeline; a paced stream behaves like a camera.
    loopOptions.overflow = options_.fast ? FrameQueue::Overflow::Block : FrameQueue::Overflow::DropOldest;
    if (!options_.fast)
        loopOptions.stallAfter = kCameraStall;
    core::DetectionOptions detection;
    detection.correctCalibration = config_.correctCalibration;
    pipeline_ = std::make_unique<core::TouchPipeline>(detection);
    loop_ = std::make_unique<FrameLoop>(
        *source_, *pipeline_, std::move(sinks), recorder_.get(), loopOptions, pipelineSettings(),
        [this] { inbox_.post([this] { onLoopNews(); }); },
        [this](const core::PipelineSettings& settings) {
            if (!touchscreen_ || !settings.calibration)
                return;
            try {
                touchscreen_->applyCalibration(*settings.calibration);
            } catch (const std::exception& error) {
                ET_LOG(Error) << "virtual touchscreen: " << error.what() << "; it keeps its previous size";
            }
        });
    snapshots_ = std::make_unique<SnapshotRequests>(
        event_.get(), *loop_, inbox_, [this](SnapshotKind kind, const TappedPair& tapped, cv::Mat& image) {
            renderSnapshot(kind, tapped.pair, tapped.detection.get(), store_->active(), image);
        });
    loop_->start();
}

int Daemon::startEventLoop() {
    sd_event* event = nullptr;
    int r = sd_event_default(&event);
    event_.reset(event);
    if (r < 0)
        return r;
    const std::pair<int, sd_event_signal_handler_t> handlers[] = {
        {SIGTERM, onStopSignal}, {SIGINT, onStopSignal}, {SIGHUP, onReloadSignal}};
    for (const auto& [signal, handler] : handlers) {
        sd_event_source* source = nullptr;
        r = sd_event_add_signal(event_.get(), &source, signal, handler, this);
        if (r < 0)
            return r;
        eventSources_.emplace_back(source);
    }
    if ((r = inbox_.attach(event_.get())) < 0)
        return r;
    sd_event_source* source = nullptr;
    r = sd_event_add_time_relative(event_.get(), &source, CLOCK_MONOTONIC, kStatusIntervalUsec, 0,
                                   onStatusTimer, this);
    if (r < 0)
        return r;
    eventSources_.emplace_back(source);
    r = sd_event_add_time_relative(event_.get(), &source, CLOCK_MONOTONIC, 0, 0, onContactsTimer, this);
    if (r < 0)
        return r;
    contactsTimer_.reset(source);
    return sd_event_source_set_enabled(source, SD_EVENT_OFF);
}

void Daemon::connectBus() {
    bus_ = std::make_unique<BusService>(*this);
    std::string failedStep;
    const int r = bus_->connect(event_.get(), failedStep);
    if (r >= 0) {
        ET_LOG(Info) << "on the system bus as " << bus::kBusName;
        return;
    }
    bus_.reset();
    const std::string problem = "cannot " + failedStep + ": " + std::strerror(-r);
    if (options_.service)
        throw std::runtime_error(problem);
    ET_LOG(Notice) << problem << "; running without the D-Bus interface";
}

void Daemon::startWatchdog() {
    if (sd_watchdog_enabled(0, &watchdogUsec_) <= 0)
        return;
    sd_event_source* source = nullptr;
    if (sd_event_add_time_relative(event_.get(), &source, CLOCK_MONOTONIC, watchdogUsec_ / 2, 0, onWatchdog,
                                   this) >= 0)
        eventSources_.emplace_back(source);
}

DaemonState Daemon::state() const {
    if (!ready_)
        return DaemonState::Starting;
    if (loop_ && loop_->failure())
        return DaemonState::Failed;
    if (calibration_)
        return DaemonState::Calibrating;
    // Detection runs on every pair once calibrated with the code known, unless a stage keeps failing, the
    // camera is gone or stalled, or its frames do not fit the calibration.
    if (!calibrated() || pattern_.empty() || projectorProblem_ || !loop_ || loop_->failing() ||
        loop_->sourceLost() || loop_->idle())
        return DaemonState::Degraded;
    // Detection goes on, but its touches land beside the fingers until someone calibrates.
    if (!loop_->calibrationProblem().empty())
        return DaemonState::Degraded;
    return DaemonState::Running;
}

std::string Daemon::stateReason() const {
    switch (state()) {
        case DaemonState::Degraded:
            if (const std::optional<std::string> lost = loop_ ? loop_->sourceLost() : std::nullopt)
                return "camera lost, asking it again: " + *lost;
            if (!calibrated())
                return "not calibrated (run everytouch-calib calibrate)";
            if (projectorProblem_)
                return "not detecting: " + *projectorProblem_;
            if (pattern_.empty() && cameraRig_)
                return "not detecting (the projected code is not known: set [Projector] Output=overlay for "
                       "the code over the desktop, window for the daemon's own projector window, or external "
                       "for a projector that embeds it, see everytouchd.conf(5))";
            if (const std::string problem = loop_ ? loop_->calibrationProblem() : std::string();
                !problem.empty() && !loop_->idle() && !loop_->failing())
                return "the calibration no longer fits: " + problem +
                       "; until it is corrected or \"everytouch-calib calibrate table\" runs, touches may "
                       "land beside the fingers or be held back";
            return "not detecting (" + (loop_ ? loop_->idleReason() : std::string("no frames yet")) + ")";
        case DaemonState::Failed:
            return loop_ ? loop_->failure().value_or("") : std::string();
        default:
            return {};
    }
}

core::PipelineSettings Daemon::pipelineSettings() const {
    return core::PipelineSettings{store_->active(), pattern_, touchHeightMm_,
                                  calibration_ == nullptr && !projectorProblem_};
}

const std::optional<core::Calibration>& Daemon::activeCalibration() const {
    static const std::optional<core::Calibration> none;
    return store_ ? store_->active() : none;
}

LoopStatistics Daemon::statistics() const {
    return loop_ ? loop_->statistics() : LoopStatistics{};
}

void Daemon::refreshState() {
    if (!ready_)
        return;
    if (std::optional<std::string> now = projector_ ? projector_->problem() : std::nullopt;
        now != projectorProblem_) {
        projectorProblem_ = std::move(now);
        applySettings();  // no detection, and no contact held, while the table shows no code
    }
    std::vector<const char*> changed;
    if (const DaemonState now = state(); now != reportedState_) {
        reportedState_ = now;
        changed.push_back(bus::kPropertyState);
    }
    if (const bool now = calibrated(); now != reportedCalibrated_) {
        reportedCalibrated_ = now;
        changed.push_back(bus::kPropertyCalibrated);
    }
    // A camera lost or back changes why the state is degraded while it stays degraded.
    if (std::string now = stateReason(); now != reportedReason_) {
        reportedReason_ = std::move(now);
        changed.push_back(bus::kPropertyStateReason);
    }
    if (changed.empty())
        return;
    if (bus_)
        bus_->propertiesChanged(changed);
    notifyStatus();
}

void Daemon::notifyStatus() {
    std::string status;
    switch (state()) {
        case DaemonState::Starting:
            status = "Starting";
            break;
        case DaemonState::Running:
        case DaemonState::Degraded: {
            const LoopStatistics statistics = loop_->statistics();
            const std::string rates = rigName_ + ": " + formatDouble("%.1f", statistics.frameRate) +
                                      " frames/s, " + std::to_string(statistics.dropped) + " dropped";
            if (state() == DaemonState::Running) {
                status = "Running on " + rates;
                break;
            }
            status = stateReason();
            status[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(status[0])));
            // A lost camera has no rates to tell.
            if (!loop_->sourceLost())
                status += ", on " + rates;
            break;
        }
        case DaemonState::Calibrating:
            status = "Calibrating";
            break;
        case DaemonState::Failed:
            status = "Failed: " + loop_->failure().value_or("");
            break;
    }
    sd_notifyf(0, "STATUS=%s", status.c_str());
}

void Daemon::applySettings() {
    if (loop_)
        loop_->setSettings(pipelineSettings());
}

void Daemon::onLoopNews() {
    if (loop_->finished()) {
        if (const std::optional<std::string> failure = loop_->failure()) {
            ET_LOG(Error) << *failure;
            exitStatus_ = kExitFailure;
            refreshState();
        }
        sd_event_exit(event_.get(), exitStatus_);
        return;
    }
    if (std::optional<core::CalibrationCorrection> correction = loop_->takeCorrection())
        adoptCorrection(*correction);
    refreshState();  // detection may have started or stopped
    emitContacts();
}

void Daemon::adoptCorrection(const core::CalibrationCorrection& correction) {
    // A calibration made or reset since the pipeline corrected the one it had is newer than the correction.
    // A correction keeps the intrinsics and the keystone, and the projector's pose against the table unless
    // the table moved, which keeps the projector's pose against the camera.
    const std::optional<core::Calibration>& active = store_->active();
    if (calibration_ || !active || active->cameraMatrix != correction.calibration.cameraMatrix ||
        active->displayToProjector != correction.calibration.displayToProjector)
        return;
    const auto cameraToProjector = [](const core::Calibration& calibration) {
        return calibration.tableToProjector * calibration.tableToCamera.inverse();
    };
    if (correction.what == "table"
            ? !cameraToProjector(*active).isApprox(cameraToProjector(correction.calibration))
            : !active->tableToProjector.isApprox(correction.calibration.tableToProjector))
        return;
    store_->activate(correction.calibration);
    applySettings();
    std::string kept = "; it is active, not saved (this rig keeps no calibration file)";
    if (store_->keepsFile()) {
        try {
            store_->saveKeepingBackup();
            kept = "; saved to " + store_->path().string() + ", the previous file kept as " +
                   store_->backupPath().string();
        } catch (const std::exception& error) {
            kept = std::string("; it is active, but could not be saved: ") + error.what();
        }
    }
    ET_LOG(Notice) << "calibration corrected: the " << correction.what << " moved; the code lay "
                   << formatDouble("%.2f", correction.beforePx) << " projector px from where the calibration "
                   << "put it, " << formatDouble("%.2f", correction.afterPx) << " px now ("
                   << correction.tiles << " tiles)" << kept;
    if (bus_)
        bus_->calibrationCorrected(correction.beforePx, correction.afterPx, correction.what);
}

void Daemon::emitContacts() {
    if (!bus_)
        return;
    std::uint64_t version = 0;
    const core::Contacts contacts = loop_->contacts(version);
    if (version == contactsVersion_)
        return;
    const Clock::time_point now = Clock::now();
    if (now - lastContactsSignal_ < kContactsSignalInterval) {
        const auto due = std::chrono::duration_cast<std::chrono::microseconds>(lastContactsSignal_ +
                                                                               kContactsSignalInterval - now);
        sd_event_source_set_time_relative(contactsTimer_.get(), static_cast<std::uint64_t>(due.count()));
        sd_event_source_set_enabled(contactsTimer_.get(), SD_EVENT_ONESHOT);
        return;
    }
    contactsVersion_ = version;
    lastContactsSignal_ = now;
    bus_->contacts(contacts);
}

void Daemon::setTouchHeightMm(double heightMm) {
    if (!std::isfinite(heightMm) || heightMm < kMinTouchHeightMm || heightMm > kMaxTouchHeightMm)
        throw BusError(SD_BUS_ERROR_INVALID_ARGS, "TouchHeightMm must be from " +
                                                      formatDouble("%g", kMinTouchHeightMm) + " to " +
                                                      formatDouble("%g", kMaxTouchHeightMm) + " mm, not " +
                                                      formatDouble("%g", heightMm));
    if (heightMm == touchHeightMm_)
        return;
    touchHeightMm_ = heightMm;
    applySettings();
    if (bus_)
        bus_->propertiesChanged({bus::kPropertyTouchHeightMm});
    ET_LOG(Info) << "touch height set to " << heightMm << " mm";
}

void Daemon::calibrate(std::string_view request, const CalibrationOptions& options) {
    std::optional<std::vector<CalibrationStep>> steps = calibrationSteps(request);
    if (!steps)
        throw BusError(SD_BUS_ERROR_INVALID_ARGS, "Unknown calibration step \"" + std::string(request) +
                                                      "\"; expected " + kCalibrationRequests);
    if (calibration_)
        throw BusError(bus::kErrorBusy,
                       "A calibration is already running; wait for its CalibrationFinished signal");
    if (loop_->finished())
        throw BusError(bus::kErrorNoCamera, "The camera delivers no frames");
    if (!projector_ && !recordedRig_)
        throw BusError(bus::kErrorCalibrationFailed,
                       "This rig has no projector output, so the calibration cannot show its chessboard; the "
                       "current calibration stays active");
    if (projectorSize_.empty() && !store_->active())
        throw BusError(
            bus::kErrorCalibrationFailed,
            "The projector's size is unknown: this rig has no projector output and no calibration");

    const cv::Size projectorSize = !projectorSize_.empty() ? projectorSize_ : store_->active()->projectorSize;
    accuracyTargetsShown_ = false;  // the calibration's images replace them and give the display back
    calibration_ = std::make_unique<CalibrationRunner>(
        loop_->tap(), projector_.get(), kQueueFrames,
        CalibrationJob{std::move(*steps), options, store_->active(), projectorSize},
        [this](const std::string& step, double fraction, const std::string& message) {
            inbox_.post([this, step, fraction, message] {
                if (bus_)
                    bus_->calibrationProgress(step, fraction, message);
            });
        },
        [this](const CalibrationOutcome& outcome) {
            inbox_.post([this, outcome] { finishCalibration(outcome); });
        });
    applySettings();  // no detection while the projector shows calibration images
    refreshState();
}

void Daemon::showAccuracyTargets() {
    if (calibration_)
        throw BusError(bus::kErrorBusy, "A calibration is running; wait for its CalibrationFinished signal");
    if (!projector_)
        throw BusError(SD_BUS_ERROR_NOT_SUPPORTED,
                       "This rig has no projector output to show the accuracy test's circles on; a recording "
                       "shows what it shows");
    if (!store_->active())
        throw BusError(bus::kErrorNotCalibrated,
                       "The circles are drawn over the display through the calibration, and there is none; "
                       "calibrate first");
    const core::Calibration& calibration = *store_->active();
    projector_->show(core::drawThroughKeystone(core::drawAccuracyTargets(calibration.displaySize),
                                               calibration.displayToProjector, projector_->size()));
    if (!accuracyTargetsShown_)
        ET_LOG(Info) << "the accuracy test's circles are on " << projector_->describe();
    accuracyTargetsShown_ = true;
}

void Daemon::hideAccuracyTargets() noexcept {
    if (!accuracyTargetsShown_)
        return;
    accuracyTargetsShown_ = false;
    projector_->release();
    ET_LOG(Info) << "the accuracy test's circles are gone; " << projector_->describe()
                 << " shows the display";
}

void Daemon::finishCalibration(const CalibrationOutcome& outcome) {
    if (!calibration_)
        return;
    calibration_.reset();
    std::string message = outcome.message;
    if (outcome.ok) {
        core::Calibration calibration = *outcome.calibration;
        if (projector_ && !projector_->drawsDisplayThroughKeystone()) {
            // The desktop reaches the panel as it is, not through the keystone the table step fitted.
            calibration.displaySize = calibration.projectorSize;
            calibration.displayToProjector = Eigen::Matrix3d::Identity();
            message += "; " + describeShape(core::displayShapeOnTable(calibration));
        }
        store_->activate(calibration);
        drawDisplayThrough(calibration);
        adoptExternalCode(calibration);
        ET_LOG(Notice) << message << "; SaveCalibration keeps it";
    } else {
        ET_LOG(Warning) << "calibration failed: " << message << "; the previous calibration stays active";
    }
    applySettings();  // detection again, with the new calibration if there is one
    if (bus_)
        bus_->calibrationFinished(outcome.ok, message, outcome.rmsPx);
    refreshState();
}

void Daemon::saveCalibration() {
    if (!store_->keepsFile())
        throw BusError(SD_BUS_ERROR_NOT_SUPPORTED,
                       "This rig uses its own calibration and no calibration file is configured; set "
                       "[Calibration] Path= in " +
                           options_.configPath.string() + " to keep one");
    if (!store_->active())
        throw BusError(bus::kErrorNotCalibrated, "There is no calibration to save; calibrate first");
    try {
        store_->save();
    } catch (const std::exception& error) {
        throw BusError(SD_BUS_ERROR_FAILED, std::string("Cannot save the calibration: ") + error.what());
    }
    ET_LOG(Notice) << "calibration saved to " << store_->path().string();
}

void Daemon::resetCalibration() {
    if (calibration_)
        throw BusError(bus::kErrorBusy, "A calibration is running; wait for its CalibrationFinished signal");
    if (const std::optional<std::string> problem = store_->load())
        ET_LOG(Error) << *problem << "; running uncalibrated";
    applySettings();
    if (store_->active()) {
        drawDisplayThrough(*store_->active());
        ET_LOG(Notice) << "calibration reset to the one "
                       << (store_->keepsFile() ? "saved in " + store_->path().string()
                                               : std::string("the rig brings"));
    } else {
        ET_LOG(Notice) << "calibration reset: none is saved, so everytouchd is not calibrated";
    }
    refreshState();
}

void Daemon::reloadConfig() {
    DaemonConfig fresh;
    try {
        fresh = loadConfig(options_.configPath, options_.configPath != kDefaultConfigPath);
    } catch (const std::exception& error) {
        const std::string problem = std::string(error.what()) + "; the running configuration stays in effect";
        ET_LOG(Error) << problem;
        throw BusError(bus::kErrorInvalidConfig, problem);
    }
    // Only what the files changed is applied, so a reload keeps a touch height set over the bus.
    if (fresh.touchHeightMm != config_.touchHeightMm)
        setTouchHeightMm(fresh.touchHeightMm);
    const std::pair<bool, const char*> restartOnly[] = {
        {options_.rig.empty() && fresh.rig != config_.rig, "[Camera] Rig"},
        {fresh.uinput != config_.uinput, "[Output] Uinput"},
        {fresh.calibrationPath != config_.calibrationPath, "[Calibration] Path"},
        {fresh.correctCalibration != config_.correctCalibration, "[Calibration] Correct"},
        {fresh.projector != config_.projector, "[Projector]"},
    };
    for (const auto& [changed, key] : restartOnly)
        if (changed)
            ET_LOG(Notice) << key << " changed: it takes effect when everytouchd restarts";
    fresh.projector = config_.projector;  // the code on the table is the one the projector shows
    config_ = fresh;
    ET_LOG(Info) << "configuration reloaded from " << options_.configPath.string();
}

void Daemon::snapshot(sd_bus_message* call, std::string_view what, int fd) {
    const std::optional<SnapshotKind> kind = parseSnapshotKind(what);
    if (!kind)
        throw BusError(SD_BUS_ERROR_INVALID_ARGS,
                       "Unknown snapshot \"" + std::string(what) + "\"; expected " + kSnapshotKinds);
    // Either answer may come after this call returned, so both keep the call alive.
    const std::shared_ptr<sd_bus_message> held(sd_bus_message_ref(call), sd_bus_message_unref);
    snapshots_->add(*kind, fd,
                    SnapshotReply{[this, held] {
                                      if (bus_)
                                          bus_->reply(held.get());
                                  },
                                  [this, held](const char* errorName, const std::string& message) {
                                      if (bus_)
                                          bus_->replyError(held.get(), errorName, message);
                                  }});
}

void Daemon::shutDown() {
    if (!loop_)
        return;
    sd_notify(0, "STOPPING=1");
    calibration_.reset();  // cancels a job still running and waits for its thread
    loop_->stop();
    snapshots_->failAll(bus::kErrorNoCamera, "everytouchd is stopping");
    bus_.reset();
    const LoopStatistics statistics = loop_->statistics();
    ET_LOG(Info) << "processed " << statistics.frames << " frames (" << statistics.pairs << " pairs) in "
                 << formatDouble("%.2f", statistics.seconds) << " s, " << statistics.dropped
                 << " dropped; all contacts released";
    ET_LOG(Info) << "detection took " << formatDouble("%.2f", statistics.pipelineMedianMs)
                 << " ms per pair (median), " << formatDouble("%.2f", statistics.pipelineP99Ms)
                 << " ms (99th percentile)"
                 << (statistics.pipelineFailures
                         ? ", failed on " + std::to_string(statistics.pipelineFailures) + " pairs"
                         : std::string())
                 << (statistics.polaritySwaps
                         ? "; the frames' order was swapped " + std::to_string(statistics.polaritySwaps) +
                               " times by the code's sign"
                         : std::string());
    if (std::isfinite(statistics.mostCalibrationErrorPx))
        ET_LOG(Info) << "the code lay at most " << formatDouble("%.2f", statistics.mostCalibrationErrorPx)
                     << " projector px from where the calibration puts it, "
                     << formatDouble("%.2f", statistics.calibrationErrorPx) << " px at the end";
    if (!statistics.recordingStopped.empty()) {
        // Detection went on to the end, but what was asked for is not all there.
        ET_LOG(Error) << options_.recordDir.string() << " is incomplete: " << statistics.recordingStopped;
        if (exitStatus_ == kExitSuccess)
            exitStatus_ = kExitFailure;
    }
    if (statistics.recordingDropped != 0)
        // A live camera does not wait for the disk: the recording has gaps, which a replay pairs across.
        ET_LOG(Warning) << options_.recordDir.string() << " leaves out " << statistics.recordingDropped
                        << " frames that came while the disk was still writing earlier ones";
    snapshots_.reset();
    loop_.reset();
}

int Daemon::onStopSignal(sd_event_source* source, const struct signalfd_siginfo* info,
                         void* userdata) noexcept {
    auto* daemon = static_cast<Daemon*>(userdata);
    ET_LOG(Info) << "stopping on " << sigabbrev_np(static_cast<int>(info->ssi_signo));
    return sd_event_exit(sd_event_source_get_event(source), daemon->exitStatus_);
}

int Daemon::onReloadSignal(sd_event_source*, const struct signalfd_siginfo*, void* userdata) noexcept {
    try {
        static_cast<Daemon*>(userdata)->reloadConfig();
    } catch (const BusError&) {
        // reloadConfig() has logged why the files were rejected.
    } catch (const std::exception& error) {
        ET_LOG(Error) << "internal error: " << error.what();
    }
    return 0;
}

int Daemon::onWatchdog(sd_event_source* source, uint64_t, void* userdata) noexcept {
    auto* daemon = static_cast<Daemon*>(userdata);
    const auto silent = Clock::now() - daemon->loop_->heartbeat();
    if (silent < std::chrono::microseconds(daemon->watchdogUsec_)) {
        sd_notify(0, "WATCHDOG=1");
        daemon->watchdogWarned_ = false;
    } else if (!daemon->watchdogWarned_) {
        ET_LOG(Warning) << "the pipeline thread has stalled; no longer telling the watchdog that all is well";
        daemon->watchdogWarned_ = true;
    }
    sd_event_source_set_time_relative(source, daemon->watchdogUsec_ / 2);
    return sd_event_source_set_enabled(source, SD_EVENT_ONESHOT);
}

int Daemon::onStatusTimer(sd_event_source* source, uint64_t, void* userdata) noexcept {
    try {
        static_cast<Daemon*>(userdata)->notifyStatus();
    } catch (const std::exception& error) {
        ET_LOG(Error) << "internal error: " << error.what();
    }
    sd_event_source_set_time_relative(source, kStatusIntervalUsec);
    return sd_event_source_set_enabled(source, SD_EVENT_ONESHOT);
}

int Daemon::onContactsTimer(sd_event_source*, uint64_t, void* userdata) noexcept {
    try {
        static_cast<Daemon*>(userdata)->emitContacts();
    } catch (const std::exception& error) {
        ET_LOG(Error) << "internal error: " << error.what();
    }
    return 0;
}

}  // namespace everytouch::service

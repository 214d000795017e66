#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/console_sink.h"
#include "io/frame_source.h"
#include "io/handles.h"
#include "io/projector_output.h"
#include "io/recording.h"
#include "io/rig_spec.h"
#include "io/touch_log.h"
#include "service/bus_error.h"
#include "service/calibration_job.h"
#include "service/calibration_runner.h"
#include "service/calibration_store.h"
#include "service/config.h"
#include "service/daemon_options.h"
#include "service/frame_loop.h"
#include "service/main_loop_inbox.h"
#include "service/snapshot.h"
#include "service/snapshot_requests.h"
#include "service/touchscreen_output.h"

namespace everytouch::service {

class BusService;

// Exit statuses of everytouchd (its --help and everytouchd(8) list them).
inline constexpr int kExitSuccess = 0;
inline constexpr int kExitFailure = 1;        // the camera, the pipeline or a sink failed while running
inline constexpr int kExitBadInput = 2;       // an option, the configuration, the rig or a file is wrong
inline constexpr int kExitNotConfigured = 6;  // a service without a camera (LSB: "program is not configured")

enum class DaemonState {
    Starting,     // until the frames flow
    Running,      // calibrated and detecting touches
    Calibrating,  // a Calibrate job runs
    Degraded,     // running without detecting: no usable calibration, no known code, or a failing stage
    Failed,       // the camera or the pipeline failed; the daemon is about to exit
};
const char* toString(DaemonState state);

// everytouchd: the frame loop, the calibration, the configuration and the D-Bus interface around them, driven
// by one sd-event loop on the main thread. Start-up is a straight chain of steps in run().
class Daemon {
public:
    explicit Daemon(DaemonOptions options);
    ~Daemon();
    Daemon(const Daemon&) = delete;
    Daemon& operator=(const Daemon&) = delete;

    // Blocks SIGTERM, SIGINT and SIGHUP for this thread and every thread started after it, so that sd-event
    // receives them, and ignores SIGPIPE: a client that closes its end of a Snapshot descriptor must not kill
    // the daemon. Call first thing in main().
    static void prepareSignals();

    // Runs until SIGTERM or SIGINT, the end of the stream or a failure and returns the exit status. Throws
    // io::InputError for bad options, configuration or rig (exit status kExitBadInput).
    int run();

    // What the bus shows. Main thread only, like everything below.
    DaemonState state() const;
    // Why the state is degraded or failed, in words; empty otherwise.
    std::string stateReason() const;
    const std::string& rig() const { return rigName_; }
    // Where the code and the calibration images come from, in words.
    const std::string& projector() const { return projectorName_; }
    // The active calibration, where the display's size and its size on the table come from; none when not
    // calibrated.
    const std::optional<core::Calibration>& activeCalibration() const;
    bool calibrated() const { return activeCalibration().has_value(); }
    LoopStatistics statistics() const;
    double touchHeightMm() const { return touchHeightMm_; }
    const std::string& devicePath() const { return devicePath_; }

    // What the bus offers; each throws BusError.
    void setTouchHeightMm(double heightMm);
    void calibrate(std::string_view request, const CalibrationOptions& options);
    void saveCalibration();
    void resetCalibration();
    void reloadConfig();
    // Replies to `call` once the next frame pair has been written to `fd` as a PNG.
    void snapshot(sd_bus_message* call, std::string_view what, int fd);
    // The accuracy test's circles on the projector, over the display through the active calibration, while
    // detection goes on: until hideAccuracyTargets() or a calibration starts.
    void showAccuracyTargets();
    void hideAccuracyTargets() noexcept;

private:
    void loadCalibration(const std::optional<io::RigDescription>& rig);
    // Has the projector draw the desktop through the keystone of `calibration`, the one now active, as the
    // touches are mapped through it. A recording shows what it was recorded showing.
    void drawDisplayThrough(const core::Calibration& calibration);
    // On a camera rig whose projector embeds the code itself ([Projector] Output=external): the code is the
    // pattern of the configured seed at the calibration's projector size, also written beside the
    // calibration file for the projector's side.
    void adoptExternalCode(const core::Calibration& calibration);
    // What a recording says of the rig: its own description, or a camera rig's calibration, code and frame
    // rate once all are known.
    std::optional<io::RigDescription> recordedRig() const;
    std::string describeProjector() const;
    // The calibration file: the configuration's, a camera rig's default, or none (the rig's own).
    std::filesystem::path calibrationPath() const;
    std::vector<io::TouchSink*> openOutputs();
    int startEventLoop();
    void startFrameLoop(std::vector<io::TouchSink*> sinks);
    void connectBus();
    void startWatchdog();
    void onLoopNews();
    void emitContacts();
    void finishCalibration(const CalibrationOutcome& outcome);
    // The pipeline corrected the calibration (the camera or the table moved, or the projector's image crept):
    // it becomes the active one, is saved when the daemon keeps a file, and is announced.
    void adoptCorrection(const core::CalibrationCorrection& correction);
    void applySettings();
    core::PipelineSettings pipelineSettings() const;
    void refreshState();
    void notifyStatus();
    void shutDown();

    static int onStopSignal(sd_event_source* source, const struct signalfd_siginfo* info,
                            void* userdata) noexcept;
    static int onReloadSignal(sd_event_source* source, const struct signalfd_siginfo* info,
                              void* userdata) noexcept;
    static int onWatchdog(sd_event_source* source, uint64_t usec, void* userdata) noexcept;
    static int onStatusTimer(sd_event_source* source, uint64_t usec, void* userdata) noexcept;
    static int onContactsTimer(sd_event_source* source, uint64_t usec, void* userdata) noexcept;

    DaemonOptions options_;
    DaemonConfig config_;
    std::string rigName_;
    std::string projectorName_;
    bool cameraRig_ = false;
    std::string devicePath_;  // the virtual touchscreen's event node; empty without one
    double touchHeightMm_ = 0.0;

    std::unique_ptr<io::FrameSource> source_;
    std::unique_ptr<io::ProjectorOutput> projector_;  // none for a recording
    // Why the projector shows no code now, as last seen: no detection meanwhile.
    std::optional<std::string> projectorProblem_;
    bool accuracyTargetsShown_ = false;
    bool recordedRig_ = false;  // the frames come from a recording
    cv::Size projectorSize_;    // the panel calibration images are drawn for
    std::unique_ptr<io::RecordingWriter> recorder_;
    std::unique_ptr<io::ConsoleSink> console_;
    std::unique_ptr<io::TouchLogWriter> touchLog_;
    std::unique_ptr<TouchscreenOutput> touchscreen_;
    std::optional<CalibrationStore> store_;

    io::Event event_;
    MainLoopInbox inbox_;
    std::vector<io::EventSource> eventSources_;
    io::EventSource contactsTimer_;
    std::unique_ptr<BusService> bus_;
    cv::Mat pattern_;  // the code the rig projects; empty when the rig does not say
    std::unique_ptr<core::PairPipeline> pipeline_;
    std::unique_ptr<FrameLoop> loop_;
    std::unique_ptr<CalibrationRunner> calibration_;  // while a Calibrate job runs
    std::unique_ptr<SnapshotRequests> snapshots_;

    bool ready_ = false;
    DaemonState reportedState_ = DaemonState::Starting;
    bool reportedCalibrated_ = false;
    std::string reportedReason_;
    std::uint64_t contactsVersion_ = 0;
    std::chrono::steady_clock::time_point lastContactsSignal_;
    std::uint64_t watchdogUsec_ = 0;
    bool watchdogWarned_ = false;
    int exitStatus_ = kExitSuccess;
};

}  // namespace everytouch::service

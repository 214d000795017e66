// everytouchd on a GigE Vision camera: Aravis's fake camera served by this process on the loopback interface,
// the daemon as a separate process on a private system bus, as a service would run it.
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/accuracy_targets.h"
#include "core/code_overlay.h"
#include "core/embedding.h"
#include "core/pattern.h"
#include "core/projector_chessboard.h"
#include "io/calibration_file.h"
#include "service/table_set_up_step.h"
#include "sim/rig_geometry.h"
#include "sim/simulator.h"
#include "support/bus_commands.h"
#include "support/calibration_checks.h"
#include "support/compositor.h"
#include "support/desktop_window.h"
#include "support/fake_gige_camera.h"
#include "support/notify_socket.h"
#include "support/private_bus.h"
#include "support/process.h"
#include "support/screen_grabs.h"
#include "support/temp_dir.h"
#include "support/virtual_display.h"
#include "support/wait.h"
#include "support/wayland_compositor.h"

namespace everytouch {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

// Generous for two busy cores; every wait ends as soon as its condition holds.
constexpr auto kStartTimeout = 60s;
constexpr auto kExitTimeout = 30s;

// The content the window shows now (O, compressed to [delta, 255 - delta]): the mean of two screens of
// opposite polarity, grabbed as soon as the window has presented the other one.
cv::Mat windowContent(const test::VirtualDisplay& display) {
    const cv::Mat first = display.grab();
    for (int attempt = 0; attempt < 100; ++attempt) {
        const cv::Mat second = display.grab();
        if (cv::norm(first, second, cv::NORM_INF) > 0.0) {
            cv::Mat content;
            cv::addWeighted(first, 0.5, second, 0.5, 0.0, content);
            return content;
        }
        std::this_thread::sleep_for(1ms);
    }
    return first;
}

// A GigE Vision camera whose frames the simulated rig renders, its projector showing what the screen shows.
std::unique_ptr<test::FakeGigeCamera> filmingTheScreen(const sim::SimParameters& rig,
                                                       std::shared_ptr<sim::Simulator> simulator,
                                                       std::shared_ptr<test::VirtualDisplay> display) {
    return std::make_unique<test::FakeGigeCamera>(
        rig.cameraSize, [simulator, display](std::uint64_t frameId, ArvPixelFormat, cv::Mat& image) {
            simulator->projectImage(windowContent(*display));
            core::Frame frame;
            sim::FrameTruth truth;
            simulator->render(frameId, frame, truth);
            cv::cvtColor(frame.image, image, cv::COLOR_BGR2RGB);
        });
}

class CameraServiceTest : public ::testing::Test {
protected:
    static constexpr int kRememberedFrames = 120;

    CameraServiceTest() : bus_(POLICY_FILE, false) { plugIn(); }

    // A camera at 127.0.0.1 that films a ramp moving by a level each frame: every frame differs from the
    // last few hundred.
    void plugIn() {
        camera_ = std::make_unique<test::FakeGigeCamera>(
            cv::Size(320, 240), [this](std::uint64_t frameId, ArvPixelFormat, cv::Mat& image) {
                for (int y = 0; y < image.rows; ++y)
                    for (int x = 0; x < image.cols; ++x)
                        image.at<uchar>(y, x) = static_cast<uchar>((x + y + frameId) % 256);
                std::lock_guard lock(mutex_);
                sent_.push_back(image.clone());
                if (sent_.size() > kRememberedFrames)
                    sent_.pop_front();
            });
    }

    void TearDown() override {
        ::unsetenv("WAYLAND_DISPLAY");
        if (daemon_ && HasFailure())
            std::cerr << "---- everytouchd log ----\n" << daemon_->output() << "-------------------------\n";
    }

    // Starts everytouchd on the camera with `cameraKeys` in [Camera], `moreSections` after the others and
    // `moreArguments` on its command line; it has no virtual touchscreen here.
    void startDaemon(const std::string& cameraKeys, const std::string& moreSections = "",
                     const std::vector<std::string>& moreArguments = {}) {
        std::ofstream(dir_ / "everytouchd.conf")
            << "[Camera]\nRig=aravis:" << test::FakeGigeCamera::kAddress << "\n"
            << cameraKeys
            << "[Output]\nUinput=no\n[Calibration]\nPath=" << (dir_ / "calibration.yml").string() << "\n"
            << moreSections;
        notify_.reset();  // a daemon started before has its socket
        notify_ = std::make_unique<test::NotifySocket>(dir_ / "notify.socket");
        std::vector<std::string> arguments{EVERYTOUCHD_PATH, "--config", (dir_ / "everytouchd.conf").string(),
                                           "--log", (dir_ / "touch.log").string()};
        arguments.insert(arguments.end(), moreArguments.begin(), moreArguments.end());
        daemon_ = std::make_unique<test::BackgroundProcess>(
            arguments, dir_ / "everytouchd.log",
            std::vector<std::pair<std::string, std::string>>{{"NOTIFY_SOCKET", notify_->path().string()}});
    }

    // Waits for a status message systemd would show that begins with `prefix`.
    bool waitForStatus(const std::string& prefix) {
        const auto deadline = std::chrono::steady_clock::now() + kStartTimeout;
        while (std::chrono::steady_clock::now() < deadline) {
            for (const std::string& message : notify_->messages())
                if (message.starts_with(prefix) || message.find("\n" + prefix) != std::string::npos)
                    return true;
            std::this_thread::sleep_for(50ms);
        }
        return false;
    }

    bool waitForLog(const std::string& text) { return daemon_->waitForOutput(text, kStartTimeout); }

    std::string get(const std::string& name) {
        return test::runProcess(test::property("get-property", name)).out;
    }

    // Waits until the daemon's property `name`, as busctl prints it, contains `text`.
    bool waitForProperty(const std::string& name, const std::string& text) {
        const auto deadline = std::chrono::steady_clock::now() + 20s;
        while (std::chrono::steady_clock::now() < deadline) {
            if (get(name).find(text) != std::string::npos)
                return true;
            std::this_thread::sleep_for(50ms);
        }
        return false;
    }

    // Replaces the camera by one filming the screen: a display of the test's own (DISPLAY) whose content
    // the simulated rig of the table-setup scenario projects onto its table.
    void filmTheScreen() {
        rig_.scenario = "table-setup";
        simulator_ = std::make_shared<sim::Simulator>(rig_, sim::rigPattern(rig_));
        display_ = std::make_shared<test::VirtualDisplay>(rig_.projectorSize);
        ::setenv("DISPLAY", display_->name().c_str(), 1);
        ::unsetenv("WAYLAND_DISPLAY");
        camera_.reset();
        camera_ = filmingTheScreen(rig_, simulator_, display_);
    }

    // Starts everytouchd on the camera filming the screen, its projector `output` (window or overlay) on
    // that screen with the rig's code; whether it got ready.
    [[nodiscard]] bool startProjecting(const std::string& output) {
        startDaemon("PixelFormat=RGB8\nFrameRate=20\n", "[Projector]\nOutput=" + output +
                                                            "\nSeed=" + std::to_string(rig_.seed) +
                                                            "\nDelta=" + std::to_string(rig_.delta) + "\n");
        return notify_->waitFor("READY=1", kStartTimeout);
    }

    void stopDaemon() {
        daemon_->signal(SIGTERM);
        EXPECT_EQ(daemon_->wait(kExitTimeout), 0) << "everytouchd did not stop cleanly on SIGTERM";
    }

    // Whether a `camera` snapshot shows a frame the camera sent lately.
    bool snapshotShowsTheCamera() {
        const std::filesystem::path file = dir_ / "camera.png";
        const test::ProcessResult snapshot =
            test::runProcess({EVERYTOUCH_CALIB_PATH, "snapshot", "camera", file.string()});
        EXPECT_EQ(snapshot.exitCode, 0) << snapshot.err;
        const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
        EXPECT_EQ(image.type(), CV_8UC1);
        EXPECT_EQ(image.size(), cv::Size(320, 240));
        return !image.empty() && sentRecently(image);
    }

    bool sentRecently(const cv::Mat& image) {
        std::lock_guard lock(mutex_);
        for (const cv::Mat& sent : sent_)
            if (sent.size() == image.size() && cv::norm(sent, image, cv::NORM_INF) == 0.0)
                return true;
        return false;
    }

    test::TempDir dir_;
    test::PrivateBus bus_;
    std::mutex mutex_;
    std::deque<cv::Mat> sent_;
    sim::SimParameters rig_;  // filmed by filmTheScreen()
    std::shared_ptr<sim::Simulator> simulator_;
    std::shared_ptr<test::VirtualDisplay> display_;
    std::unique_ptr<test::FakeGigeCamera> camera_;
    std::unique_ptr<test::NotifySocket> notify_;
    std::unique_ptr<test::BackgroundProcess> daemon_;
};

TEST_F(CameraServiceTest, StreamsTheCameraAndSaysItIsNotCalibratedYet) {
    startDaemon("PixelFormat=Mono8\nFrameRate=30\n");
    ASSERT_TRUE(notify_->waitFor("READY=1", kStartTimeout)) << "everytouchd did not get ready";
    EXPECT_EQ(get("State"), "s \"degraded\"\n");
    EXPECT_EQ(get("Rig"), "s \"aravis:127.0.0.1\"\n");
    double frameRate = 0.0;
    const auto deadline = std::chrono::steady_clock::now() + kStartTimeout;
    while (std::chrono::steady_clock::now() < deadline && !(frameRate > 25.0 && frameRate < 35.0)) {
        std::this_thread::sleep_for(100ms);
        std::sscanf(get("FrameRate").c_str(), "d %lf", &frameRate);
    }
    EXPECT_GT(frameRate, 25.0);
    EXPECT_LT(frameRate, 35.0);
    EXPECT_EQ(get("DroppedFrames"), "t 0\n");

    // What the camera sees, as the camera sent it.
    EXPECT_TRUE(snapshotShowsTheCamera()) << "the snapshot is no frame the camera sent lately";

    const test::ProcessResult status = test::runProcess({EVERYTOUCH_CALIB_PATH, "status"});
    EXPECT_THAT(status.out, HasSubstr("State:              degraded"));
    EXPECT_THAT(status.out, HasSubstr("Calibrated:         no"));
    EXPECT_THAT(status.out,
                HasSubstr("Why:                not calibrated (run everytouch-calib calibrate)\n"));

    stopDaemon();
}

TEST_F(CameraServiceTest, ACameraThatGoesAwayIsAskedAgainUntilItIsBackWithoutARestart) {
    startDaemon("PixelFormat=Mono8\nFrameRate=60\n");
    ASSERT_TRUE(notify_->waitFor("READY=1", kStartTimeout)) << "everytouchd did not get ready";
    camera_->unplug();
    ASSERT_TRUE(
        waitForStatus("STATUS=Camera lost, asking it again: camera Aravis Fake (serial everytouch-test), "
                      "320x240 Mono8 at 60 frames/s: no complete frame for 0.3 s"))
        << "the status does not say the camera is lost";
    EXPECT_EQ(get("State"), "s \"degraded\"\n");
    EXPECT_THAT(get("StateReason"), ::testing::StartsWith("s \"camera lost, asking it again: "));
    plugIn();
    ASSERT_TRUE(waitForLog("camera: frames come again")) << "the camera was not taken back";
    EXPECT_TRUE(daemon_->running());
    EXPECT_TRUE(snapshotShowsTheCamera()) << "the snapshot is no frame the camera sent after it came back";
    EXPECT_EQ(get("StateReason"), "s \"not calibrated (run everytouch-calib calibrate)\"\n");
    stopDaemon();
}

TEST_F(CameraServiceTest, AProjectorThatEmbedsTheCodeItselfGivesTheCodeOfItsSeedWrittenBesideTheCalibration) {
    // The calibration of the simulated rig with this camera's sensor.
    sim::SimParameters rig;
    rig.cameraSize = cv::Size(320, 240);
    io::writeCalibrationFile(dir_ / "calibration.yml", sim::rigCalibration(rig));

    // Calibrated, but nothing says what the projector shows.
    startDaemon("PixelFormat=Mono8\nFrameRate=30\n");
    ASSERT_TRUE(notify_->waitFor("READY=1", kStartTimeout)) << "everytouchd did not get ready";
    EXPECT_EQ(get("State"), "s \"degraded\"\n");
    EXPECT_THAT(get("StateReason"),
                HasSubstr("the projected code is not known: set [Projector] Output=overlay"));
    EXPECT_FALSE(std::filesystem::exists(dir_ / "pattern.png"));
    daemon_->signal(SIGTERM);
    ASSERT_EQ(daemon_->wait(kExitTimeout), 0) << "everytouchd did not stop cleanly on SIGTERM";

    startDaemon("PixelFormat=Mono8\nFrameRate=30\n", "[Projector]\nOutput=external\nSeed=7\n");
    ASSERT_TRUE(notify_->waitFor("READY=1", kStartTimeout)) << "everytouchd did not get ready";
    EXPECT_EQ(get("Projector"), "s \"a projector that embeds the code of seed 7 itself, 10 levels\"\n");
    // Detection runs on the camera's pairs: the ramp it films shows no hand, and no code either, which
    // is not a fault.
    std::string state;
    const auto deadline = std::chrono::steady_clock::now() + kStartTimeout;
    while (std::chrono::steady_clock::now() < deadline && (state = get("State")) != "s \"running\"\n")
        std::this_thread::sleep_for(100ms);
    EXPECT_EQ(state, "s \"running\"\n") << get("StateReason");
    core::PatternOptions pattern;
    pattern.size = rig.projectorSize;
    pattern.seed = 7;
    const cv::Mat written = cv::imread((dir_ / "pattern.png").string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(written.type(), CV_8UC1) << "no pattern.png beside the calibration";
    EXPECT_EQ(cv::norm(written, core::generatePattern(pattern) * 255, cv::NORM_INF), 0.0);
    stopDaemon();
}

// The first touch-down of a touch log (JSON Lines): frame index and position in display pixels.
struct TouchDown {
    std::uint64_t index = 0;
    double x = 0.0, y = 0.0;
    // The first entry after it in which nothing touches, if the log has one.
    std::optional<std::uint64_t> liftIndex;
};

// The last entry of a touch log, parsed.
nlohmann::json lastEntry(const std::filesystem::path& log) {
    std::ifstream in(log);
    std::string line, last;
    while (std::getline(in, line))
        if (!line.empty())
            last = line;
    return nlohmann::json::parse(last, nullptr, false);
}

bool touches(const nlohmann::json& entry) {
    for (const nlohmann::json& contact : entry["contacts"])
        if (contact.value("touch", false))
            return true;
    return false;
}

std::optional<TouchDown> firstTouchDown(const std::filesystem::path& log) {
    std::ifstream in(log);
    std::string line;
    std::optional<TouchDown> touchDown;
    while (std::getline(in, line)) {
        const nlohmann::json entry = nlohmann::json::parse(line, nullptr, false);
        if (entry.is_discarded() || !entry.contains("contacts"))
            continue;
        if (touchDown && !touches(entry)) {
            touchDown->liftIndex = entry["index"].get<std::uint64_t>();
            break;
        }
        if (!touchDown)
            for (const nlohmann::json& contact : entry["contacts"])
                if (contact.value("touch", false)) {
                    touchDown = TouchDown{entry["index"].get<std::uint64_t>(), contact["x"].get<double>(),
                                          contact["y"].get<double>(), std::nullopt};
                    break;
                }
    }
    return touchDown;
}

TEST_F(CameraServiceTest, DetectsTheSimulatedRigsTapThroughGigEVision) {
    // The camera films the simulated rig's grid35 from 1 s on, a frame of the simulation per camera frame,
    // as RGB8 over GVSP; the daemon knows the rig's calibration and, as from a projector that embeds the
    // code itself, the pattern of its seed.
    sim::SimParameters rig;
    rig.scenario = "grid35";
    auto simulator = std::make_shared<sim::Simulator>(rig, sim::rigPattern(rig));
    io::writeCalibrationFile(dir_ / "calibration.yml", simulator->calibration());
    constexpr std::uint64_t kFirstSimulatedFrame = 120;
    auto firstFrameId = std::make_shared<std::atomic<std::int64_t>>(-1);
    camera_.reset();
    camera_ = std::make_unique<test::FakeGigeCamera>(
        rig.cameraSize, [simulator, firstFrameId](std::uint64_t frameId, ArvPixelFormat, cv::Mat& image) {
            std::int64_t unset = -1;
            firstFrameId->compare_exchange_strong(unset, static_cast<std::int64_t>(frameId));
            core::Frame frame;
            sim::FrameTruth truth;
            simulator->render(
                kFirstSimulatedFrame + frameId - static_cast<std::uint64_t>(firstFrameId->load()), frame,
                truth);
            cv::cvtColor(frame.image, image, cv::COLOR_BGR2RGB);
        });
    // 20 frames/s leaves the rendering and the pipeline time to spare under the sanitizers too, so that no
    // frame is dropped and the daemon pairs the frames the simulated rig's run pairs.
    startDaemon("PixelFormat=RGB8\nFrameRate=20\n", "[Projector]\nOutput=external\n",
                {"--record", (dir_ / "recording").string()});
    ASSERT_TRUE(notify_->waitFor("READY=1", kStartTimeout)) << "everytouchd did not get ready";

    // The simulated rig's own run over the same frames touches down at frame 204: 84 camera frames in, and
    // lifts at frame 250.
    std::optional<TouchDown> touchDown;
    const auto deadline = std::chrono::steady_clock::now() + kStartTimeout;
    while (std::chrono::steady_clock::now() < deadline && !(touchDown = firstTouchDown(dir_ / "touch.log")))
        std::this_thread::sleep_for(100ms);
    ASSERT_TRUE(touchDown) << "no touch in the touch log; StateReason " << get("StateReason");
    EXPECT_EQ(get("State"), "s \"running\"\n");
    const std::string droppedReply = get("DroppedFrames");
    unsigned long long dropped = 0;
    ASSERT_EQ(std::sscanf(droppedReply.c_str(), "t %llu", &dropped), 1) << droppedReply;

    // The cable pulled while the finger touches (the tap lasts 46 frames, 2.3 s): the camera is lost within
    // half a second, the finger released, and the daemon waits for the camera. (Stopping then takes some
    // 10 s: Aravis lets go of a GigE camera that no longer answers only after its protocol's timeouts.)
    camera_->unplug();
    ASSERT_TRUE(waitForStatus("STATUS=Camera lost")) << "the status does not say the camera is lost";
    EXPECT_EQ(get("State"), "s \"degraded\"\n");
    const nlohmann::json last = lastEntry(dir_ / "touch.log");
    ASSERT_TRUE(last.contains("contacts")) << last.dump();
    EXPECT_TRUE(last["contacts"].empty())
        << "a contact stays down after the camera was lost: " << last.dump();
    stopDaemon();

    // Where the simulated rig's own pipeline puts it, over the same pairs.
    const test::ProcessResult simulated =
        test::runProcess({EVERYTOUCHD_PATH, "--rig", "sim:grid35", "--fast", "--frames", "260", "--log",
                          (dir_ / "simulated.log").string()});
    ASSERT_EQ(simulated.exitCode, 0) << simulated.err;
    const std::optional<TouchDown> expected = firstTouchDown(dir_ / "simulated.log");
    ASSERT_TRUE(expected);
    RecordProperty("touch_down_frame", std::to_string(touchDown->index));
    RecordProperty("touch_down_offset_px",
                   std::to_string(std::hypot(touchDown->x - expected->x, touchDown->y - expected->y)));
    RecordProperty("dropped_frames", std::to_string(dropped));
    if (dropped == 0) {
        EXPECT_EQ(kFirstSimulatedFrame + touchDown->index, expected->index);
    } else {
        // Frames lost on the way (a loaded machine drops GVSP packets on the loopback) take pairs from the
        // evidence the touch adds up: it comes later, but within the tap, where the finger rests.
        ASSERT_TRUE(expected->liftIndex);
        EXPECT_GE(kFirstSimulatedFrame + touchDown->index, expected->index) << "DroppedFrames " << dropped;
        EXPECT_LT(kFirstSimulatedFrame + touchDown->index, *expected->liftIndex)
            << "DroppedFrames " << dropped;
    }
    EXPECT_NEAR(touchDown->x, expected->x, 1.0) << "DroppedFrames " << dropped;
    EXPECT_NEAR(touchDown->y, expected->y, 1.0) << "DroppedFrames " << dropped;

    // The camera's recording, replayed, touches down as the camera did.
    const test::ProcessResult replayed =
        test::runProcess({EVERYTOUCHD_PATH, "--rig", "replay:" + (dir_ / "recording").string(), "--fast",
                          "--log", (dir_ / "replayed.log").string()});
    ASSERT_EQ(replayed.exitCode, 0) << replayed.err;
    const std::optional<TouchDown> again = firstTouchDown(dir_ / "replayed.log");
    ASSERT_TRUE(again) << "the recording's replay has no touch";
    EXPECT_EQ(again->index, touchDown->index);
    EXPECT_NEAR(again->x, touchDown->x, 1.0);
    EXPECT_NEAR(again->y, touchDown->y, 1.0);
}

// Whether the screen shows `content` with the code of `bits` added or taken away within `timeout`.
bool showsWithTheCode(const test::VirtualDisplay& display, const cv::Mat& content, const cv::Mat& bits,
                      int delta, std::chrono::seconds timeout) {
    cv::Mat positive, negative;
    core::embedCode(content, bits, delta, positive, negative);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
        const cv::Mat screen = display.grab();
        if (cv::norm(screen, positive, cv::NORM_INF) <= 1.0 ||
            cv::norm(screen, negative, cv::NORM_INF) <= 1.0)
            return true;
        std::this_thread::sleep_for(5ms);
    }
    return false;
}

TEST_F(CameraServiceTest, ItsProjectorWindowShowsTheCodeAndTheCalibrationsChessboard) {
    sim::SimParameters rig;
    rig.cameraSize = cv::Size(320, 240);
    const core::Calibration calibration = sim::rigCalibration(rig);
    io::writeCalibrationFile(dir_ / "calibration.yml", calibration);
    const test::VirtualDisplay display(rig.projectorSize);
    ::setenv("DISPLAY", display.name().c_str(), 1);
    ::unsetenv("WAYLAND_DISPLAY");

    startDaemon("PixelFormat=Mono8\nFrameRate=30\n", "[Projector]\nOutput=window\nSeed=5\nDelta=12\n");
    ASSERT_TRUE(notify_->waitFor("READY=1", kStartTimeout)) << "everytouchd did not get ready";
    EXPECT_THAT(daemon_->output(), HasSubstr("calibration images on the window on x11 display 0 \"screen\""));
    EXPECT_THAT(get("Projector"), HasSubstr("the window on x11 display 0 \\\"screen\\\" (640x480) at 60 Hz"));
    EXPECT_TRUE(std::filesystem::exists(dir_ / "pattern-seed5-640x480.png"))
        << "the window's pattern is not kept beside the calibration for the next start";
    // systemd waits while the window's code is generated, which takes a minute on a large panel.
    bool extended = false;
    for (const std::string& message : notify_->messages())
        extended = extended || message.find("EXTEND_TIMEOUT_USEC=") != std::string::npos;
    EXPECT_TRUE(extended) << "systemd's start timeout is not extended for the window's code";
    // Between calibrations: the display, white through the calibration's keystone, carrying the code.
    core::PatternOptions pattern;
    pattern.size = rig.projectorSize;
    pattern.seed = 5;
    const cv::Mat bits = core::generatePattern(pattern);
    cv::Mat keystone;
    cv::eigen2cv(calibration.displayToProjector, keystone);
    cv::Mat idle;
    cv::warpPerspective(cv::Mat(calibration.displaySize, CV_8UC3, cv::Scalar::all(255)), idle, keystone,
                        rig.projectorSize);
    EXPECT_TRUE(showsWithTheCode(display, idle, bits, 12, 20s)) << "the window does not show the display";

    // The projector step shows its chessboard until it gives up (the camera films a ramp), then the display.
    const test::ProcessResult calibrate =
        test::runProcess(test::call("Calibrate", {"sa{sv}", "projector", "1", "view_timeout_s", "d", "3"}));
    ASSERT_EQ(calibrate.exitCode, 0) << calibrate.err;
    cv::Mat board;
    core::renderProjectorChessboard(service::tableSetUpChessboard(), rig.projectorSize, board);
    cv::cvtColor(board, board, cv::COLOR_GRAY2BGR);
    EXPECT_TRUE(showsWithTheCode(display, board, bits, 12, 20s)) << "the window does not show the chessboard";
    EXPECT_TRUE(waitForLog("calibration failed")) << "the calibration did not give up";
    EXPECT_TRUE(showsWithTheCode(display, idle, bits, 12, 20s))
        << "the window does not show the display again";

    stopDaemon();
}

// The whole loop of a camera rig: everytouchd shows the table step's chessboard in its projector window (an
// Xvfb of the test's own); the simulated rig projects what the window shows onto its table, where the card
// lies, and its camera films it as a GigE Vision camera; the daemon finds the table's pose from those frames.
// The simulated projector embeds the code anew (of the same seed) into what it takes from the screen.
TEST_F(CameraServiceTest, CalibratesTheTableThroughItsProjectorWindow) {
    filmTheScreen();
    const core::Calibration truth = simulator_->calibration();
    const core::Calibration moved = test::withTheTableMoved(truth);
    io::writeCalibrationFile(dir_ / "calibration.yml", moved);
    ASSERT_TRUE(startProjecting("window")) << "everytouchd did not get ready";

    test::expectTheTableFound(test::runProcess({EVERYTOUCH_CALIB_PATH, "calibrate", "table"}),
                              dir_ / "calibration.yml", moved, truth);
    stopDaemon();
}

// The same loop through the code overlay over a desktop (picom composites it on the test's Xvfb): the table
// step's chessboard shows opaque in the overlay, and since the desktop under the overlay is not warped, the
// calibration maps the display onto the whole output.
TEST_F(CameraServiceTest, CalibratesTheTableThroughItsOverlayAndMapsTheDisplayOntoTheWholeOutput) {
    filmTheScreen();
    const core::Calibration truth = simulator_->calibration();
    const core::Calibration moved = test::withTheTableMoved(truth);
    io::writeCalibrationFile(dir_ / "calibration.yml", moved);
    const cv::Mat picture(rig_.projectorSize, CV_8UC3, cv::Scalar(200, 180, 160));
    test::DesktopWindow desktop(display_->name(), cv::Rect(cv::Point(), rig_.projectorSize), picture);
    test::Compositor compositor(display_->name());
    ASSERT_TRUE(startProjecting("overlay")) << "everytouchd did not get ready";
    EXPECT_THAT(get("Projector"), HasSubstr("the overlay on the X server " + display_->name() +
                                            " monitor 0 \\\"screen\\\" (640x480)"));
    // Between calibrations the desktop shows through, the code over it.
    cv::Mat positive, negative;
    core::makeCodeOverlay(sim::rigPattern(rig_), rig_.delta, positive, negative);
    const test::AlternateGrabs grabbed = test::grabAlternates(
        *display_, test::compositedOver(positive, picture), test::compositedOver(negative, picture));
    EXPECT_FALSE(grabbed.positive.empty() || grabbed.negative.empty())
        << "the screen does not show the desktop with the code over it";

    const test::ProcessResult calibrate = test::runProcess({EVERYTOUCH_CALIB_PATH, "calibrate", "table"});
    test::expectTheTableFound(calibrate, dir_ / "calibration.yml", moved, truth);
    // The projector's own keystone must square the display: the user is told how far it is.
    EXPECT_THAT(calibrate.out, HasSubstr("\nThe display lands on the table with sides of "));
    const core::Calibration calibrated = io::readCalibrationFile(dir_ / "calibration.yml");
    EXPECT_EQ(calibrated.displaySize, rig_.projectorSize);
    EXPECT_TRUE(calibrated.displayToProjector.isApprox(Eigen::Matrix3d::Identity()))
        << calibrated.displayToProjector;

    // Without a compositing manager the overlay hides, and the state says why nothing is detected.
    compositor.stop();
    EXPECT_TRUE(waitForProperty("StateReason", "not detecting: no compositing manager runs on its X server"))
        << get("StateReason");
    EXPECT_EQ(get("State"), "s \"degraded\"\n");
    const test::Compositor again(display_->name());
    EXPECT_TRUE(waitForProperty("StateReason", "\"\""))
        << "the state stays degraded once a compositing manager runs again: " << get("StateReason");
    stopDaemon();
}

// everytouch-calib test on a camera rig: the daemon's projector window shows the 35 circles over the display,
// with the code, while the test runs, and the display again when it ends or its client dies.
TEST_F(CameraServiceTest, TheAccuracyTestsCirclesShowInTheProjectorWindowWhileItsClientRuns) {
    filmTheScreen();
    const core::Calibration truth = simulator_->calibration();
    io::writeCalibrationFile(dir_ / "calibration.yml", truth);
    ASSERT_TRUE(startProjecting("window")) << "everytouchd did not get ready";
    ASSERT_TRUE(waitForProperty("State", "\"running\"")) << get("StateReason");

    cv::Mat keystone;
    cv::eigen2cv(truth.displayToProjector, keystone);
    cv::Mat targets, idle;
    cv::warpPerspective(core::drawAccuracyTargets(truth.displaySize), targets, keystone, rig_.projectorSize);
    cv::warpPerspective(cv::Mat(truth.displaySize, CV_8UC3, cv::Scalar::all(255)), idle, keystone,
                        rig_.projectorSize);
    const cv::Mat bits = sim::rigPattern(rig_);

    {
        // The fake camera films the screen from this process and, on a loaded machine, can miss the
        // daemon's 0.4 s once in a while; the tool then rightly refuses to start while the daemon says it is
        // degraded, and is started again once the daemon runs.
        std::optional<test::BackgroundProcess> tool;
        for (int attempt = 0; attempt < 3; ++attempt) {
            ASSERT_TRUE(waitForProperty("State", "\"running\"")) << get("StateReason");
            tool.emplace(std::vector<std::string>{EVERYTOUCH_CALIB_PATH, "test", "--timeout-s", "3"},
                         dir_ / ("test" + std::to_string(attempt) + ".log"));
            if (!tool->waitForOutput("is not detecting touches", 1s))
                break;
            tool->wait(5s);
        }
        EXPECT_TRUE(showsWithTheCode(*display_, targets, bits, rig_.delta, 20s))
            << "no circles on the projector";
        EXPECT_EQ(tool->wait(20s), 0) << tool->output();
        EXPECT_THAT(tool->output(), HasSubstr("tap the centre of each circle the projector shows"));
        EXPECT_THAT(tool->output(), HasSubstr("FRR"));
    }
    EXPECT_TRUE(showsWithTheCode(*display_, idle, bits, rig_.delta, 20s)) << "the display does not come back";

    {
        test::BackgroundProcess tool({EVERYTOUCH_CALIB_PATH, "test"}, dir_ / "killed.log");
        EXPECT_TRUE(showsWithTheCode(*display_, targets, bits, rig_.delta, 20s))
            << "no circles on the projector";
        tool.signal(SIGKILL);
        EXPECT_TRUE(tool.wait(10s));
    }
    EXPECT_TRUE(showsWithTheCode(*display_, idle, bits, rig_.delta, 20s))
        << "the circles stay after their client died";
    stopDaemon();
}

// On a Wayland desktop (sway here) the overlay is a surface on the compositor's overlay layer; the state says
// when the compositor goes away, and the code comes back with it.
TEST_F(CameraServiceTest, OnAWaylandDesktopTheOverlayIsOnTheCompositorsOverlayLayer) {
    const cv::Size output(320, 240);
    const cv::Vec3b colour(160, 180, 200);
    sim::SimParameters rig;
    rig.cameraSize = cv::Size(320, 240);
    rig.projectorSize = output;
    io::writeCalibrationFile(dir_ / "calibration.yml", sim::rigCalibration(rig));
    test::WaylandCompositor compositor(output, colour);
    ::setenv("WAYLAND_DISPLAY", compositor.socket().c_str(), 1);
    startDaemon("PixelFormat=Mono8\nFrameRate=30\n",
                "[Projector]\nOutput=overlay\nDisplay=HEADLESS-1\nSeed=5\nDelta=10\n");
    ASSERT_TRUE(notify_->waitFor("READY=1", kStartTimeout)) << "everytouchd did not get ready";
    EXPECT_THAT(get("Projector"), HasSubstr("the overlay on the Wayland compositor " + compositor.socket() +
                                            " output 0 \\\"HEADLESS-1\\\" (320x240)"));
    core::PatternOptions pattern;
    pattern.size = output;
    pattern.seed = 5;
    const cv::Mat bits = core::generatePattern(pattern);
    const auto grab = [&compositor] { return compositor.grab(); };
    test::AlternateGrabs grabbed = test::grabBothPolarities(grab, bits, 10);
    EXPECT_FALSE(grabbed.positive.empty() || grabbed.negative.empty())
        << "the screen does not show the code over the desktop";

    compositor.stop();
    EXPECT_TRUE(waitForProperty("StateReason", "closed the connection")) << get("StateReason");
    EXPECT_EQ(get("State"), "s \"degraded\"\n");
    compositor.start();
    EXPECT_TRUE(test::waitUntil(
        [this] { return get("StateReason").find("closed the connection") == std::string::npos; }, 20s))
        << "the state still says the compositor is gone once it is back: " << get("StateReason");
    grabbed = test::grabBothPolarities(grab, bits, 10);
    EXPECT_FALSE(grabbed.positive.empty() || grabbed.negative.empty())
        << "the code does not come back over the desktop";
    stopDaemon();
}

TEST_F(CameraServiceTest, AProjectorWindowOnADisplayThatDoesNotExistIsABadConfiguration) {
    const test::VirtualDisplay display(cv::Size(320, 240));
    ::setenv("DISPLAY", display.name().c_str(), 1);
    startDaemon("PixelFormat=Mono8\n", "[Projector]\nOutput=window\nDisplay=HDMI-9\n");
    EXPECT_EQ(daemon_->wait(kExitTimeout), 2);
    EXPECT_THAT(daemon_->output(), HasSubstr("[Projector] Display=: HDMI-9: no such display on x11; it has 0 "
                                             "\"screen\" (320x240)"));
}

TEST_F(CameraServiceTest, AnOverlayNeedsAMonitorThatExistsAndACompositingManager) {
    const test::VirtualDisplay display(cv::Size(320, 240));
    ::setenv("DISPLAY", display.name().c_str(), 1);
    startDaemon("PixelFormat=Mono8\n", "[Projector]\nOutput=overlay\n");
    EXPECT_EQ(daemon_->wait(kExitTimeout), 1);
    EXPECT_THAT(daemon_->output(),
                HasSubstr("no compositing manager runs on the X server " + display.name()));

    const test::Compositor compositor(display.name());
    startDaemon("PixelFormat=Mono8\n", "[Projector]\nOutput=overlay\nDisplay=HDMI-9\n");
    EXPECT_EQ(daemon_->wait(kExitTimeout), 2);
    EXPECT_THAT(daemon_->output(),
                HasSubstr("[Projector] Display=: HDMI-9: no such monitor on the X server " + display.name() +
                          "; it has 0 \"screen\" (320x240)"));
}

TEST_F(CameraServiceTest, ASettingTheCameraRefusesIsABadConfiguration) {
    startDaemon("PixelFormat=BGR8\n");
    EXPECT_EQ(daemon_->wait(kExitTimeout), 2);
    EXPECT_THAT(daemon_->output(),
                HasSubstr("--rig aravis:127.0.0.1: [Camera] PixelFormat: BGR8 is not offered; the "
                          "camera offers BayerBG8, BayerGB8, BayerGR8, BayerRG8, Mono8, RGB8, Mono16"));
}

}  // namespace
}  // namespace everytouch

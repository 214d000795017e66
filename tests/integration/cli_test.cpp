// Runs the real everytouchd and everytouch-calib binaries.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/recording.h"
#include "io/touch_log.h"
#include "support/process.h"
#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch {
namespace {

using ::testing::HasSubstr;

TEST(Everytouchd, HelpListsEveryOption) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCHD_PATH, "--help"});
    EXPECT_EQ(result.exitCode, 0);
    for (const char* option : {"--config", "--rig", "--log", "--output", "--projector", "--record",
                               "--frames", "--fast", "--verbose", "--version"})
        EXPECT_THAT(result.out, HasSubstr(option));
}

TEST(Everytouchd, VersionPrintsNameAndVersion) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCHD_PATH, "--version"});
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_THAT(result.out, HasSubstr("everytouchd 0."));
}

TEST(Everytouchd, BadRigIsAUsageErrorNamingTheOption) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCHD_PATH, "--rig", "webcam"});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr("--rig webcam"));
}

TEST(Everytouchd, MissingRecordingIsReportedByPath) {
    test::TempDir dir;
    const test::ProcessResult result =
        test::runProcess({EVERYTOUCHD_PATH, "--rig", "replay:" + (dir / "absent").string()});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr("absent"));
}

TEST(Everytouchd, ReplaysARecordingAndRecordsItAgain) {
    test::TempDir dir;
    const io::RigDescription rig = test::paperLikeRig();
    const auto maskOf = [&](std::uint64_t i) {
        cv::Mat mask(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(0));
        mask(cv::Rect(50 * static_cast<int>(i), 100, 60, 30)).setTo(255);
        return mask;
    };
    {
        io::RecordingWriter writer(dir / "in", rig, false, true);
        for (std::uint64_t i = 0; i < 6; ++i) {
            core::Frame frame;
            frame.index = i;
            frame.timestampUs = static_cast<std::int64_t>(i) * 8333;
            frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
            frame.image =
                cv::Mat(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(static_cast<double>(40 * i)));
            writer.addFrame(frame);
            writer.addMask(i, maskOf(i));
        }
    }
    const test::ProcessResult result = test::runProcess(
        {EVERYTOUCHD_PATH, "--rig", "replay:" + (dir / "in").string(), "--fast", "--frames", "5", "--record",
         (dir / "out").string(), "--log", (dir / "touches.jsonl").string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.err, HasSubstr("processed 5 frames (4 pairs)"));
    const io::Recording again = io::Recording::open(dir / "out");
    EXPECT_EQ(again.frames().size(), 5u);
    EXPECT_EQ(cv::norm(again.loadFrame(4).image,
                       cv::Mat(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(160)), cv::NORM_INF),
              0.0);
    ASSERT_TRUE(again.hasMasks()) << "the ground-truth masks are kept";
    EXPECT_EQ(cv::norm(again.loadMask(4), maskOf(4), cv::NORM_INF), 0.0);
    EXPECT_TRUE(io::readTouchLog(dir / "touches.jsonl").empty());
}

TEST(Everytouchd, RecordsTheSimulatedRigWithGroundTruth) {
    test::TempDir dir;
    const test::ProcessResult result =
        test::runProcess({EVERYTOUCHD_PATH, "--rig", "sim:demo,seed=5,start=3", "--fast", "--frames", "24",
                          "--record", (dir / "rec").string(), "--log", (dir / "touches.jsonl").string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.err, HasSubstr("processed 24 frames (23 pairs)"));
    const io::Recording recording = io::Recording::open(dir / "rec");
    ASSERT_EQ(recording.frames().size(), 24u);
    EXPECT_TRUE(recording.hasTruth());
    EXPECT_EQ(recording.truth().size(), 24u);  // 3 s into the demo one finger points at the display
    EXPECT_EQ(recording.frames().front().index, 360u);
    EXPECT_EQ(recording.rig().calibration.cameraSize, cv::Size(648, 488));
    EXPECT_EQ(recording.frames()[1].polarity, core::Polarity::Negative);
    EXPECT_EQ(recording.truth().front().frameIndex, 360u);
    EXPECT_EQ(recording.loadFrame(0).image.type(), CV_8UC3);
    ASSERT_TRUE(recording.hasMasks());  // and so a mask file for every frame, masks/000360.png on
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "rec" / "masks" / "000383.png"));
    EXPECT_GT(cv::countNonZero(recording.loadMask(23)), 0) << "the pointing hand";
}

TEST(Everytouchd, FramesLabelledTheOtherWayRoundGiveTheSameTouches) {
    // A camera that starts on the O - P frame labels every frame with the wrong polarity: the code's sign
    // tells, and the touches come out as from the frames labelled right.
    test::TempDir dir;
    const test::ProcessResult recorded =
        test::runProcess({EVERYTOUCHD_PATH, "--rig", "sim:grid35,start=1.6", "--fast", "--frames", "40",
                          "--record", (dir / "right").string()});
    ASSERT_EQ(recorded.exitCode, 0) << recorded.err;
    std::filesystem::copy(dir / "right", dir / "wrong", std::filesystem::copy_options::recursive);
    {
        std::ifstream in(dir / "right" / "frames.csv");
        std::ofstream out(dir / "wrong" / "frames.csv", std::ios::trunc);
        std::string line;
        std::getline(in, line);
        out << line << '\n';
        while (std::getline(in, line)) {
            const std::size_t comma = line.rfind(',');
            out << line.substr(0, comma + 1) << (line.substr(comma + 1) == "1" ? "-1" : "1") << '\n';
        }
    }
    std::vector<std::vector<io::TouchLogEntry>> logs;
    for (const char* name : {"right", "wrong"}) {
        const std::filesystem::path log = dir / (std::string(name) + ".jsonl");
        const test::ProcessResult replayed = test::runProcess(
            {EVERYTOUCHD_PATH, "--rig", "replay:" + (dir / name).string(), "--fast", "--log", log.string()});
        ASSERT_EQ(replayed.exitCode, 0) << replayed.err;
        if (std::string(name) == "wrong")
            EXPECT_THAT(replayed.err, HasSubstr("taken the other way round"));
        else
            EXPECT_THAT(replayed.err, ::testing::Not(HasSubstr("other way round")));
        logs.push_back(io::readTouchLog(log));
    }
    const auto touching = [](const std::vector<io::TouchLogEntry>& log) {
        int n = 0;
        for (const io::TouchLogEntry& entry : log)
            for (const core::Contact& contact : entry.contacts)
                n += contact.touching;
        return n;
    };
    ASSERT_GT(touching(logs[0]), 10) << "the finger touches from frame 205";
    ASSERT_EQ(logs[1].size(), logs[0].size());
    for (std::size_t i = 0; i < logs[0].size(); ++i) {
        EXPECT_EQ(logs[1][i].index, logs[0][i].index);
        EXPECT_EQ(logs[1][i].contacts, logs[0][i].contacts) << "frame " << logs[0][i].index;
    }
}

TEST(Everytouchd, ADiskThatFillsStopsTheRecordingNotTheDetection) {
    // A real full disk: a 1.5 MB tmpfs in a mount namespace of the daemon's own, which holds three frames.
    if (geteuid() != 0 || !std::filesystem::exists("/usr/bin/unshare") ||
        test::runProcess({"/usr/bin/unshare", "-m", "true"}).exitCode != 0)
        GTEST_SKIP() << "a small filesystem of the test's own needs root and unshare -m";
    test::TempDir dir;
    const std::vector<std::string> session = {"--rig", "sim:grid35,start=1.6", "--fast", "--frames", "40"};
    std::vector<std::string> plain = {EVERYTOUCHD_PATH};
    plain.insert(plain.end(), session.begin(), session.end());
    plain.insert(plain.end(), {"--log", (dir / "plain.jsonl").string()});
    const test::ProcessResult unrecorded = test::runProcess(plain);
    ASSERT_EQ(unrecorded.exitCode, 0) << unrecorded.err;

    std::filesystem::create_directory(dir / "small");
    std::vector<std::string> recording = {"/usr/bin/unshare",
                                          "-m",
                                          "/bin/sh",
                                          "-c",
                                          "mount -t tmpfs -o size=1536k tmpfs \"$1\" || exit 99; shift; "
                                          "\"$@\"; status=$?; cp -r \"$SMALL/rec\" \"$KEPT\"; exit $status",
                                          "sh",
                                          (dir / "small").string(),
                                          EVERYTOUCHD_PATH};
    recording.insert(recording.end(), session.begin(), session.end());
    recording.insert(recording.end(), {"--log", (dir / "recorded.jsonl").string(), "--record",
                                       (dir / "small" / "rec").string()});
    ::setenv("SMALL", (dir / "small").c_str(), 1);
    ::setenv("KEPT", (dir / "kept").c_str(), 1);
    const test::ProcessResult recorded = test::runProcess(recording);
    ::unsetenv("SMALL");
    ::unsetenv("KEPT");
    ASSERT_NE(recorded.exitCode, 99) << "no tmpfs: " << recorded.err;
    EXPECT_EQ(recorded.exitCode, 1) << "the recording asked for is incomplete";
    EXPECT_THAT(recorded.err, HasSubstr("the recording stopped: "));
    EXPECT_THAT(recorded.err, HasSubstr("No space left on device"));
    EXPECT_THAT(recorded.err, HasSubstr("detection goes on"));
    EXPECT_THAT(recorded.err, HasSubstr("processed 40 frames"));

    // Detection went on as without the recording, frame for frame.
    const std::vector<io::TouchLogEntry> expected = io::readTouchLog(dir / "plain.jsonl");
    const std::vector<io::TouchLogEntry> detected = io::readTouchLog(dir / "recorded.jsonl");
    ASSERT_EQ(detected.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(detected[i].index, expected[i].index);
        EXPECT_EQ(detected[i].contacts, expected[i].contacts) << "frame " << expected[i].index;
    }
    // What the disk held is a recording that plays.
    const io::Recording kept = io::Recording::open(dir / "kept");
    ASSERT_GE(kept.frames().size(), 1u);
    EXPECT_LT(kept.frames().size(), 40u);
    for (std::size_t i = 0; i < kept.frames().size(); ++i)
        EXPECT_FALSE(kept.loadFrame(i).image.empty());
    const test::ProcessResult replayed =
        test::runProcess({EVERYTOUCHD_PATH, "--rig", "replay:" + (dir / "kept").string(), "--fast"});
    EXPECT_EQ(replayed.exitCode, 0) << replayed.err;
}

TEST(Everytouchd, BadSimulatorOptionIsAUsageError) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCHD_PATH, "--rig", "sim:demo,surface=wood"});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr("surface: expected one of gray, yellow, artifacts"));
}

TEST(Everytouchd, UnknownOutputIsAUsageErrorNamingTheOption) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCHD_PATH, "--output", "uinput,screen"});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr("--output screen"));
}

// top -H and ps -L tell the camera's thread from the pipeline's.
TEST(Everytouchd, NamesItsThreads) {
    test::TempDir dir;
    test::BackgroundProcess daemon(
        {EVERYTOUCHD_PATH, "--rig", "sim:demo", "--log", (dir / "touch.log").string()},
        dir / "everytouchd.log");
    ASSERT_TRUE(daemon.waitForOutput("everytouchd", std::chrono::seconds(60))) << daemon.output();
    const auto named = [](const std::vector<std::string>& names, const std::string& name) {
        return std::find(names.begin(), names.end(), name) != names.end();
    };
    std::vector<std::string> names;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!(named(names, "et-camera") && named(names, "et-pipeline")) &&
           std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        names.clear();
        for (const auto& task :
             std::filesystem::directory_iterator("/proc/" + std::to_string(daemon.pid()) + "/task")) {
            std::string name;
            std::getline(std::ifstream(task.path() / "comm"), name);
            names.push_back(name);
        }
    }
    EXPECT_THAT(names, ::testing::IsSupersetOf({"everytouchd", "et-camera", "et-pipeline"}));
}

TEST(Everytouchd, UnknownProjectorOutputIsAUsageErrorNamingTheOption) {
    for (const char* projector : {"beamer", "external:HDMI-1", "overlays"}) {
        const test::ProcessResult result = test::runProcess({EVERYTOUCHD_PATH, "--projector", projector});
        EXPECT_EQ(result.exitCode, 2) << projector;
        EXPECT_THAT(result.err, HasSubstr("--projector: ")) << projector;
    }
}

TEST(Everytouchd, VirtualTouchscreenWithoutUinputFailsNamingIt) {
    if (std::filesystem::exists("/dev/uinput"))
        GTEST_SKIP() << "/dev/uinput exists here; tests/vm checks the touchscreen it creates";
    test::TempDir dir;
    io::RecordingWriter(dir / "in", test::paperLikeRig(), false).flush();
    const test::ProcessResult result = test::runProcess(
        {EVERYTOUCHD_PATH, "--rig", "replay:" + (dir / "in").string(), "--fast", "--output", "uinput"});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_THAT(result.err, HasSubstr("/dev/uinput"));
}

TEST(EverytouchCalib, HelpDocumentsExitCodes) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCH_CALIB_PATH, "--help"});
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_THAT(result.out, HasSubstr("Exit status"));
    EXPECT_THAT(result.out, HasSubstr("status"));
}

TEST(EverytouchCalib, MonitorHelpNamesItsOptions) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCH_CALIB_PATH, "monitor", "--help"});
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_THAT(result.out, HasSubstr("--count"));
    EXPECT_THAT(result.out, HasSubstr("--duration"));
}

TEST(EverytouchCalib, MonitorRefusesACountOrDurationOfNothingAsUsage) {
    for (const std::vector<std::string>& option :
         {std::vector<std::string>{"--count", "0"}, {"--duration", "0"}, {"--duration", "-1"}}) {
        const test::ProcessResult result =
            test::runProcess({EVERYTOUCH_CALIB_PATH, "monitor", option[0], option[1]});
        EXPECT_EQ(result.exitCode, 2) << option[0] << " " << option[1];
        EXPECT_THAT(result.err, HasSubstr(option[0])) << option[0] << " " << option[1];
    }
}

TEST(EverytouchCalib, TestHelpNamesItsOptionsAndTheRigItNeeds) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCH_CALIB_PATH, "test", "--help"});
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_THAT(result.out, HasSubstr("--timeout-s"));
    EXPECT_THAT(result.out, HasSubstr("--json"));
    EXPECT_THAT(result.out, HasSubstr("sim:grid35"));
}

TEST(EverytouchCalib, TestRefusesATimeoutOfNothingAsUsage) {
    for (const char* seconds : {"0", "-5"}) {
        const test::ProcessResult result =
            test::runProcess({EVERYTOUCH_CALIB_PATH, "test", "--timeout-s", seconds});
        EXPECT_EQ(result.exitCode, 2) << seconds;
        EXPECT_THAT(result.err, HasSubstr("--timeout-s")) << seconds;
    }
}

TEST(EverytouchCalib, VersionPrintsNameAndVersion) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCH_CALIB_PATH, "--version"});
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_THAT(result.out, HasSubstr("everytouch-calib 0."));
}

}  // namespace
}  // namespace everytouch

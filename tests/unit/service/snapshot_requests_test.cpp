#include "service/snapshot_requests.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <systemd/sd-bus.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/replay_source.h"
#include "service/bus_error.h"
#include "service/bus_names.h"
#include "support/coded_recording.h"
#include "support/temp_dir.h"

namespace everytouch::service {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;

// How the calls were answered.
struct Answers {
    int done = 0;
    std::vector<std::pair<std::string, std::string>> failures;  // error name, message

    SnapshotReply reply() {
        return {
            [this] { ++done; },
            [this](const char* name, const std::string& message) { failures.emplace_back(name, message); }};
    }
};

// Draws a flat image whose first pixel is the pair's newer frame index, so the test can see which pair
// reached the descriptor and that it went through the renderer.
struct MarkingRenderer {
    std::vector<SnapshotKind> kinds;

    SnapshotRenderer function() {
        return [this](SnapshotKind kind, const TappedPair& tapped, cv::Mat& image) {
            const core::FramePair& pair = tapped.pair;
            kinds.push_back(kind);
            image = cv::Mat(pair.latest().image.size(), CV_8UC1, cv::Scalar(77));
            image.at<uchar>(0, 0) = static_cast<uchar>(pair.latest().index);
        };
    }
};

// The thing a failed add() threw.
std::string addError(SnapshotRequests& requests, int fd, Answers& answers) {
    try {
        requests.add(SnapshotKind::Camera, fd, answers.reply());
    } catch (const BusError& error) {
        return std::string(error.name()) + ": " + error.what();
    }
    return "";
}

// A pipeline whose first pair takes as long as a new calibration's preparation on a slow machine.
class SlowFirstPairPipeline final : public core::PairPipeline {
public:
    explicit SlowFirstPairPipeline(Clock::duration firstPair) : firstPair_(firstPair) {}
    const core::PipelineResult& process(const core::FramePair& pair, const core::PipelineSettings&) override {
        if (pairs_++ == 0)
            std::this_thread::sleep_for(firstPair_);
        result_.frameIndex = pair.latest().index;
        return result_;
    }
    void reset() override {}

private:
    Clock::duration firstPair_;
    int pairs_ = 0;
    core::PipelineResult result_;
};

// How a snapshot was answered, and after how long.
struct SlowAnswer {
    Answers answers;
    Clock::duration waited{};
};

class SnapshotRequestsTest : public ::testing::Test {
protected:
    void SetUp() override {
        test::writeCodedRecording(dir_ / "recording", test::smallRig(), 20, 8333);
        sd_event* event = nullptr;
        ASSERT_GE(sd_event_new(&event), 0);
        event_.reset(event);
        ASSERT_EQ(inbox_.attach(event_.get()), 0);
        options_.overflow = FrameQueue::Overflow::Block;
    }

    // Runs the event loop, as the daemon's main thread does, until `condition` holds.
    bool runUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
        const auto deadline = Clock::now() + timeout;
        while (!condition()) {
            if (Clock::now() >= deadline)
                return false;
            if (sd_event_run(event_.get(), 20'000) < 0)
                return false;
        }
        return true;
    }

    io::UniqueFd openForWriting(const std::string& name) {
        return io::UniqueFd(::open((dir_ / name).c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600));
    }

    // One snapshot asked for while a pipeline whose first pair takes `firstPair` works on it, with a frame
    // timeout of 100 ms and `busy` beyond it.
    SlowAnswer snapshotWhileTheFirstPairTakes(Clock::duration firstPair, std::chrono::milliseconds busy) {
        io::ReplaySource source(dir_ / "recording", false);
        SlowFirstPairPipeline slow(firstPair);
        FrameLoop loop(source, slow, {}, nullptr, options_, {}, [] {});
        MarkingRenderer renderer;
        SnapshotRequests requests(event_.get(), loop, inbox_, renderer.function(),
                                  SnapshotTimeouts{100ms, 3000ms, busy});
        loop.start();
        SlowAnswer answer;
        EXPECT_TRUE(runUntil([&] { return loop.processing(); }, 10s));
        io::UniqueFd fd = openForWriting("snapshot.png");
        const auto begun = Clock::now();
        requests.add(SnapshotKind::Camera, fd.get(), answer.answers.reply());
        EXPECT_TRUE(runUntil([&] { return answer.answers.done + answer.answers.failures.size() > 0; }, 10s));
        answer.waited = Clock::now() - begun;
        return answer;
    }

    test::TempDir dir_;
    LoopOptions options_;
    core::TouchPipeline pipeline_;  // uncalibrated: the pairs pass through without detection
    io::Event event_;
    MainLoopInbox inbox_;
};

TEST_F(SnapshotRequestsTest, WritesTheRenderedNextPairAndAnswersTheCall) {
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    MarkingRenderer renderer;
    SnapshotRequests requests(event_.get(), loop, inbox_, renderer.function());
    Answers answers;
    io::UniqueFd fd = openForWriting("snapshot.png");
    ASSERT_TRUE(fd);
    requests.add(SnapshotKind::Texture, fd.get(), answers.reply());
    EXPECT_EQ(requests.pending(), 1u);
    fd.reset();  // the request keeps its own copy: the caller may close its end at once

    loop.start();
    ASSERT_TRUE(runUntil([&] { return answers.done + answers.failures.size() > 0; }, 30s));
    EXPECT_EQ(answers.done, 1);
    EXPECT_TRUE(answers.failures.empty());
    EXPECT_EQ(requests.pending(), 0u);
    EXPECT_EQ(renderer.kinds, std::vector{SnapshotKind::Texture});
    const cv::Mat written = cv::imread((dir_ / "snapshot.png").string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(written.empty());
    EXPECT_EQ(written.size(), test::smallRig().calibration.cameraSize);
    EXPECT_EQ(written.at<uchar>(0, 0), 1);  // the first pair: frames 0 and 1
    EXPECT_EQ(written.at<uchar>(5, 5), 77);
}

TEST_F(SnapshotRequestsTest, WithoutFramesTheRequestFailsAfterItsTimeoutAndStaysAnswered) {
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    MarkingRenderer renderer;
    SnapshotRequests requests(event_.get(), loop, inbox_, renderer.function(),
                              SnapshotTimeouts{50ms, 3000ms});
    Answers answers;
    io::UniqueFd fd = openForWriting("snapshot.png");
    const auto begun = Clock::now();
    requests.add(SnapshotKind::Camera, fd.get(), answers.reply());

    ASSERT_TRUE(runUntil([&] { return !answers.failures.empty(); }, 10s));
    EXPECT_GE(Clock::now() - begun, 50ms);
    EXPECT_EQ(answers.failures.front().first, bus::kErrorNoCamera);
    EXPECT_EQ(answers.failures.front().second, "No camera frame pair arrived within 0.05 s");
    EXPECT_EQ(requests.pending(), 0u);

    // Frames that come later find no request left: the call is not answered twice.
    loop.start();
    ASSERT_TRUE(runUntil([&] { return loop.finished(); }, 30s));
    runUntil([] { return false; }, 100ms);
    EXPECT_EQ(answers.done, 0);
    EXPECT_EQ(answers.failures.size(), 1u);
    EXPECT_TRUE(renderer.kinds.empty());
    EXPECT_EQ(std::filesystem::file_size(dir_ / "snapshot.png"), 0u);
}

TEST_F(SnapshotRequestsTest, WaitsForAPairDetectionIsStillWorkingOn) {
    const SlowAnswer answer = snapshotWhileTheFirstPairTakes(400ms, 1000ms);
    EXPECT_EQ(answer.answers.done, 1)
        << (answer.answers.failures.empty() ? "" : answer.answers.failures.front().second);
}

TEST_F(SnapshotRequestsTest, GivesUpOnAPairDetectionWorksOnLongerThanItsWait) {
    const SlowAnswer answer = snapshotWhileTheFirstPairTakes(2s, 300ms);
    EXPECT_GE(answer.waited, 400ms);
    ASSERT_EQ(answer.answers.failures.size(), 1u);
    EXPECT_EQ(answer.answers.failures.front().first, bus::kErrorBusy);
    EXPECT_EQ(answer.answers.failures.front().second,
              "Detection has been working on one frame pair for more than 0.3 s");
}

TEST_F(SnapshotRequestsTest, RefusesADescriptorNotOpenForWriting) {
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    MarkingRenderer renderer;
    SnapshotRequests requests(event_.get(), loop, inbox_, renderer.function());
    Answers answers;
    const io::UniqueFd readOnly(::open("/dev/null", O_RDONLY | O_CLOEXEC));
    EXPECT_EQ(addError(requests, readOnly.get(), answers),
              std::string(SD_BUS_ERROR_INVALID_ARGS) + ": The file descriptor is not open for writing");
    EXPECT_THAT(addError(requests, -1, answers), HasSubstr(SD_BUS_ERROR_INVALID_ARGS));
    EXPECT_EQ(requests.pending(), 0u);
}

TEST_F(SnapshotRequestsTest, RefusesOnceTheCameraHasEnded) {
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    MarkingRenderer renderer;
    SnapshotRequests requests(event_.get(), loop, inbox_, renderer.function());
    loop.start();
    ASSERT_TRUE(runUntil([&] { return loop.finished(); }, 30s));
    Answers answers;
    const io::UniqueFd fd = openForWriting("snapshot.png");
    EXPECT_EQ(addError(requests, fd.get(), answers),
              std::string(bus::kErrorNoCamera) + ": The camera delivers no frames");
    EXPECT_EQ(requests.pending(), 0u);
}

TEST_F(SnapshotRequestsTest, AReaderThatWentAwayGetsAnIoError) {
    std::signal(SIGPIPE, SIG_IGN);  // as everytouchd does
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    MarkingRenderer renderer;
    SnapshotRequests requests(event_.get(), loop, inbox_, renderer.function());
    int ends[2];
    ASSERT_EQ(::pipe2(ends, O_CLOEXEC), 0);
    io::UniqueFd readEnd(ends[0]);
    const io::UniqueFd writeEnd(ends[1]);
    Answers answers;
    requests.add(SnapshotKind::Camera, writeEnd.get(), answers.reply());
    readEnd.reset();

    loop.start();
    ASSERT_TRUE(runUntil([&] { return answers.done + answers.failures.size() > 0; }, 30s));
    EXPECT_EQ(answers.done, 0);
    ASSERT_EQ(answers.failures.size(), 1u);
    EXPECT_EQ(answers.failures.front().first, SD_BUS_ERROR_IO_ERROR);
    EXPECT_THAT(answers.failures.front().second, HasSubstr("Cannot write the PNG: Broken pipe"));
    EXPECT_EQ(requests.pending(), 0u);
}

// Draws noise, whose PNG is larger than a pipe holds.
SnapshotRenderer noiseRenderer() {
    return [](SnapshotKind, const TappedPair& tapped, cv::Mat& image) {
        image.create(tapped.pair.latest().image.size() * 4, CV_8UC1);
        cv::randu(image, 0, 256);
    };
}

TEST_F(SnapshotRequestsTest, AReaderThatNeverReadsHoldsUpNothingButItsOwnCall) {
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    SnapshotRequests requests(event_.get(), loop, inbox_, noiseRenderer(), SnapshotTimeouts{3000ms, 1000ms});
    int ends[2];
    ASSERT_EQ(::pipe2(ends, O_CLOEXEC), 0);
    const io::UniqueFd readEnd(ends[0]);
    const io::UniqueFd writeEnd(ends[1]);
    Answers answers;
    requests.add(SnapshotKind::Camera, writeEnd.get(), answers.reply());

    loop.start();
    // Every turn of the main loop stays short while the PNG waits for its reader: a turn that waited for it
    // would last the write timeout. Encoding the noise's PNG, which a turn does, took up to 157 ms under
    // AddressSanitizer on a loaded machine.
    Clock::duration longestTurn{};
    const auto deadline = Clock::now() + 30s;
    while (answers.done + answers.failures.size() == 0 && Clock::now() < deadline) {
        const auto begun = Clock::now();
        ASSERT_GE(sd_event_run(event_.get(), 20'000), 0);
        longestTurn = std::max(longestTurn, Clock::now() - begun);
    }
    EXPECT_LT(longestTurn, 500ms);
    EXPECT_EQ(answers.done, 0);
    ASSERT_EQ(answers.failures.size(), 1u);
    EXPECT_EQ(answers.failures.front().first, SD_BUS_ERROR_IO_ERROR);
    EXPECT_EQ(answers.failures.front().second, "The reader did not take the PNG within 1 s");
    EXPECT_EQ(requests.pending(), 0u);
}

TEST_F(SnapshotRequestsTest, ASlowReaderGetsTheWholePngAndItsDescriptorKeepsItsFlags) {
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    SnapshotRequests requests(event_.get(), loop, inbox_, noiseRenderer());
    int ends[2];
    ASSERT_EQ(::pipe2(ends, O_CLOEXEC), 0);
    io::UniqueFd readEnd(ends[0]);
    io::UniqueFd writeEnd(ends[1]);
    const int flagsBefore = ::fcntl(writeEnd.get(), F_GETFL);
    Answers answers;
    requests.add(SnapshotKind::Camera, writeEnd.get(), answers.reply());
    std::vector<unsigned char> received;
    std::thread reader([&] {
        unsigned char chunk[4096];
        for (ssize_t n; (n = ::read(readEnd.get(), chunk, sizeof chunk)) > 0;) {
            received.insert(received.end(), chunk, chunk + n);
            std::this_thread::sleep_for(1ms);
        }
    });

    loop.start();
    const bool answered = runUntil([&] { return answers.done + answers.failures.size() > 0; }, 30s);
    EXPECT_EQ(::fcntl(writeEnd.get(), F_GETFL), flagsBefore);
    writeEnd.reset();
    requests.failAll(bus::kErrorNoCamera, "the test ends");  // closes the daemon's own descriptor too
    reader.join();
    ASSERT_TRUE(answered);
    EXPECT_EQ(answers.done, 1);
    EXPECT_TRUE(answers.failures.empty());
    const cv::Mat image = cv::imdecode(received, cv::IMREAD_UNCHANGED);
    EXPECT_EQ(image.size(), test::smallRig().calibration.cameraSize * 4);
}

TEST_F(SnapshotRequestsTest, FailAllAnswersEveryPendingRequest) {
    io::ReplaySource source(dir_ / "recording", false);
    FrameLoop loop(source, pipeline_, {}, nullptr, options_, {}, [] {});
    MarkingRenderer renderer;
    SnapshotRequests requests(event_.get(), loop, inbox_, renderer.function());
    Answers first, second;
    const io::UniqueFd fd = openForWriting("snapshot.png");
    requests.add(SnapshotKind::Camera, fd.get(), first.reply());
    requests.add(SnapshotKind::Overlay, fd.get(), second.reply());
    EXPECT_EQ(requests.pending(), 2u);

    requests.failAll(bus::kErrorNoCamera, "everytouchd is stopping");
    EXPECT_EQ(requests.pending(), 0u);
    for (const Answers* answers : {&first, &second}) {
        EXPECT_EQ(answers->done, 0);
        ASSERT_EQ(answers->failures.size(), 1u);
        EXPECT_EQ(answers->failures.front().first, bus::kErrorNoCamera);
        EXPECT_EQ(answers->failures.front().second, "everytouchd is stopping");
    }
}

}  // namespace
}  // namespace everytouch::service

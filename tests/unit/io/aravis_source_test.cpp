#include "io/aravis_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "io/input_error.h"
#include "sim/simulator.h"
#include "support/bayer_mosaic.h"
#include "support/fake_gige_camera.h"

namespace everytouch::io {
namespace {

using ::testing::HasSubstr;

// A GigE camera on the loopback interface that films the simulated rig: camera frame N shows simulator frame
// N modulo the scenario's length, and every image it sends is kept, as our frames should read it.
class SimulatedGigeCamera {
public:
    SimulatedGigeCamera()
        : simulator_(warmedUp(parameters())),
          camera_(simulator_.parameters().cameraSize,
                  [this](std::uint64_t frameId, ArvPixelFormat format, cv::Mat& image) {
                      fill(frameId, format, image);
                  }) {}

    // The images sent so far, as everytouchd should read them (gray for Mono8, BGR otherwise).
    std::vector<cv::Mat> sent() const {
        std::lock_guard lock(mutex_);
        return sent_;
    }
    void unplug() { camera_.unplug(); }

private:
    static sim::SimParameters parameters() {
        sim::SimParameters parameters;
        parameters.scenario = "grid35";
        parameters.startS = 2.0;  // a hand in view
        return parameters;
    }

    // A simulator that has rendered once already: the first rendering prepares the scene, which takes far
    // longer than a frame.
    static sim::Simulator warmedUp(const sim::SimParameters& parameters) {
        sim::Simulator simulator(parameters, sim::rigPattern(parameters));
        core::Frame frame;
        sim::FrameTruth truth;
        simulator.render(0, frame, truth);
        return simulator;
    }

    void fill(std::uint64_t frameId, ArvPixelFormat format, cv::Mat& image) {
        core::Frame frame;
        sim::FrameTruth truth;
        simulator_.render(frameId % 240, frame, truth);
        cv::Mat expected;
        if (format == ARV_PIXEL_FORMAT_MONO_8) {
            cv::cvtColor(frame.image, image, cv::COLOR_BGR2GRAY);
            expected = image.clone();
        } else if (format == ARV_PIXEL_FORMAT_RGB_8_PACKED) {
            cv::cvtColor(frame.image, image, cv::COLOR_BGR2RGB);
            expected = frame.image;
        } else if (format == ARV_PIXEL_FORMAT_BAYER_RG_8) {
            test::bayerMosaic(frame.image, "BayerRG8").copyTo(image);
            expected = frame.image;
        } else {
            return;
        }
        std::lock_guard lock(mutex_);
        sent_.push_back(expected);
    }

    sim::Simulator simulator_;
    mutable std::mutex mutex_;
    std::vector<cv::Mat> sent_;
    test::FakeGigeCamera camera_;  // last: it stops filling before the rest goes
};

CameraSettings withPixels(CameraPixels pixels) {
    CameraSettings settings;
    settings.pixels = pixels;
    return settings;
}

CameraSettings mono8At(double frameRate) {
    CameraSettings settings = withPixels(CameraPixels::Mono8);
    settings.frameRate = frameRate;
    return settings;
}

// What opening the camera throws: bad input (the configuration's fault) or a failure (which may pass).
std::string errorOf(const std::string& id, const CameraSettings& settings) {
    try {
        AravisSource source("--rig aravis:" + id, id, settings);
    } catch (const InputError& error) {
        return std::string("bad input: ") + error.what();
    } catch (const std::runtime_error& error) {
        return std::string("failure: ") + error.what();
    }
    return "no error";
}

TEST(AravisSource, FramesMissingFromTheCamerasCountAreCountedAcrossItsWrap) {
    EXPECT_EQ(framesMissedBetween(5, 6), 0u);
    EXPECT_EQ(framesMissedBetween(5, 9), 3u);
    EXPECT_EQ(framesMissedBetween(65535, 1), 0u);  // GigE Vision skips 0
    EXPECT_EQ(framesMissedBetween(65534, 2), 2u);
    EXPECT_EQ(framesMissedBetween(70000, 70001), 0u);  // a 64-bit counter
    EXPECT_EQ(framesMissedBetween(70000, 70004), 3u);
    EXPECT_EQ(framesMissedBetween(500, 7), 0u);  // started over
    EXPECT_EQ(framesMissedBetween(80000, 7), 0u);
    EXPECT_EQ(framesMissedBetween(7, 9000), 0u);
}

TEST(AravisSource, DeliversTheCamerasFramesUnchangedInOrderWithTheCamerasTime) {
    SimulatedGigeCamera camera;
    AravisSource source("--rig aravis:127.0.0.1", "127.0.0.1", mono8At(60.0));
    EXPECT_THAT(source.describe(), HasSubstr("648x488 Mono8 at 60 frames/s"));
    std::vector<core::Frame> frames;
    for (int i = 0; i < 8; ++i) {
        std::optional<core::Frame> frame = source.next();
        ASSERT_TRUE(frame);
        frames.push_back(std::move(*frame));
    }
    // Each frame we read is one the camera sent, in the order sent; a frame sent and not read (lost on the
    // way) is counted as dropped and leaves its place in the indices.
    const std::vector<cv::Mat> sent = camera.sent();
    std::vector<std::size_t> positions;
    std::size_t position = 0;
    for (const core::Frame& frame : frames) {
        ASSERT_EQ(frame.image.type(), CV_8UC1);
        while (position < sent.size() && cv::norm(sent[position], frame.image, cv::NORM_INF) != 0.0)
            ++position;
        ASSERT_LT(position, sent.size()) << "frame " << frame.index << " is none the camera sent";
        positions.push_back(position++);
    }
    for (std::size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].index, positions[i] - positions[0]);
        EXPECT_EQ(frames[i].polarity,
                  frames[i].index % 2 ? core::Polarity::Negative : core::Polarity::Positive);
        if (i > 0) {
            EXPECT_GT(frames[i].timestampUs, frames[i - 1].timestampUs);
        }
    }
    EXPECT_EQ(source.droppedFrames(), positions.back() - positions.front() + 1 - frames.size());
    // The camera's clock: frames a frame period apart at least (more where rendering a frame held the fake
    // camera up, as under the sanitizers).
    std::vector<std::int64_t> periods;
    for (std::size_t i = 1; i < frames.size(); ++i)
        periods.push_back(frames[i].timestampUs - frames[i - 1].timestampUs);
    std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
    EXPECT_GT(periods[periods.size() / 2], 0.75e6 / 60.0);
    EXPECT_EQ(source.droppedFrames(), 0u);
}

TEST(AravisSource, ReadsColourFromTheCamerasBayerMosaicByDefault) {
    SimulatedGigeCamera camera;
    AravisSource source("--rig aravis", "", CameraSettings{});
    EXPECT_THAT(source.describe(), HasSubstr("BayerRG8"));
    std::optional<core::Frame> frame = source.next();
    ASSERT_TRUE(frame);
    ASSERT_EQ(frame->image.type(), CV_8UC3);
    // Demosaicing blurs edges a little: the frame is the colour image the camera saw, nearly.
    double closest = 255.0;
    for (const cv::Mat& sent : camera.sent()) {
        cv::Mat difference;
        cv::absdiff(sent, frame->image, difference);
        const cv::Scalar mean = cv::mean(difference);
        closest = std::min(closest, (mean[0] + mean[1] + mean[2]) / 3.0);
    }
    EXPECT_LT(closest, 2.0);
}

TEST(AravisSource, ACameraThatGoesAwayIsReportedOnTimeAndTakenBackWhenItReturns) {
    auto camera = std::make_unique<SimulatedGigeCamera>();
    AravisSource source("--rig aravis:127.0.0.1", "127.0.0.1", mono8At(60.0));
    ASSERT_TRUE(source.next());
    camera->unplug();
    const auto start = std::chrono::steady_clock::now();
    std::string message = "no error";
    try {
        for (int i = 0; i < 100; ++i)  // what was on its way still arrives
            source.next();
    } catch (const SourceLost& lost) {
        message = lost.what();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_THAT(message, HasSubstr("no complete frame for 0.3 s"));
    EXPECT_LT(seconds, 0.5) << "a camera pulled out must release the contacts within half a second";
    // While it is away, each call says so at once, and lets go of nothing it still needs.
    EXPECT_THROW(source.next(), SourceLost);
    camera = std::make_unique<SimulatedGigeCamera>();
    std::optional<core::Frame> frame;
    for (int attempt = 0; attempt < 20 && !frame; ++attempt) {
        try {
            frame = source.next();
        } catch (const SourceLost&) {
        }
    }
    ASSERT_TRUE(frame) << "the camera was not taken back";
    EXPECT_EQ(frame->image.size(), cv::Size(648, 488));
}

TEST(AravisSource, TakesItsRegionAndAFramePerPulseOnItsTrigger) {
    test::FakeGigeCamera camera(cv::Size(648, 488),
                                [](std::uint64_t frameId, ArvPixelFormat, cv::Mat& image) {
                                    image.setTo(cv::Scalar(static_cast<double>(frameId % 256)));
                                });
    CameraSettings triggered = mono8At(60.0);
    triggered.region = cv::Rect(8, 4, 320, 240);
    triggered.trigger = "Software";
    AravisSource source("--rig aravis:127.0.0.1", "127.0.0.1", triggered);
    EXPECT_THAT(source.describe(), HasSubstr("320x240 Mono8, triggered by Software"));
    EXPECT_EQ(source.stallTimeoutSeconds(), 2.0);
    // The camera would run free at 60 frames/s: on its trigger it gives a frame per pulse, and none without.
    for (int i = 0; i < 3; ++i) {
        camera.triggerSoftware();
        const std::optional<core::Frame> frame = source.next();
        ASSERT_TRUE(frame);
        EXPECT_EQ(frame->image.size(), cv::Size(320, 240));
    }
    const auto start = std::chrono::steady_clock::now();
    EXPECT_THROW(source.next(), std::runtime_error);
    EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

TEST(AravisSource, RefusesWhatTheCameraCannotDoNamingIt) {
    SimulatedGigeCamera camera;
    // A setting it refuses is the configuration's fault; a camera that does not answer may yet come.
    EXPECT_EQ(
        errorOf("127.0.0.1", withPixels(CameraPixels::Bgr8)),
        "bad input: --rig aravis:127.0.0.1: [Camera] PixelFormat: BGR8 is not offered; the camera offers "
        "BayerBG8, "
        "BayerGB8, BayerGR8, BayerRG8, Mono8, RGB8, Mono16");
    EXPECT_THAT(errorOf("everytouch-no-such-camera", CameraSettings{}),
                HasSubstr("failure: --rig aravis:everytouch-no-such-camera: no camera answers as "
                          "\"everytouch-no-such-camera\""));
}

}  // namespace
}  // namespace everytouch::io

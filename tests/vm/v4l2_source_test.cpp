// V4l2Source against a real V4L2 driver: the kernel's vivid, its webcam input for the capture path and the
// faults the driver can inject, and its HDMI output looped back into its HDMI input, so that frames of our
// own go in through the output and come back through the real capture path. tests/vm/run-vm-test.sh loads
// vivid in a virtual machine (node_types=0x101: a capture node and an output node; inputs: a webcam and HDMI;
// output: HDMI) and sets EVERYTOUCH_V4L2_TESTS=1; elsewhere these tests skip.
#include <fcntl.h>
#include <linux/v4l2-dv-timings.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <set>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/calibration_file.h"
#include "io/handles.h"
#include "io/input_error.h"
#include "io/recording.h"
#include "io/touch_log.h"
#include "io/v4l2_source.h"
#include "support/file_contents.h"
#include "support/private_bus.h"
#include "support/process.h"
#include "support/temp_dir.h"

namespace everytouch {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

constexpr unsigned kWebcamInput = 0;
constexpr unsigned kHdmiInput = 1;
const cv::Size kLoopSize(640, 480);

struct VividNodes {
    std::string capture, output;
};

// vivid's capture and output nodes, found by their driver and capabilities.
VividNodes findVivid() {
    VividNodes nodes;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/dev", error)) {
        const std::string path = entry.path().string();
        if (path.rfind("/dev/video", 0) != 0)
            continue;
        io::UniqueFd fd(::open(path.c_str(), O_RDWR | O_CLOEXEC));
        v4l2_capability capability{};
        if (!fd || ::ioctl(fd.get(), VIDIOC_QUERYCAP, &capability) != 0 ||
            std::strcmp(reinterpret_cast<const char*>(capability.driver), "vivid") != 0)
            continue;
        if (capability.device_caps & V4L2_CAP_VIDEO_CAPTURE)
            nodes.capture = path;
        if (capability.device_caps & V4L2_CAP_VIDEO_OUTPUT)
            nodes.output = path;
    }
    return nodes;
}

#define SKIP_WITHOUT_VIVID(nodes)                                                                            \
    do {                                                                                                     \
        if (const char* allowed = std::getenv("EVERYTOUCH_V4L2_TESTS");                                      \
            !allowed || std::string(allowed) != "1")                                                         \
            GTEST_SKIP() << "tests/vm loads the vivid driver and sets EVERYTOUCH_V4L2_TESTS=1 to run these"; \
        nodes = findVivid();                                                                                 \
        ASSERT_FALSE(nodes.capture.empty() || nodes.output.empty()) << "vivid's nodes are missing";          \
    } while (false)

io::UniqueFd openNode(const std::string& path) {
    io::UniqueFd fd(::open(path.c_str(), O_RDWR | O_CLOEXEC));
    EXPECT_TRUE(fd) << path << ": " << std::strerror(errno);
    return fd;
}

// A control of vivid's, by the name v4l2-ctl lists.
std::uint32_t controlId(int fd, const std::string& name) {
    v4l2_queryctrl query{};
    query.id = V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
    while (::ioctl(fd, VIDIOC_QUERYCTRL, &query) == 0) {
        if (name == reinterpret_cast<const char*>(query.name))
            return query.id;
        query.id |= V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
    }
    ADD_FAILURE() << "vivid has no control \"" << name << "\"";
    return 0;
}

void setControl(const std::string& node, const std::string& name, int value) {
    const io::UniqueFd fd = openNode(node);
    v4l2_control setting{};
    setting.id = controlId(fd.get(), name);
    setting.value = value;
    ASSERT_EQ(::ioctl(fd.get(), VIDIOC_S_CTRL, &setting), 0) << name << ": " << std::strerror(errno);
}

void selectInput(const std::string& capture, unsigned input) {
    const io::UniqueFd fd = openNode(capture);
    unsigned index = input;
    ASSERT_EQ(::ioctl(fd.get(), VIDIOC_S_INPUT, &index), 0) << std::strerror(errno);
    if (input == kHdmiInput) {
        v4l2_dv_timings timings = V4L2_DV_BT_CEA_640X480P59_94;
        ASSERT_EQ(::ioctl(fd.get(), VIDIOC_S_DV_TIMINGS, &timings), 0) << std::strerror(errno);
    }
}

std::optional<core::Frame> nextWithin(io::V4l2Source& source, int attempts = 3) {
    for (int i = 0; i < attempts; ++i) {
        try {
            return source.next();
        } catch (const io::SourceLost&) {
        }
    }
    return std::nullopt;
}

TEST(V4l2SourceOnVivid, TheWebcamStreamsColourFramesInCountAndTime) {
    VividNodes nodes;
    SKIP_WITHOUT_VIVID(nodes);
    selectInput(nodes.capture, kWebcamInput);
    io::V4l2Source source("--rig v4l2:" + nodes.capture, nodes.capture, io::CameraSettings{});
    EXPECT_THAT(source.describe(), HasSubstr("V4L2 camera"));
    EXPECT_THAT(source.describe(), HasSubstr("(vivid, " + nodes.capture + ")"));
    EXPECT_THAT(source.describe(), HasSubstr(" YUYV at "));
    std::int64_t lastTimestamp = 0;
    std::uint64_t lastIndex = 0;
    for (int i = 0; i < 12; ++i) {
        const std::optional<core::Frame> frame = source.next();
        ASSERT_TRUE(frame);
        EXPECT_EQ(frame->image.type(), CV_8UC3);
        EXPECT_GT(frame->image.cols, 0);
        if (i > 0) {
            EXPECT_GT(frame->timestampUs, lastTimestamp);
            EXPECT_EQ(frame->index, lastIndex + 1);
        }
        EXPECT_EQ(frame->polarity, frame->index % 2 ? core::Polarity::Negative : core::Polarity::Positive);
        lastTimestamp = frame->timestampUs;
        lastIndex = frame->index;
    }
    EXPECT_EQ(source.droppedFrames(), 0u);
}

TEST(V4l2SourceOnVivid, SettingsAreAppliedOrRefusedByName) {
    VividNodes nodes;
    SKIP_WITHOUT_VIVID(nodes);
    selectInput(nodes.capture, kWebcamInput);
    io::CameraSettings gray;
    gray.pixels = io::CameraPixels::Mono8;
    gray.region = cv::Rect(0, 0, 640, 480);
    gray.frameRate = 25.0;  // vivid's webcam gives 640x480 at 25 frames/s at most
    {
        io::V4l2Source source("--rig v4l2:" + nodes.capture, nodes.capture, gray);
        EXPECT_THAT(source.describe(), HasSubstr("640x480 GREY at 25 frames/s"));
        const std::optional<core::Frame> frame = source.next();
        ASSERT_TRUE(frame);
        EXPECT_EQ(frame->image.type(), CV_8UC1);
        EXPECT_EQ(frame->image.size(), cv::Size(640, 480));
    }
    io::CameraSettings tooFast = gray;
    tooFast.frameRate = 500.0;
    try {
        io::V4l2Source source("--rig v4l2:" + nodes.capture, nodes.capture, tooFast);
        ADD_FAILURE() << "500 frames/s taken";
    } catch (const io::InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr("[Camera] FrameRate: the camera gives "));
        EXPECT_THAT(error.what(), HasSubstr("640x480 GREY, not 500"));
    }
    io::CameraSettings triggered;
    triggered.trigger = "Line0";
    EXPECT_THROW(io::V4l2Source("--rig v4l2:" + nodes.capture, nodes.capture, triggered), io::InputError);
    io::CameraSettings bayer;
    bayer.pixels = io::CameraPixels::BayerRg8;
    EXPECT_THROW(io::V4l2Source("--rig v4l2:" + nodes.capture, nodes.capture, bayer), io::InputError);
}

TEST(V4l2SourceOnVivid, ADamagedBufferIsCountedAndKeepsItsPlaceInTheCount) {
    VividNodes nodes;
    SKIP_WITHOUT_VIVID(nodes);
    selectInput(nodes.capture, kWebcamInput);
    io::V4l2Source source("--rig v4l2:" + nodes.capture, nodes.capture, io::CameraSettings{});
    std::optional<core::Frame> frame = source.next();
    ASSERT_TRUE(frame);
    setControl(nodes.capture, "Inject V4L2_BUF_FLAG_ERROR", 1);
    std::uint64_t lastIndex = frame->index;
    bool skipped = false;
    for (int i = 0; i < 10 && !skipped; ++i) {
        frame = source.next();
        ASSERT_TRUE(frame);
        skipped = frame->index > lastIndex + 1;
        lastIndex = frame->index;
    }
    EXPECT_TRUE(skipped) << "no index was left out for the damaged buffer";
    EXPECT_GE(source.droppedFrames(), 1u);
}

TEST(V4l2SourceOnVivid, ACameraThatDisconnectsIsLostAndComesBackWithoutANewSource) {
    VividNodes nodes;
    SKIP_WITHOUT_VIVID(nodes);
    selectInput(nodes.capture, kWebcamInput);
    io::V4l2Source source("--rig v4l2:" + nodes.capture, nodes.capture, io::CameraSettings{});
    ASSERT_TRUE(source.next());
    // vivid acts as a USB camera pulled out, until every handle on it is closed.
    setControl(nodes.capture, "Disconnect", 1);
    const auto start = std::chrono::steady_clock::now();
    bool lost = false;
    for (int i = 0; i < 20 && !lost; ++i) {
        try {
            source.next();
        } catch (const io::SourceLost& error) {
            lost = true;
            EXPECT_THAT(error.what(), HasSubstr(nodes.capture));
        }
    }
    ASSERT_TRUE(lost);
    EXPECT_LT(std::chrono::steady_clock::now() - start, 2s)
        << "a pulled camera is noticed within its stall time";
    // The source let go of the node: the driver connects again, and the next call opens it anew.
    const std::optional<core::Frame> back = nextWithin(source, 10);
    ASSERT_TRUE(back);
    EXPECT_FALSE(back->image.empty());
}

// The loop: vivid's HDMI output shows frames of ours, its HDMI input captures them. `frameOf(number)` gives
// the output's frame `number` in the layout of `fourcc`: CV_8UC1 for GREY, CV_8UC2 for YUYV.
class LoopedFrames {
public:
    using FrameOf = std::function<cv::Mat(std::uint32_t number)>;

    LoopedFrames(const std::string& output, cv::Size size, std::uint32_t fourcc, FrameOf frameOf)
        : fd_(openNode(output)), size_(size), frameOf_(std::move(frameOf)) {
        unsigned index = 0;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_S_OUTPUT, &index), 0) << std::strerror(errno);
        v4l2_dv_timings timings = V4L2_DV_BT_CEA_640X480P59_94;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_S_DV_TIMINGS, &timings), 0) << std::strerror(errno);
        v4l2_format format{};
        format.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        format.fmt.pix.width = static_cast<std::uint32_t>(size.width);
        format.fmt.pix.height = static_cast<std::uint32_t>(size.height);
        format.fmt.pix.pixelformat = fourcc;
        format.fmt.pix.field = V4L2_FIELD_NONE;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_S_FMT, &format), 0) << std::strerror(errno);
        EXPECT_EQ(format.fmt.pix.pixelformat, fourcc);
        bytesPerLine_ = format.fmt.pix.bytesperline;
        v4l2_requestbuffers request{};
        request.count = 4;
        request.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        request.memory = V4L2_MEMORY_MMAP;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_REQBUFS, &request), 0) << std::strerror(errno);
        for (std::uint32_t i = 0; i < request.count; ++i) {
            v4l2_buffer buffer = outputBuffer(i);
            EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_QUERYBUF, &buffer), 0);
            void* start = ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_.get(),
                                 buffer.m.offset);
            EXPECT_NE(start, MAP_FAILED);
            buffers_.emplace_back(start, buffer.length);
            queue(buffer);
        }
        v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_STREAMON, &type), 0) << std::strerror(errno);
        feeder_ = std::thread([this] { feed(); });
    }
    ~LoopedFrames() {
        stop_ = true;
        feeder_.join();
        v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        ::ioctl(fd_.get(), VIDIOC_STREAMOFF, &type);
    }

    // Frame `number`: a pattern no two frames share, the number in the first row.
    static cv::Mat frame(std::uint32_t number, cv::Size size) {
        cv::Mat image(size, CV_8UC1);
        for (int y = 0; y < size.height; ++y)
            for (int x = 0; x < size.width; ++x)
                image.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((x * 7 + y * 3 + number * 29) % 251);
        for (int bit = 0; bit < 16; ++bit)
            image.at<std::uint8_t>(0, bit) = (number >> bit) & 1 ? 255 : 0;
        return image;
    }
    static std::uint32_t numberOf(const cv::Mat& image) {
        std::uint32_t number = 0;
        for (int bit = 0; bit < 16; ++bit)
            number |= (image.at<std::uint8_t>(0, bit) > 127 ? 1u : 0u) << bit;
        return number;
    }

private:
    v4l2_buffer outputBuffer(std::uint32_t index) const {
        v4l2_buffer buffer{};
        buffer.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        buffer.memory = V4L2_MEMORY_MMAP;
        buffer.index = index;
        return buffer;
    }
    void queue(v4l2_buffer& buffer) {
        const cv::Mat image = frameOf_(next_++);
        EXPECT_EQ(image.size(), size_);
        auto* bytes = const_cast<std::uint8_t*>(buffers_[buffer.index].data());
        for (int y = 0; y < size_.height; ++y)
            std::memcpy(bytes + y * bytesPerLine_, image.ptr(y), image.cols * image.elemSize());
        buffer.bytesused = bytesPerLine_ * static_cast<std::uint32_t>(size_.height);
        buffer.field = V4L2_FIELD_NONE;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_QBUF, &buffer), 0) << std::strerror(errno);
    }
    void feed() {
        while (!stop_) {
            pollfd ready{fd_.get(), POLLOUT, 0};
            if (::poll(&ready, 1, 100) <= 0)
                continue;
            v4l2_buffer buffer = outputBuffer(0);
            if (::ioctl(fd_.get(), VIDIOC_DQBUF, &buffer) == 0)
                queue(buffer);
        }
    }

    io::UniqueFd fd_;
    cv::Size size_;
    FrameOf frameOf_;
    std::uint32_t bytesPerLine_ = 0;
    std::vector<io::MemoryMapping> buffers_;
    std::uint32_t next_ = 0;
    std::atomic<bool> stop_{false};
    std::thread feeder_;
};

TEST(V4l2SourceOnVivid, FramesShownOnTheLoopedOutputArriveUnchanged) {
    VividNodes nodes;
    SKIP_WITHOUT_VIVID(nodes);
    selectInput(nodes.capture, kHdmiInput);
    setControl(nodes.capture, "Loop Video", 1);
    setControl(nodes.capture, "OSD Text Mode", 2);  // no text of vivid's own over the frames
    LoopedFrames looped(nodes.output, kLoopSize, V4L2_PIX_FMT_GREY,
                        [](std::uint32_t number) { return LoopedFrames::frame(number, kLoopSize); });
    io::CameraSettings gray;
    gray.pixels = io::CameraPixels::Mono8;
    gray.region = cv::Rect(cv::Point(0, 0), kLoopSize);
    io::V4l2Source source("--rig v4l2:" + nodes.capture, nodes.capture, gray);
    std::set<std::uint32_t> seen;
    for (int i = 0; i < 30; ++i) {
        const std::optional<core::Frame> frame = source.next();
        ASSERT_TRUE(frame);
        ASSERT_EQ(frame->image.size(), kLoopSize);
        const std::uint32_t number = LoopedFrames::numberOf(frame->image);
        const cv::Mat shown = LoopedFrames::frame(number, kLoopSize);
        EXPECT_EQ(cv::norm(frame->image, shown, cv::NORM_INF), 0.0)
            << "frame " << number << " changed on its way";
        seen.insert(number);
    }
    EXPECT_GE(seen.size(), 10u) << "the captured frames do not follow the output";
}

// A frame as a camera sends it in YUYV (BT.601, video range): what V4l2Source decodes back into `bgr`, two
// neighbouring pixels sharing their chroma.
cv::Mat yuyvOf(const cv::Mat& bgr) {
    cv::Mat yuyv(bgr.size(), CV_8UC2);
    const auto level = [](double value) { return cv::saturate_cast<std::uint8_t>(value); };
    for (int y = 0; y < bgr.rows; ++y)
        for (int x = 0; x + 1 < bgr.cols; x += 2) {
            double u = 0.0, v = 0.0;
            for (int k = 0; k < 2; ++k) {
                const cv::Vec3b pixel = bgr.at<cv::Vec3b>(y, x + k);
                const double b = pixel[0], g = pixel[1], r = pixel[2];
                yuyv.at<cv::Vec2b>(y, x + k)[0] = level(16.0 + 0.257 * r + 0.504 * g + 0.098 * b);
                u += 128.0 - 0.148 * r - 0.291 * g + 0.439 * b;
                v += 128.0 + 0.439 * r - 0.368 * g - 0.071 * b;
            }
            yuyv.at<cv::Vec2b>(y, x)[1] = level(u / 2.0);
            yuyv.at<cv::Vec2b>(y, x + 1)[1] = level(v / 2.0);
        }
    return yuyv;
}

// The touch log as far as the daemon has written it; nothing while it is writing an entry.
std::optional<std::vector<io::TouchLogEntry>> touchLogSoFar(const std::filesystem::path& path) {
    try {
        return io::readTouchLog(path);
    } catch (const io::InputError&) {
        return std::nullopt;
    }
}

// The touching contacts of the log's last entry.
std::vector<core::Contact> touchingNow(const std::vector<io::TouchLogEntry>& log) {
    std::vector<core::Contact> touching;
    if (!log.empty())
        for (const core::Contact& contact : log.back().contacts)
            if (contact.touching && !contact.palm)
                touching.push_back(contact);
    return touching;
}

// Positions in the recording of two consecutive frames whose true fingers all satisfy `holds` (at least one
// finger when `needFinger`), the last such two.
std::optional<std::size_t> lastPairWhere(const io::Recording& recording, bool needFinger,
                                         const std::function<bool(const core::FingerTruth&)>& holds) {
    const auto frameHolds = [&](std::uint64_t index) {
        bool any = false;
        for (const core::FingerTruth& finger : recording.truth())
            if (finger.frameIndex == index) {
                if (!holds(finger))
                    return false;
                any = true;
            }
        return any || !needFinger;
    };
    const std::vector<io::FrameEntry>& frames = recording.frames();
    for (std::size_t position = frames.size() - 1; position >= 1; --position)
        if (frameHolds(frames[position].index) && frameHolds(frames[position - 1].index))
            return position - 1;
    return std::nullopt;
}

// everytouchd detecting a touch through the V4L2 capture path: frames the simulated rig rendered (the
// recording run-vm-test.sh makes on the host) go out through vivid's HDMI output as YUYV, come back through
// its HDMI input, and the daemon reads them as any camera, knowing the rig's calibration and, as from a
// projector that embeds the code itself, its pattern. The pipeline runs a few pairs a second under emulation,
// far slower than the camera's 60 frames, so each scene is one pair of consecutive frames shown in turn:
// whichever frames the daemon has to leave out, two in a row hold the code. First the finger resting on the
// table, then the table after the finger lifted: the daemon touches down where the finger rests and lifts.
TEST(V4l2SourceOnVivid, TheDaemonDetectsARecordedTouchThroughTheCamera) {
    VividNodes nodes;
    SKIP_WITHOUT_VIVID(nodes);
    const char* recordingPath = std::getenv("EVERYTOUCH_TEST_RECORDING");
    if (!recordingPath)
        GTEST_SKIP() << "EVERYTOUCH_TEST_RECORDING names no recording with a touch (tests/vm sets it)";
    const io::Recording recording = io::Recording::open(recordingPath);
    ASSERT_TRUE(recording.hasTruth()) << recordingPath << " has no truth.csv";
    const std::optional<std::size_t> resting = lastPairWhere(
        recording, true, [](const core::FingerTruth& finger) { return finger.heightMm == 0.0; });
    const std::optional<std::size_t> lifted = lastPairWhere(
        recording, false, [](const core::FingerTruth& finger) { return finger.heightMm >= 10.0; });
    ASSERT_TRUE(resting && lifted && *resting < *lifted)
        << recordingPath << " has no finger resting on the table and lifted after";

    // The loop carries 640x480: the recording's frames lose their last columns and rows, the calibration
    // keeps its camera model, whose pixels keep their places.
    const auto scene = [&](std::size_t position) {
        std::array<cv::Mat, 2> frames;
        for (std::size_t k = 0; k < 2; ++k)
            frames[k] = yuyvOf(recording.loadFrame(position + k).image(cv::Rect(cv::Point(0, 0), kLoopSize)));
        return frames;
    };
    const std::array<std::array<cv::Mat, 2>, 2> scenes{scene(*resting), scene(*lifted)};
    std::atomic<std::size_t> shown{0};

    const test::TempDir dir;
    core::Calibration calibration = recording.rig().calibration;
    ASSERT_GE(calibration.cameraSize.width, kLoopSize.width);
    ASSERT_GE(calibration.cameraSize.height, kLoopSize.height);
    calibration.cameraSize = kLoopSize;
    io::writeCalibrationFile(dir.path() / "calibration.yml", calibration);
    // The daemon reads the pattern it keeps for its seed before it would generate it (minutes under
    // emulation): the recording's rig is the simulated rig of seed 1 (tests/vm/CMakeLists.txt), and this is
    // its pattern.
    const cv::Size projector = calibration.projectorSize;
    io::writePatternImage(dir.path() / ("pattern-seed1-" + std::to_string(projector.width) + "x" +
                                        std::to_string(projector.height) + ".png"),
                          recording.rig().pattern);
    std::ofstream(dir.path() / "everytouchd.conf")
        << "[Camera]\nRig=v4l2:" << nodes.capture << "\nRegion=" << kLoopSize.width << "x" << kLoopSize.height
        << "\n[Projector]\nOutput=external\nSeed=1\nDelta=" << recording.rig().delta
        << "\n[Output]\nUinput=no\n[Calibration]\nPath=" << (dir.path() / "calibration.yml").string() << "\n";

    selectInput(nodes.capture, kHdmiInput);
    setControl(nodes.capture, "Loop Video", 1);
    setControl(nodes.capture, "OSD Text Mode", 2);
    LoopedFrames looped(nodes.output, kLoopSize, V4L2_PIX_FMT_YUYV,
                        [&](std::uint32_t number) { return scenes[shown.load()][number % 2]; });
    const test::PrivateBus bus("", true);
    const char* daemonPath = std::getenv("EVERYTOUCHD");
    ASSERT_TRUE(daemonPath) << "EVERYTOUCHD names the daemon";
    const std::filesystem::path touchLog = dir.path() / "touches.jsonl";
    test::BackgroundProcess daemon(
        {daemonPath, "--config", (dir.path() / "everytouchd.conf").string(), "--log", touchLog.string()},
        dir.path() / "daemon.log");
    const auto waitFor = [&](const auto& condition) {
        const auto deadline = std::chrono::steady_clock::now() + 180s;
        while (std::chrono::steady_clock::now() < deadline && daemon.running()) {
            if (const auto log = touchLogSoFar(touchLog); log && condition(*log))
                return true;
            std::this_thread::sleep_for(200ms);
        }
        return false;
    };

    std::vector<core::Contact> down;
    std::uint64_t downIndex = 0;
    ASSERT_TRUE(waitFor([&](const std::vector<io::TouchLogEntry>& log) {
        down = touchingNow(log);
        downIndex = log.empty() ? 0 : log.back().index;
        return !down.empty();
    })) << "no touch through the camera\n"
        << daemon.output();
    ASSERT_EQ(down.size(), 1u);
    const std::uint64_t restingIndex = recording.frames()[*resting + 1].index;
    for (const core::FingerTruth& finger : recording.truth())
        if (finger.frameIndex == restingIndex) {
            const cv::Size2d mm = calibration.displaySizeMm();
            const double errorMm =
                std::hypot((down[0].x - finger.x) * mm.width / calibration.displaySize.width,
                           (down[0].y - finger.y) * mm.height / calibration.displaySize.height);
            // Half a finger's width, as everytouch-eval matches a touch to a finger.
            EXPECT_LE(errorMm, 8.0) << "touch at (" << down[0].x << ", " << down[0].y << "), finger at ("
                                    << finger.x << ", " << finger.y << ")";
        }

    shown = 1;
    EXPECT_TRUE(waitFor([&](const std::vector<io::TouchLogEntry>& log) {
        return !log.empty() && log.back().index > downIndex && touchingNow(log).empty();
    })) << "the touch stayed down after the finger lifted\n"
        << daemon.output();
    daemon.signal(SIGTERM);
    const std::optional<int> status = daemon.wait(60s);
    ASSERT_TRUE(status) << daemon.output();
    EXPECT_EQ(*status, 0) << daemon.output();
    std::cout << daemon.output();
}

// everytouchd itself on the camera without a calibration: it streams and counts the frames.
TEST(V4l2SourceOnVivid, TheDaemonRunsOnTheCamera) {
    VividNodes nodes;
    SKIP_WITHOUT_VIVID(nodes);
    selectInput(nodes.capture, kWebcamInput);
    const test::TempDir dir;
    const test::PrivateBus bus("", true);
    const char* daemonPath = std::getenv("EVERYTOUCHD");
    ASSERT_TRUE(daemonPath) << "EVERYTOUCHD names the daemon";
    test::BackgroundProcess daemon({daemonPath, "--rig", "v4l2:" + nodes.capture, "--frames", "40"},
                                   dir.path() / "daemon.log");
    const std::optional<int> status = daemon.wait(60s);
    const std::string log = test::fileContents(dir.path() / "daemon.log");
    ASSERT_TRUE(status) << log;
    EXPECT_EQ(*status, 0) << log;
    EXPECT_THAT(log, HasSubstr("on V4L2 camera"));
    EXPECT_THAT(log, HasSubstr("processed 40 frames"));
}

}  // namespace
}  // namespace everytouch

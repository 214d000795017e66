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

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/handles.h"
#include "io/input_error.h"
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

// The loop: vivid's HDMI output shows frames of ours, its HDMI input captures them.
class LoopedFrames {
public:
    LoopedFrames(const std::string& output, cv::Size size) : fd_(openNode(output)), size_(size) {
        unsigned index = 0;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_S_OUTPUT, &index), 0) << std::strerror(errno);
        v4l2_dv_timings timings = V4L2_DV_BT_CEA_640X480P59_94;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_S_DV_TIMINGS, &timings), 0) << std::strerror(errno);
        v4l2_format format{};
        format.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        format.fmt.pix.width = static_cast<std::uint32_t>(size.width);
        format.fmt.pix.height = static_cast<std::uint32_t>(size.height);
        format.fmt.pix.pixelformat = V4L2_PIX_FMT_GREY;
        format.fmt.pix.field = V4L2_FIELD_NONE;
        EXPECT_EQ(::ioctl(fd_.get(), VIDIOC_S_FMT, &format), 0) << std::strerror(errno);
        EXPECT_EQ(format.fmt.pix.pixelformat, V4L2_PIX_FMT_GREY);
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
        const cv::Mat image = frame(next_++, size_);
        auto* bytes = const_cast<std::uint8_t*>(buffers_[buffer.index].data());
        for (int y = 0; y < size_.height; ++y)
            std::memcpy(bytes + y * bytesPerLine_, image.ptr(y), static_cast<std::size_t>(size_.width));
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
    LoopedFrames looped(nodes.output, kLoopSize);
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

// everytouchd itself on the camera: it streams and counts the frames; detection needs the code's description,
// which a camera rig does not have yet, and the daemon says so.
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

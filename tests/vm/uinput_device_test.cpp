// The virtual touchscreen on a real kernel, read back by real clients: libevdev, evemu-record, udev and
// libinput. tests/vm/run-vm-test.sh runs this inside a virtual machine; elsewhere it skips.
#include <fcntl.h>
#include <libevdev/libevdev.h>
#include <linux/input.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <systemd/sd-bus.h>

#include <csignal>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/evdev_handles.h"
#include "io/recording.h"
#include "io/touch_log.h"
#include "io/touchscreen_axes.h"
#include "io/uinput_sink.h"
#include "service/bus_names.h"
#include "support/file_contents.h"
#include "support/private_bus.h"
#include "support/process.h"
#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;
using ::testing::Not;

// Under emulation a client can take seconds to start; nothing here waits that long when things work.
constexpr auto kPatience = 30s;

#define SKIP_WITHOUT_UINPUT()                                                                          \
    do {                                                                                               \
        if (!std::filesystem::exists("/dev/uinput"))                                                   \
            GTEST_SKIP()                                                                               \
                << "/dev/uinput is missing (no uinput kernel module here); tests/vm runs these tests " \
                   "on a real kernel";                                                                 \
        if (const char* allowed = std::getenv("EVERYTOUCH_UINPUT_TESTS");                              \
            !allowed || std::string(allowed) != "1")                                                   \
            GTEST_SKIP()                                                                               \
                << "these tests create a touchscreen a running desktop would act on; tests/vm sets "   \
                   "EVERYTOUCH_UINPUT_TESTS=1 to run them";                                            \
    } while (false)

template <typename Condition>
bool waitFor(Condition condition, std::chrono::milliseconds timeout = kPatience) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
        if (std::chrono::steady_clock::now() >= deadline)
            return false;
        std::this_thread::sleep_for(20ms);
    }
    return true;
}

// Where udev keeps what it found out about a character device.
std::filesystem::path udevDatabaseEntry(const std::string& devnode) {
    struct stat info {};
    if (stat(devnode.c_str(), &info) != 0)
        return {};
    return "/run/udev/data/c" + std::to_string(major(info.st_rdev)) + ":" +
           std::to_string(minor(info.st_rdev));
}

// Waits until udev has processed the device; libinput ignores input devices udev has not tagged.
std::string udevProperties(const std::string& devnode) {
    const std::filesystem::path entry = udevDatabaseEntry(devnode);
    if (entry.empty() || !waitFor([&] { return std::filesystem::exists(entry); }))
        return {};
    return test::fileContents(entry);
}

// Waits until udev has processed the removal of a device, whose event node a new device may get next.
bool udevForgot(const std::filesystem::path& entry) {
    return waitFor([&] { return !std::filesystem::exists(entry); });
}

// Waits until a client has the event node open and has read the device's state: events that arrive while
// evemu-record and libinput take their snapshot of the device do not all show in their output.
bool attached(const test::BackgroundProcess& client, const std::string& devnode) {
    if (!waitFor([&] { return client.hasOpen(devnode); }))
        return false;
    std::this_thread::sleep_for(300ms);
    return true;
}

// Display pixels -> millimetres on the table the way the projected display lies there, as libinput should
// report them.
cv::Point2d expectedMm(const core::Calibration& calibration, double x, double y) {
    const cv::Size2d size = calibration.displaySizeMm();
    return {x * size.width / calibration.displaySize.width, y * size.height / calibration.displaySize.height};
}

// The block `libinput list-devices` prints for one event node.
std::string libinputDeviceBlock(const std::string& listing, const std::string& devnode) {
    std::istringstream lines(listing);
    std::string block, line;
    std::vector<std::string> blocks(1);
    while (std::getline(lines, line)) {
        if (line.empty())
            blocks.emplace_back();
        else
            blocks.back() += line + "\n";
    }
    for (const std::string& candidate : blocks)
        if (std::regex_search(candidate, std::regex("Kernel: +" + devnode + "\n")))
            return candidate;
    return {};
}

cv::Size2d libinputSizeMm(const std::string& block) {
    std::smatch match;
    if (!std::regex_search(block, match, std::regex(R"(Size: +([0-9.]+)x([0-9.]+)mm)")))
        return {};
    return {std::stod(match[1]), std::stod(match[2])};
}

// One touch event as `libinput debug-events` prints it.
struct LibinputTouch {
    std::string type;  // TOUCH_DOWN, TOUCH_MOTION, TOUCH_UP, TOUCH_CANCEL
    int slot = -1;
    cv::Point2d mm;  // for DOWN and MOTION
};

std::vector<LibinputTouch> libinputTouches(const std::string& output) {
    std::vector<LibinputTouch> touches;
    const std::regex pattern(
        R"((TOUCH_(?:DOWN|MOTION|UP|CANCEL))\s+\S+\s+(\d+) \(\d+\)(?:\s+\S+/\s*\S+\s+\(\s*([-0-9.]+)/\s*([-0-9.]+)mm\))?)");
    for (std::sregex_iterator it(output.begin(), output.end(), pattern), end; it != end; ++it) {
        LibinputTouch touch{(*it)[1], std::stoi((*it)[2]), {}};
        if ((*it)[3].matched)
            touch.mm = {std::stod((*it)[3]), std::stod((*it)[4])};
        touches.push_back(touch);
    }
    return touches;
}

std::vector<io::EvdevEvent> evemuEvents(const std::string& output) {
    std::vector<io::EvdevEvent> events;
    const std::regex pattern(R"(^E: \S+ ([0-9a-f]{4}) ([0-9a-f]{4}) (-?[0-9]+))");
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);) {
        std::smatch match;
        if (std::regex_search(line, match, pattern))
            events.push_back({static_cast<std::uint16_t>(std::stoi(match[1], nullptr, 16)),
                              static_cast<std::uint16_t>(std::stoi(match[2], nullptr, 16)),
                              std::stoi(match[3])});
    }
    return events;
}

std::string describe(const std::vector<io::EvdevEvent>& events) {
    std::string text;
    for (const io::EvdevEvent& e : events)
        text +=
            std::string(libevdev_event_code_get_name(e.type, e.code)) + " " + std::to_string(e.value) + "\n";
    return text;
}

// Reads a device node through libevdev, as a compositor would, without blocking.
class EvdevReader {
public:
    explicit EvdevReader(const std::string& devnode)
        : fd_(open(devnode.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)) {
        libevdev* device = nullptr;
        if (fd_ && libevdev_new_from_fd(fd_.get(), &device) == 0)
            device_.reset(device);
    }
    explicit operator bool() const { return static_cast<bool>(device_); }
    libevdev* get() const { return device_.get(); }

    // Everything queued; stops at the end of the queue or when the device is gone.
    std::vector<io::EvdevEvent> drain() {
        std::vector<io::EvdevEvent> events;
        input_event event{};
        while (true) {
            const int status = libevdev_next_event(device_.get(), LIBEVDEV_READ_FLAG_NORMAL, &event);
            if (status == LIBEVDEV_READ_STATUS_SUCCESS)
                events.push_back({event.type, event.code, event.value});
            else if (status == LIBEVDEV_READ_STATUS_SYNC)
                events.push_back({EV_SYN, SYN_DROPPED, 0});
            else
                return events;
        }
    }

private:
    io::UniqueFd fd_;
    io::UniqueLibevdev device_;
};

// A touchscreen created from the paper rig's calibration with libinput debug-events and evemu-record
// attached, and a libevdev reader in this process.
class LiveTouchscreen : public ::testing::Test {
protected:
    void SetUp() override {
        SKIP_WITHOUT_UINPUT();
        sink_ = std::make_unique<io::UinputSink>(calibration_);
        devnode_ = sink_->devnode();
        udevEntry_ = udevDatabaseEntry(devnode_);
        udev_ = udevProperties(devnode_);
        ASSERT_THAT(udev_, HasSubstr("E:ID_INPUT=1")) << "udev did not process " << devnode_;
        reader_ = std::make_unique<EvdevReader>(devnode_);
        ASSERT_TRUE(*reader_) << "libevdev cannot read " << devnode_;
        libinput_ = std::make_unique<test::BackgroundProcess>(
            std::vector<std::string>{"libinput", "debug-events", "--device", devnode_},
            dir_ / "libinput.txt");
        evemu_ = std::make_unique<test::BackgroundProcess>(std::vector<std::string>{"evemu-record", devnode_},
                                                           dir_ / "evemu.txt");
        ASSERT_TRUE(attached(*libinput_, devnode_) && attached(*evemu_, devnode_))
            << "the clients never opened " << devnode_;
    }

    void publish(const core::Contacts& contacts) {
        const std::int64_t timestampUs = static_cast<std::int64_t>(frame_) * 8333;
        sink_->publish(frame_, timestampUs, contacts);
        const std::vector<io::EvdevEvent>& expected = twin_.encode(timestampUs, contacts);
        expected_.insert(expected_.end(), expected.begin(), expected.end());
        const std::vector<io::EvdevEvent> read = reader_->drain();
        read_.insert(read_.end(), read.begin(), read.end());
        ++frame_;
        // A real camera delivers frames apart; clients keep up instead of finding their queue overflowed.
        std::this_thread::sleep_for(10ms);
    }

    // Destroys the device (releasing what is down) and collects what the clients saw.
    void finish() {
        // This process reads nothing once the device is gone; the clients, waiting in read(), get the lift.
        readable_ = expected_;
        sink_.reset();
        const std::int64_t lastTimestampUs = frame_ > 0 ? static_cast<std::int64_t>(frame_ - 1) * 8333 : 0;
        const std::vector<io::EvdevEvent>& released = twin_.encode(lastTimestampUs, {});
        expected_.insert(expected_.end(), released.begin(), released.end());
        EXPECT_TRUE(evemu_->wait(kPatience)) << "evemu-record did not end with the device";
        std::this_thread::sleep_for(300ms);
        libinput_->signal(SIGINT);
        EXPECT_TRUE(libinput_->wait(kPatience)) << "libinput debug-events did not stop";
        libinputOutput_ = test::fileContents(dir_ / "libinput.txt");
        evemuOutput_ = test::fileContents(dir_ / "evemu.txt");
        EXPECT_TRUE(udevForgot(udevEntry_));
    }

    const core::Calibration calibration_ = test::paperLikeCalibration();
    test::TempDir dir_;
    std::unique_ptr<io::UinputSink> sink_;
    std::string devnode_;
    std::filesystem::path udevEntry_;
    std::string udev_;
    std::unique_ptr<EvdevReader> reader_;
    std::unique_ptr<test::BackgroundProcess> libinput_;
    std::unique_ptr<test::BackgroundProcess> evemu_;
    io::MultitouchEncoder twin_{
        io::TouchscreenAxes::forDisplay(calibration_.displaySize, calibration_.displaySizeMm())};
    std::uint64_t frame_ = 0;
    std::vector<io::EvdevEvent> expected_;  // everything sent, including the lift on removal
    std::vector<io::EvdevEvent> readable_;  // what was sent while the device existed
    std::vector<io::EvdevEvent> read_;
    std::string libinputOutput_;
    std::string evemuOutput_;
};

core::Contact finger(std::uint32_t id, double x, double y) {
    return {id, x, y, true, 0.0, false};
}

TEST_F(LiveTouchscreen, DescribesADirectTouchscreenOfTheProjectedSize) {
    libevdev* device = reader_->get();
    EXPECT_STREQ(libevdev_get_name(device), "everytouch virtual touchscreen");
    EXPECT_EQ(libevdev_get_id_bustype(device), BUS_VIRTUAL);
    EXPECT_EQ(libevdev_get_id_vendor(device), io::UinputSink::kVendorId);
    EXPECT_EQ(libevdev_get_id_product(device), io::UinputSink::kProductId);
    EXPECT_TRUE(libevdev_has_property(device, INPUT_PROP_DIRECT));
    EXPECT_TRUE(libevdev_has_event_code(device, EV_KEY, BTN_TOUCH));
    for (unsigned absent : {BTN_LEFT, BTN_TOOL_PEN, BTN_STYLUS, BTN_TOOL_RUBBER})
        EXPECT_FALSE(libevdev_has_event_code(device, EV_KEY, absent))
            << libevdev_event_code_get_name(EV_KEY, absent);
    EXPECT_EQ(libevdev_get_num_slots(device), 10);
    EXPECT_EQ(libevdev_get_abs_maximum(device, ABS_MT_TRACKING_ID),
              io::MultitouchEncoder::kMaximumTrackingId);
    EXPECT_TRUE(libevdev_has_event_code(device, EV_MSC, MSC_TIMESTAMP));
    const io::TouchscreenAxes& axes = sink_->axes();
    for (unsigned code : {ABS_X, ABS_MT_POSITION_X}) {
        EXPECT_EQ(libevdev_get_abs_maximum(device, code), axes.maximumX);
        EXPECT_EQ(libevdev_get_abs_resolution(device, code), axes.resolutionX);
    }
    for (unsigned code : {ABS_Y, ABS_MT_POSITION_Y}) {
        EXPECT_EQ(libevdev_get_abs_maximum(device, code), axes.maximumY);
        EXPECT_EQ(libevdev_get_abs_resolution(device, code), axes.resolutionY);
    }

    std::cout << "udev database entry of " << devnode_ << ":\n" << udev_;
    EXPECT_THAT(udev_, HasSubstr("E:ID_INPUT_TOUCHSCREEN=1"));
    for (const char* other : {"ID_INPUT_TABLET", "ID_INPUT_TOUCHPAD", "ID_INPUT_MOUSE", "ID_INPUT_JOYSTICK"})
        EXPECT_THAT(udev_, Not(HasSubstr(other)));
    // udev/70-everytouch.rules
    EXPECT_THAT(udev_, HasSubstr("S:input/everytouch-touchscreen\n"));
    EXPECT_EQ(std::filesystem::canonical("/dev/input/everytouch-touchscreen"), devnode_);

    const test::ProcessResult listing = test::runProcess({"/usr/bin/libinput", "list-devices"});
    const std::string block = libinputDeviceBlock(listing.out, devnode_);
    ASSERT_FALSE(block.empty()) << "libinput list-devices does not list " << devnode_ << ":\n" << listing.out;
    std::cout << "libinput list-devices:\n" << block;
    EXPECT_THAT(block, ::testing::ContainsRegex("Capabilities: +touch *\n"));
    const cv::Size2d projected = calibration_.displaySizeMm();
    const cv::Size2d reported = libinputSizeMm(block);
    EXPECT_NEAR(reported.width, projected.width, 0.02 * projected.width);
    EXPECT_NEAR(reported.height, projected.height, 0.02 * projected.height);
    finish();
}

TEST_F(LiveTouchscreen, ClientsFollowAScriptedHand) {
    // Display pixels of the paper rig's 1280x960 display.
    publish({finger(1, 320, 240)});        // down
    for (int step = 1; step <= 4; ++step)  // move right
        publish({finger(1, 320 + 20 * step, 240)});
    publish({finger(1, 400, 240), finger(2, 960, 720)});                // a second finger
    publish({finger(1, 410, 250), finger(2, 950, 710)});                // both move
    publish({finger(1, 420, 260), {2, 950, 710, true, 0.0, true}});     // the second turns out a palm
    publish({finger(1, 430, 270)});                                     // the palm vanishes
    publish({finger(1, 430, 270), {3, 640, 480, false, 12.0, false}});  // a hovering finger is no touch
    publish({finger(1, 430, 270), finger(3, 640, 480)});                // until it lands
    publish({finger(3, 640, 480)});                                     // the first vanishes
    publish({});                                                        // all lifted
    finish();

    EXPECT_EQ(describe(read_), describe(readable_)) << "libevdev read other events than were encoded";
    EXPECT_EQ(describe(evemuEvents(evemuOutput_)), describe(expected_)) << evemuOutput_;
    EXPECT_THAT(evemuOutput_, HasSubstr("N: everytouch virtual touchscreen"));
    std::cout << "evemu-record:\n" << evemuOutput_;

    struct Expected {
        const char* type;
        int slot;
        double x = -1, y = -1;  // display pixels, for DOWN and MOTION
    };
    const std::vector<Expected> script = {
        {"TOUCH_DOWN", 0, 320, 240},
        {"TOUCH_MOTION", 0, 340, 240},
        {"TOUCH_MOTION", 0, 360, 240},
        {"TOUCH_MOTION", 0, 380, 240},
        {"TOUCH_MOTION", 0, 400, 240},
        {"TOUCH_DOWN", 1, 960, 720},
        {"TOUCH_MOTION", 0, 410, 250},
        {"TOUCH_MOTION", 1, 950, 710},
        {"TOUCH_MOTION", 0, 420, 260},
        {"TOUCH_CANCEL", 1},
        {"TOUCH_MOTION", 0, 430, 270},
        {"TOUCH_DOWN", 1, 640, 480},
        {"TOUCH_UP", 0},
        {"TOUCH_UP", 1},
    };
    const std::vector<LibinputTouch> seen = libinputTouches(libinputOutput_);
    std::cout << "libinput debug-events:\n" << libinputOutput_;
    ASSERT_EQ(seen.size(), script.size()) << libinputOutput_;
    const cv::Size2d size = calibration_.displaySizeMm();
    for (size_t i = 0; i < script.size(); ++i) {
        SCOPED_TRACE("libinput event " + std::to_string(i));
        EXPECT_EQ(seen[i].type, script[i].type);
        EXPECT_EQ(seen[i].slot, script[i].slot);
        if (script[i].x < 0)
            continue;
        const cv::Point2d mm = expectedMm(calibration_, script[i].x, script[i].y);
        // The integer resolution keeps positions within 0.5 % of the true scale; debug-events prints 0.01 mm.
        EXPECT_NEAR(seen[i].mm.x, mm.x, 0.005 * size.width);
        EXPECT_NEAR(seen[i].mm.y, mm.y, 0.005 * size.height);
    }
}

TEST_F(LiveTouchscreen, RemovingTheDeviceLiftsEveryContactFirst) {
    publish({finger(4, 100, 100), finger(5, 1100, 800)});
    publish({finger(4, 110, 100), finger(5, 1100, 810)});
    finish();
    EXPECT_EQ(describe(read_), describe(readable_));
    EXPECT_EQ(describe(evemuEvents(evemuOutput_)), describe(expected_))
        << "the lift did not reach evemu-record";
    std::map<int, int> down;
    for (const LibinputTouch& touch : libinputTouches(libinputOutput_))
        down[touch.slot] = touch.type == "TOUCH_DOWN" || touch.type == "TOUCH_MOTION";
    EXPECT_EQ(down.size(), 2u) << libinputOutput_;
    for (const auto& [slot, isDown] : down)
        EXPECT_FALSE(isDown) << "slot " << slot << " left down:\n" << libinputOutput_;
}

TEST(UinputSink, ANewDisplaySizeRecreatesTheDeviceAfterLiftingContacts) {
    SKIP_WITHOUT_UINPUT();
    core::Calibration calibration = test::paperLikeCalibration();
    auto owned = std::make_unique<io::UinputSink>(calibration);
    io::UinputSink& sink = *owned;
    const std::string first = sink.devnode();
    const std::filesystem::path firstEntry = udevDatabaseEntry(first);
    ASSERT_THAT(udevProperties(first), HasSubstr("E:ID_INPUT=1"));
    test::TempDir dir;
    test::BackgroundProcess evemu({"evemu-record", first}, dir / "evemu.txt");
    ASSERT_TRUE(attached(evemu, first));
    sink.publish(0, 0, {finger(1, 100, 100)});
    EXPECT_FALSE(sink.applyCalibration(calibration)) << "an unchanged size recreated the device";
    EXPECT_EQ(sink.devnode(), first);

    calibration.displaySize = {1920, 1440};
    calibration.displayToProjector = Eigen::Vector3d(1.0 / 3.0, 1.0 / 3.0, 1).asDiagonal();
    ASSERT_TRUE(sink.applyCalibration(calibration));
    EXPECT_NE(sink.devnode(), first);
    EXPECT_TRUE(evemu.wait(kPatience)) << "evemu-record still reads the old device";
    const std::string oldEvents = describe(evemuEvents(test::fileContents(dir / "evemu.txt")));
    EXPECT_THAT(oldEvents, ::testing::EndsWith("ABS_MT_TRACKING_ID -1\nBTN_TOUCH 0\nBTN_TOOL_FINGER 0\n"
                                               "MSC_TIMESTAMP 0\nSYN_REPORT 0\n"));
    EXPECT_TRUE(udevForgot(firstEntry));

    ASSERT_THAT(udevProperties(sink.devnode()), HasSubstr("E:ID_INPUT_TOUCHSCREEN=1"));
    EvdevReader newReader(sink.devnode());
    ASSERT_TRUE(newReader);
    EXPECT_EQ(libevdev_get_abs_maximum(newReader.get(), ABS_MT_POSITION_X),
              1920 * sink.axes().unitsPerPixel - 1);
    const cv::Size2d sizeMm = calibration.displaySizeMm();
    EXPECT_NEAR(sink.axes().sizeMm().width, sizeMm.width, 0.005 * sizeMm.width);
    const std::filesystem::path secondEntry = udevDatabaseEntry(sink.devnode());
    owned.reset();
    EXPECT_TRUE(udevForgot(secondEntry));
}

// The DevicePath property of the daemon on the system bus; empty when it cannot be read.
std::string busDevicePath() {
    sd_bus* raw = nullptr;
    if (sd_bus_open_system(&raw) < 0)
        return {};
    const io::Bus bus(raw);
    sd_bus_error error = SD_BUS_ERROR_NULL;
    char* value = nullptr;
    const int r = sd_bus_get_property_string(bus.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                             "DevicePath", &error, &value);
    sd_bus_error_free(&error);
    if (r < 0)
        return {};
    const std::unique_ptr<char, decltype(&std::free)> owned(value, &std::free);
    return value;
}

// The daemon on a recording of the paper rig, with --output uinput: the touchscreen it creates has the size
// of the recorded rig's projected display, its node is the daemon's DevicePath on the bus, and it goes away
// with the daemon. The recording's frames are blank; Everytouchd.ReplaysARecordedDragOntoItsTouchscreen
// follows a finger the daemon detects onto the screen.
TEST(Everytouchd, CreatesTheVirtualTouchscreenOfItsRig) {
    SKIP_WITHOUT_UINPUT();
    test::TempDir dir;
    io::RigDescription rig = test::paperLikeRig();
    {
        io::RecordingWriter writer(dir / "recording", rig, false);
        for (std::uint64_t i = 0; i < 40; ++i) {
            core::Frame frame;
            frame.index = i;
            frame.timestampUs = static_cast<std::int64_t>(i) * 100000;  // 4 s in all, paced
            frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
            frame.image = cv::Mat(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(128));
            writer.addFrame(frame);
        }
    }
    // The daemon's own checks are tested elsewhere; here any caller may read.
    const test::PrivateBus bus("", true);
    const char* daemonPath = std::getenv("EVERYTOUCHD");
    test::BackgroundProcess daemon({daemonPath ? daemonPath : EVERYTOUCHD_PATH, "--rig",
                                    "replay:" + (dir / "recording").string(), "--output", "uinput"},
                                   dir / "daemon.log");
    std::smatch match;
    std::string log;
    const std::regex announced("virtual touchscreen (/dev/input/event[0-9]+)");
    ASSERT_TRUE(waitFor([&] {
        log = test::fileContents(dir / "daemon.log");
        return std::regex_search(log, match, announced);
    })) << log;
    const std::string devnode = match[1];
    ASSERT_THAT(udevProperties(devnode), HasSubstr("E:ID_INPUT_TOUCHSCREEN=1"));
    std::string published;
    EXPECT_TRUE(waitFor([&] { return (published = busDevicePath()) == devnode; }))
        << "DevicePath is \"" << published << "\", the device " << devnode;

    const test::ProcessResult listing = test::runProcess({"/usr/bin/libinput", "list-devices"});
    const std::string block = libinputDeviceBlock(listing.out, devnode);
    ASSERT_FALSE(block.empty()) << listing.out;
    EXPECT_THAT(block, HasSubstr("everytouch virtual touchscreen"));
    EXPECT_THAT(block, ::testing::ContainsRegex("Capabilities: +touch *\n"));
    const cv::Size2d projected = rig.calibration.displaySizeMm();
    const cv::Size2d reported = libinputSizeMm(block);
    EXPECT_NEAR(reported.width, projected.width, 0.02 * projected.width) << block;
    EXPECT_NEAR(reported.height, projected.height, 0.02 * projected.height) << block;

    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.wait(kPatience), 0) << test::fileContents(dir / "daemon.log");
    EXPECT_TRUE(waitFor([&] { return !std::filesystem::exists(devnode); }))
        << "the touchscreen outlived the daemon";
    std::cout << "everytouchd log:\n" << test::fileContents(dir / "daemon.log");
}

// The input event nodes there are now.
std::set<std::filesystem::path> eventNodes() {
    std::set<std::filesystem::path> nodes;
    for (const auto& entry : std::filesystem::directory_iterator("/dev/input"))
        if (entry.path().filename().string().starts_with("event"))
            nodes.insert(entry.path());
    return nodes;
}

// Whether a touch log, as far as its lines are complete, has a frame without touches after one with a touch.
bool logsALift(const std::string& log) {
    bool touched = false;
    for (std::size_t start = 0, end; (end = log.find('\n', start)) != std::string::npos; start = end + 1) {
        const bool touching = log.substr(start, end - start).find("\"touch\":true") != std::string::npos;
        if (touched && !touching)
            return true;
        touched = touched || touching;
    }
    return false;
}

// A touching finger in the daemon's touch log, where the device reports it.
struct LoggedTouch {
    std::uint64_t index = 0;  // frame
    std::size_t entry = 0;    // position in the log
    std::uint32_t id = 0;
    bool begins = false;   // not touching in the entry before
    cv::Point2d px;        // display pixels, as logged
    cv::Point2d deviceMm;  // through the touchscreen's axes, as libinput computes it
    cv::Point2i units;     // the axis units the position rounds to
};

std::vector<LoggedTouch> loggedTouches(const std::vector<io::TouchLogEntry>& log,
                                       const io::TouchscreenAxes& axes) {
    std::vector<LoggedTouch> touches;
    std::set<std::uint32_t> touching;
    for (std::size_t i = 0; i < log.size(); ++i) {
        std::set<std::uint32_t> now;
        for (const core::Contact& contact : log[i].contacts) {
            if (!contact.touching || contact.palm)
                continue;
            now.insert(contact.id);
            const cv::Point2i units(axes.unitsX(contact.x), axes.unitsY(contact.y));
            touches.push_back({log[i].index,
                               i,
                               contact.id,
                               !touching.contains(contact.id),
                               {contact.x, contact.y},
                               {static_cast<double>(units.x) / axes.resolutionX,
                                static_cast<double>(units.y) / axes.resolutionY},
                               units});
        }
        touching = now;
    }
    return touches;
}

// The nearest true contact point of frame `index`, in mm from `mm` on the table; infinite without one.
double truthDistanceMm(const io::Recording& recording, std::uint64_t index, const cv::Point2d& mm) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const core::FingerTruth& finger : recording.truth())
        if (finger.frameIndex == index)
            nearest =
                std::min(nearest, cv::norm(expectedMm(recording.rig().calibration, finger.x, finger.y) - mm));
    return nearest;
}

// How far a reported touch may lie from the true contact point: everytouch-eval's match radius, half a
// finger's width, the middle between a finger's contact point and its neighbour's; further off, the touch
// could be the neighbour's. The pipeline's touches on this drag lie within about 3 mm of the truth, most of
// it the lag of its filter behind the sliding finger.
constexpr double kTruthToleranceMm = 8.0;

// everytouchd replays a recording of the simulated rig (run-vm-test.sh makes it on the host, where rendering
// is fast) with --output uinput: the last 0.5 s (28 mm) of a finger dragged along a side of a square, held
// still and lifted. libinput sees the daemon's touches exactly as its touch log has them, each frame's move
// as its own motion, and where the true finger is.
TEST(Everytouchd, ReplaysARecordedDragOntoItsTouchscreen) {
    SKIP_WITHOUT_UINPUT();
    const char* recordingPath = std::getenv("EVERYTOUCH_TEST_RECORDING");
    if (!recordingPath)
        GTEST_SKIP() << "EVERYTOUCH_TEST_RECORDING names no recording with a touch (tests/vm sets it)";
    const io::Recording recording = io::Recording::open(recordingPath);
    ASSERT_TRUE(recording.hasTruth()) << recordingPath << " has no truth.csv";
    const core::Calibration& calibration = recording.rig().calibration;
    const io::TouchscreenAxes axes =
        io::TouchscreenAxes::forDisplay(calibration.displaySize, calibration.displaySizeMm());

    test::TempDir dir;
    const std::set<std::filesystem::path> before = eventNodes();
    const char* daemonPath = std::getenv("EVERYTOUCHD");
    // --fast: every frame is processed, however slowly this machine runs the pipeline, as on the host.
    test::BackgroundProcess daemon(
        {daemonPath ? daemonPath : EVERYTOUCHD_PATH, "--rig", std::string("replay:") + recordingPath,
         "--fast", "--output", "uinput", "--log", (dir / "touches.jsonl").string()},
        dir / "daemon.log");
    // The daemon is held as soon as its touchscreen appears, until libinput has it open: the finger touches
    // within the first frames.
    std::filesystem::path devnode;
    const bool appeared = waitFor(
        [&] {
            for (const std::filesystem::path& node : eventNodes())
                if (!before.contains(node))
                    devnode = node;
            return !devnode.empty() || !daemon.running();
        },
        kPatience);
    daemon.signal(SIGSTOP);
    ASSERT_TRUE(appeared && !devnode.empty()) << "no touchscreen appeared\n" << daemon.output();
    ASSERT_THAT(udevProperties(devnode), HasSubstr("E:ID_INPUT_TOUCHSCREEN=1"));
    test::BackgroundProcess libinput({"libinput", "debug-events", "--device", devnode.string()},
                                     dir / "libinput.txt");
    const bool opened = attached(libinput, devnode);
    ASSERT_TRUE(test::fileContents(dir / "touches.jsonl").find("\"touch\":true") == std::string::npos)
        << "the daemon reported a touch before libinput was there";
    daemon.signal(SIGCONT);
    ASSERT_TRUE(opened) << "libinput debug-events never opened " << devnode;

    // Held again once it has logged the lift (the daemon writes its touchscreen before its log), until
    // libinput shows the up: an up that came only with the device's removal at the end would be a lift the
    // screen missed.
    constexpr auto kReplayPatience = 300s;  // 108 frames take 25 s under emulation
    ASSERT_TRUE(
        waitFor([&] { return logsALift(test::fileContents(dir / "touches.jsonl")) || !daemon.running(); },
                kReplayPatience));
    daemon.signal(SIGSTOP);
    ASSERT_TRUE(daemon.running()) << "the replay ended before its lift could be checked\n" << daemon.output();
    EXPECT_TRUE(waitFor([&] {
        return test::fileContents(dir / "libinput.txt").find("TOUCH_UP") != std::string::npos;
    })) << "libinput showed no up after the daemon's lift:\n"
        << test::fileContents(dir / "libinput.txt");
    daemon.signal(SIGCONT);

    // The daemon ends with the recording and takes its touchscreen along.
    const std::optional<int> status = daemon.wait(kReplayPatience);
    ASSERT_TRUE(status) << "the replay did not end\n" << daemon.output();
    EXPECT_EQ(*status, 0) << daemon.output();
    EXPECT_TRUE(waitFor([&] { return !std::filesystem::exists(devnode); }));
    std::this_thread::sleep_for(300ms);
    libinput.signal(SIGINT);
    EXPECT_TRUE(libinput.wait(kPatience)) << "libinput debug-events did not stop";
    const std::string libinputOutput = test::fileContents(dir / "libinput.txt");
    std::cout << "everytouchd log:\n" << daemon.output() << "libinput debug-events:\n" << libinputOutput;

    const std::vector<io::TouchLogEntry> log = io::readTouchLog(dir / "touches.jsonl");
    const std::vector<LoggedTouch> logged = loggedTouches(log, axes);
    const auto downs = static_cast<std::size_t>(
        std::ranges::count_if(logged, [](const LoggedTouch& t) { return t.begins; }));
    ASSERT_GE(downs, 1u) << "the daemon detected no touch in " << recordingPath;
    // A lift the daemon saw, not the release of what still touches when the recording ends.
    ASSERT_LT(logged.back().entry + 1, log.size());
    ASSERT_LT(log[logged.back().entry + 1].index, recording.frames().back().index)
        << "the finger still touched at the end of the recording";

    // Every touch the daemon logged reaches the table where the finger is.
    double worstLoggedMm = 0.0;
    for (const LoggedTouch& touch : logged) {
        const double error =
            truthDistanceMm(recording, touch.index, expectedMm(calibration, touch.px.x, touch.px.y));
        worstLoggedMm = std::max(worstLoggedMm, error);
        EXPECT_LE(error, kTruthToleranceMm) << "touch log, frame " << touch.index;
    }

    // Each libinput down and motion is a touch of the log, in the log's order, at the position the device
    // carries: in axis units of 0.01 mm or finer, from the log's position rounded to 0.01 px (under a unit),
    // printed by libinput to 0.01 mm.
    const double matchMmX = 1.5 / axes.resolutionX + 0.005, matchMmY = 1.5 / axes.resolutionY + 0.005;
    const std::vector<LibinputTouch> seen = libinputTouches(libinputOutput);
    std::map<int, bool> slotDown;
    std::size_t next = 0, libinputDowns = 0, libinputUps = 0, motions = 0;
    double worstSeenMm = 0.0;
    for (size_t i = 0; i < seen.size(); ++i) {
        const LibinputTouch& touch = seen[i];
        SCOPED_TRACE("libinput event " + std::to_string(i) + " " + touch.type + " slot " +
                     std::to_string(touch.slot));
        if (touch.type == "TOUCH_UP" || touch.type == "TOUCH_CANCEL") {
            EXPECT_TRUE(slotDown[touch.slot]) << "the slot was not down";
            slotDown[touch.slot] = false;
            libinputUps += touch.type == "TOUCH_UP";
            continue;
        }
        const bool down = touch.type == "TOUCH_DOWN";
        EXPECT_EQ(slotDown[touch.slot], !down);
        slotDown[touch.slot] = true;
        libinputDowns += down;
        motions += !down;
        std::size_t match = next;
        while (match < logged.size() &&
               (logged[match].begins != down || std::abs(logged[match].deviceMm.x - touch.mm.x) > matchMmX ||
                std::abs(logged[match].deviceMm.y - touch.mm.y) > matchMmY))
            ++match;
        ASSERT_LT(match, logged.size())
            << "no " << (down ? "touch-down" : "touching frame") << " of the daemon's log, from frame "
            << (next < logged.size() ? logged[next].index : 0) << " on, is at (" << touch.mm.x << ", "
            << touch.mm.y << ") mm";
        next = match;
        const double error = truthDistanceMm(recording, logged[match].index, touch.mm);
        worstSeenMm = std::max(worstSeenMm, error);
        EXPECT_LE(error, kTruthToleranceMm) << "frame " << logged[match].index;
    }
    EXPECT_EQ(libinputDowns, downs) << libinputOutput;
    EXPECT_EQ(libinputUps, libinputDowns) << libinputOutput;
    for (const auto& [slot, isDown] : slotDown)
        EXPECT_FALSE(isDown) << "slot " << slot << " left down";

    // No move is lost or merged with the next: every logged frame in which the finger moved by more than the
    // log's rounding shows as a motion of its own, and none shows where the log has no touch.
    std::size_t moved = 0, touchingFrames = 0;
    std::map<std::uint32_t, cv::Point2i> lastUnits;
    for (const LoggedTouch& touch : logged) {
        if (!touch.begins) {
            ++touchingFrames;
            const cv::Point2i step = touch.units - lastUnits[touch.id];
            moved += std::abs(step.x) >= 2 || std::abs(step.y) >= 2;
        }
        lastUnits[touch.id] = touch.units;
    }
    std::cout << "libinput: " << libinputDowns << " down, " << motions << " motion, " << libinputUps
              << " up; the touch log: " << downs << " down, " << touchingFrames
              << " frames touching after it, " << moved
              << " of them moving; farthest from the true contact point: libinput " << worstSeenMm
              << " mm, the touch log " << worstLoggedMm << " mm\n";
    EXPECT_GE(motions, moved);
    EXPECT_LE(motions, touchingFrames);
    EXPECT_GT(moved, 10u) << "the finger hardly moved while touching";
}

// What libinput saw of a touchscreen: how many touches went down, and the slots still down at the end.
struct LibinputBalance {
    std::size_t downs = 0;
    std::set<int> leftDown;
};

LibinputBalance libinputBalance(const std::string& output) {
    LibinputBalance balance;
    for (const LibinputTouch& touch : libinputTouches(output)) {
        if (touch.type == "TOUCH_DOWN") {
            ++balance.downs;
            balance.leftDown.insert(touch.slot);
        } else if (touch.type == "TOUCH_UP" || touch.type == "TOUCH_CANCEL") {
            balance.leftDown.erase(touch.slot);
        }
    }
    return balance;
}

// How the daemon is interrupted while a finger touches.
enum class Interruption { Terminate, Kill, ReloadABrokenFile };

// everytouchd replays the drag onto its touchscreen; once its log shows the finger touching it is
// interrupted. Whatever the interruption, no touch stays down as libinput sees it. Returns libinput's output.
std::string interruptMidTouch(Interruption interruption, const test::TempDir& dir, const std::string& name) {
    const char* recordingPath = std::getenv("EVERYTOUCH_TEST_RECORDING");
    const char* daemonPath = std::getenv("EVERYTOUCHD");
    const std::filesystem::path config = dir / (name + ".conf");
    std::ofstream(config) << "[Touch]\nHeightMm=3\n";
    const std::filesystem::path log = dir / (name + ".jsonl");
    const std::set<std::filesystem::path> before = eventNodes();
    test::BackgroundProcess daemon(
        {daemonPath ? daemonPath : EVERYTOUCHD_PATH, "--config", config.string(), "--rig",
         std::string("replay:") + recordingPath, "--fast", "--output", "uinput", "--log", log.string()},
        dir / (name + ".log"));
    std::filesystem::path devnode;
    const bool appeared = waitFor([&] {
        for (const std::filesystem::path& node : eventNodes())
            if (!before.contains(node))
                devnode = node;
        return !devnode.empty() || !daemon.running();
    });
    daemon.signal(SIGSTOP);
    EXPECT_TRUE(appeared && !devnode.empty()) << "no touchscreen appeared\n" << daemon.output();
    if (devnode.empty())
        return {};
    udevProperties(devnode);
    test::BackgroundProcess libinput({"libinput", "debug-events", "--device", devnode.string()},
                                     dir / (name + ".libinput"));
    EXPECT_TRUE(attached(libinput, devnode)) << "libinput debug-events never opened " << devnode;
    daemon.signal(SIGCONT);
    // Interrupted once the touch has reached libinput.
    const bool touching = waitFor([&] {
        return test::fileContents(dir / (name + ".libinput")).find("TOUCH_DOWN") != std::string::npos ||
               !daemon.running();
    });
    daemon.signal(SIGSTOP);
    EXPECT_TRUE(touching && daemon.running()) << "libinput saw no touch\n" << daemon.output();

    switch (interruption) {
        case Interruption::Terminate:
            daemon.signal(SIGTERM);
            daemon.signal(SIGCONT);
            EXPECT_EQ(daemon.wait(kPatience), 0) << daemon.output();
            break;
        case Interruption::Kill:
            daemon.signal(SIGKILL);
            EXPECT_EQ(daemon.wait(kPatience), 128 + SIGKILL);
            break;
        case Interruption::ReloadABrokenFile: {
            const std::size_t logged = test::fileContents(log).size();
            std::ofstream(config, std::ios::trunc) << "[Touch]\nHeightMm=banana\n";
            daemon.signal(SIGHUP);
            daemon.signal(SIGCONT);
            EXPECT_TRUE(daemon.waitForOutput("the running configuration stays in effect", kPatience))
                << daemon.output();
            // Detection goes on through the rejected reload: the finger is followed until it lifts.
            EXPECT_TRUE(
                waitFor([&] { return logsALift(test::fileContents(log)) || !daemon.running(); }, 300s));
            EXPECT_GT(test::fileContents(log).size(), logged) << "nothing was detected after the reload";
            daemon.signal(SIGTERM);
            EXPECT_EQ(daemon.wait(kPatience), 0) << daemon.output();
            break;
        }
    }
    EXPECT_TRUE(waitFor([&] { return !std::filesystem::exists(devnode); })) << devnode << " stayed";
    std::this_thread::sleep_for(300ms);
    libinput.signal(SIGINT);
    libinput.wait(kPatience);
    return test::fileContents(dir / (name + ".libinput"));
}

TEST(Everytouchd, NoTouchStaysDownWhenTheDaemonIsStoppedKilledOrReloadedMidTouch) {
    SKIP_WITHOUT_UINPUT();
    if (!std::getenv("EVERYTOUCH_TEST_RECORDING"))
        GTEST_SKIP() << "EVERYTOUCH_TEST_RECORDING names no recording with a touch (tests/vm sets it)";
    test::TempDir dir;
    // The kill first: the daemons after it start again as systemd would start them, and must begin with a
    // touchscreen of their own and nothing down.
    for (const auto& [interruption, name] :
         {std::pair{Interruption::Kill, "kill"}, std::pair{Interruption::Terminate, "terminate"},
          std::pair{Interruption::ReloadABrokenFile, "reload"}}) {
        SCOPED_TRACE(name);
        const std::string seen = interruptMidTouch(interruption, dir, name);
        const LibinputBalance balance = libinputBalance(seen);
        EXPECT_GE(balance.downs, 1u) << seen;
        EXPECT_TRUE(balance.leftDown.empty()) << "slots left down: " << balance.leftDown.size() << "\n"
                                              << seen;
        std::cout << name << ": libinput saw " << balance.downs << " touch-downs, "
                  << (seen.find("TOUCH_CANCEL") != std::string::npos ? "cancelled" : "lifted") << "\n";
    }
}

}  // namespace
}  // namespace everytouch

#include "io/v4l2_source.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "io/input_error.h"

namespace everytouch::io {

namespace {

constexpr unsigned kStreamBuffers = 4;
// A jump of the sequence larger than this is the driver starting over, not frames lost.
constexpr std::uint32_t kMostMissed = 1000;
// A granted frame rate this far from the asked one is refused rather than run at silently.
constexpr double kFrameRateTolerance = 0.01;

// ioctl, repeated when a signal interrupts it: 0, or -errno.
int control(int fd, unsigned long request, void* argument) {
    int r;
    do
        r = ::ioctl(fd, request, argument);
    while (r < 0 && errno == EINTR);
    return r < 0 ? -errno : 0;
}

std::string errorText(int negativeErrno) {
    return std::strerror(-negativeErrno);
}

std::string formatRate(double framesPerSecond) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", framesPerSecond);
    return text;
}

std::string joinedFourCcs(const std::vector<std::uint32_t>& fourCcs) {
    std::string text;
    for (std::uint32_t fourCc : fourCcs)
        text += (text.empty() ? "" : ", ") + fourCcName(fourCc);
    return text.empty() ? "none" : text;
}

// Sets a control the camera has; false when it has none of that id, throws InputError when it refuses.
bool setControl(int fd, std::uint32_t id, std::int32_t value, const std::string& input,
                const std::string& field) {
    v4l2_queryctrl query{};
    query.id = id;
    if (control(fd, VIDIOC_QUERYCTRL, &query) < 0 || (query.flags & V4L2_CTRL_FLAG_DISABLED))
        return false;
    v4l2_control setting{};
    setting.id = id;
    setting.value = value;
    if (const int r = control(fd, VIDIOC_S_CTRL, &setting); r < 0)
        throw InputError(input, field,
                         std::string("the camera refused ") + reinterpret_cast<const char*>(query.name) +
                             " = " + std::to_string(value) + ": " + errorText(r));
    return true;
}

double grantedFrameRate(int fd) {
    v4l2_streamparm parameters{};
    parameters.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (control(fd, VIDIOC_G_PARM, &parameters) < 0)
        return 0.0;
    const v4l2_fract& period = parameters.parm.capture.timeperframe;
    return period.numerator > 0 && period.denominator > 0 ? double(period.denominator) / period.numerator
                                                          : 0.0;
}

std::int64_t monotonicNowUs() {
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);
    return static_cast<std::int64_t>(now.tv_sec) * 1'000'000 + now.tv_nsec / 1000;
}

}  // namespace

V4l2Source::V4l2Source(const std::string& input, const std::string& device, const CameraSettings& settings)
    : input_(input), device_(device), settings_(settings) {
    connect();
}

void V4l2Source::connect() {
    const std::string& input = input_;
    UniqueFd fd(::open(device_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
    if (!fd) {
        const int error = errno;
        throw std::runtime_error(input + ": cannot open " + device_ + ": " + std::strerror(error) +
                                 (error == EACCES ? " (everytouchd needs to be in the video group)"
                                                  : " (v4l2-ctl --list-devices lists the cameras)"));
    }

    v4l2_capability capability{};
    if (control(fd.get(), VIDIOC_QUERYCAP, &capability) < 0)
        throw InputError(input, "", device_ + " is no V4L2 device");
    const std::uint32_t caps =
        capability.capabilities & V4L2_CAP_DEVICE_CAPS ? capability.device_caps : capability.capabilities;
    const std::string card = reinterpret_cast<const char*>(capability.card);
    const std::string driver = reinterpret_cast<const char*>(capability.driver);
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
        throw InputError(
            input, "",
            device_ + " (" + card + ") captures no video; v4l2-ctl --list-devices lists the cameras");
    if (!(caps & V4L2_CAP_STREAMING))
        throw InputError(input, "", device_ + " (" + card + ") does not stream into memory-mapped buffers");

    std::vector<std::uint32_t> offered;
    v4l2_fmtdesc description{};
    description.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    for (; control(fd.get(), VIDIOC_ENUM_FMT, &description) == 0; ++description.index)
        offered.push_back(description.pixelformat);
    const std::optional<V4l2Pixels> pixels = preferredV4l2Pixels(offered, settings_.pixels);
    if (!pixels) {
        if (settings_.pixels)
            throw InputError(input, "[Camera] PixelFormat",
                             std::string(cameraPixelsName(*settings_.pixels)) +
                                 (*settings_.pixels == CameraPixels::Mono8
                                      ? " (GREY) is not offered"
                                      : " has no V4L2 format everytouchd reads (Mono8 asks for GREY)") +
                                 "; the camera offers " + joinedFourCcs(offered));
        throw InputError(input, "",
                         "the camera offers no pixel format everytouchd reads (it offers " +
                             joinedFourCcs(offered) + "; everytouchd reads YUYV, GREY and MJPG)");
    }
    if (settings_.gainDb)
        throw InputError(input, "[Camera] GainDb",
                         "a V4L2 camera's gain has units of its own, not decibels: leave GainDb= unset");
    if (settings_.trigger && *settings_.trigger != "off")
        throw InputError(input, "[Camera] Trigger",
                         "V4L2 has no trigger input: a V4L2 camera runs free (off)");

    v4l2_format format{};
    format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (const int r = control(fd.get(), VIDIOC_G_FMT, &format); r < 0)
        throw std::runtime_error(input + ": the camera does not tell its format: " + errorText(r));
    if (settings_.region) {
        format.fmt.pix.width = static_cast<std::uint32_t>(settings_.region->width);
        format.fmt.pix.height = static_cast<std::uint32_t>(settings_.region->height);
    }
    format.fmt.pix.pixelformat = v4l2FourCc(*pixels);
    format.fmt.pix.field = V4L2_FIELD_NONE;
    format.fmt.pix.bytesperline = 0;
    if (const int r = control(fd.get(), VIDIOC_S_FMT, &format); r < 0)
        throw InputError(input, "",
                         "the camera refused " + fourCcName(v4l2FourCc(*pixels)) + ": " + errorText(r));
    if (format.fmt.pix.pixelformat != v4l2FourCc(*pixels))
        throw InputError(input, "",
                         "the camera gives " + fourCcName(format.fmt.pix.pixelformat) + " when asked for " +
                             fourCcName(v4l2FourCc(*pixels)));
    const cv::Size size(static_cast<int>(format.fmt.pix.width), static_cast<int>(format.fmt.pix.height));
    if (settings_.region && size != settings_.region->size())
        throw InputError(
            input, "[Camera] Region",
            "the camera gives " + std::to_string(size.width) + "x" + std::to_string(size.height) + ", not " +
                std::to_string(settings_.region->width) + "x" + std::to_string(settings_.region->height));
    if (settings_.region && (settings_.region->x != 0 || settings_.region->y != 0)) {
        v4l2_selection crop{};
        crop.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        crop.target = V4L2_SEL_TGT_CROP;
        crop.r = {settings_.region->x, settings_.region->y, static_cast<std::uint32_t>(size.width),
                  static_cast<std::uint32_t>(size.height)};
        if (const int r = control(fd.get(), VIDIOC_S_SELECTION, &crop); r < 0)
            throw InputError(
                input, "[Camera] Region",
                "the camera does not crop its sensor (" + errorText(r) + "): give the offset +0+0");
    }
    if (format.fmt.pix.field != V4L2_FIELD_NONE && format.fmt.pix.field != V4L2_FIELD_ANY)
        throw InputError(input, "",
                         "the camera gives interlaced frames; everytouchd reads whole frames only");

    if (settings_.frameRate) {
        v4l2_streamparm parameters{};
        parameters.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (control(fd.get(), VIDIOC_G_PARM, &parameters) < 0 ||
            !(parameters.parm.capture.capability & V4L2_CAP_TIMEPERFRAME))
            throw InputError(input, "[Camera] FrameRate", "the camera does not take a frame rate");
        parameters.parm.capture.timeperframe = {
            1000, static_cast<std::uint32_t>(std::lround(*settings_.frameRate * 1000))};
        if (const int r = control(fd.get(), VIDIOC_S_PARM, &parameters); r < 0)
            throw InputError(input, "[Camera] FrameRate", "the camera refused it: " + errorText(r));
        const double granted = grantedFrameRate(fd.get());
        if (std::abs(granted - *settings_.frameRate) > kFrameRateTolerance * *settings_.frameRate)
            throw InputError(input, "[Camera] FrameRate",
                             "the camera gives " + formatRate(granted) + " frames/s in " +
                                 std::to_string(size.width) + "x" + std::to_string(size.height) + " " +
                                 fourCcName(v4l2FourCc(*pixels)) + ", not " +
                                 formatRate(*settings_.frameRate));
    }
    if (settings_.exposureUs) {
        setControl(fd.get(), V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, input, "[Camera] ExposureUs");
        // V4L2 counts exposure in units of 100 us.
        const auto units = static_cast<std::int32_t>(std::lround(*settings_.exposureUs / 100.0));
        if (!setControl(fd.get(), V4L2_CID_EXPOSURE_ABSOLUTE, std::max(1, units), input,
                        "[Camera] ExposureUs"))
            throw InputError(input, "[Camera] ExposureUs", "the camera has no exposure time control");
    }

    v4l2_requestbuffers request{};
    request.count = kStreamBuffers;
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    if (const int r = control(fd.get(), VIDIOC_REQBUFS, &request); r < 0 || request.count < 2)
        throw std::runtime_error(input + ": the camera gives no streaming buffers" +
                                 (r < 0 ? ": " + errorText(r) : std::string()));
    std::vector<MemoryMapping> buffers;
    for (std::uint32_t i = 0; i < request.count; ++i) {
        v4l2_buffer buffer{};
        buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buffer.memory = V4L2_MEMORY_MMAP;
        buffer.index = i;
        if (const int r = control(fd.get(), VIDIOC_QUERYBUF, &buffer); r < 0)
            throw std::runtime_error(input + ": the camera's buffer " + std::to_string(i) + ": " +
                                     errorText(r));
        void* start =
            ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd.get(), buffer.m.offset);
        if (start == MAP_FAILED)
            throw std::runtime_error(input + ": cannot map the camera's buffer: " + std::strerror(errno));
        buffers.emplace_back(start, buffer.length);
        if (const int r = control(fd.get(), VIDIOC_QBUF, &buffer); r < 0)
            throw std::runtime_error(input + ": the camera does not take its buffer: " + errorText(r));
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (const int r = control(fd.get(), VIDIOC_STREAMON, &type); r < 0)
        throw std::runtime_error(input + ": the camera does not start: " + errorText(r));

    pixels_ = *pixels;
    size_ = size;
    bytesPerLine_ = format.fmt.pix.bytesperline;
    frameRate_ = grantedFrameRate(fd.get());
    fd_ = std::move(fd);
    buffers_ = std::move(buffers);
    lastSequence_.reset();
    description_ = "V4L2 camera " + card + " (" + driver + ", " + device_ + "), " +
                   std::to_string(size.width) + "x" + std::to_string(size.height) + " " +
                   fourCcName(v4l2FourCc(pixels_)) +
                   (frameRate_ > 0.0 ? " at " + formatRate(frameRate_) + " frames/s" : std::string());
}

void V4l2Source::release() {
    buffers_.clear();
    fd_.reset();
    lastSequence_.reset();
}

void V4l2Source::lose(const std::string& problem) {
    release();
    throw SourceLost(problem);
}

double V4l2Source::stallTimeoutSeconds() const {
    return cameraStallSeconds(frameRate_);
}

std::optional<core::Frame> V4l2Source::read(cv::Mat spare) {
    if (!fd_) {
        try {
            connect();
        } catch (const std::runtime_error& error) {
            release();
            throw SourceLost(error.what());
        }
    }
    using Clock = std::chrono::steady_clock;
    const Clock::time_point giveUp = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                        std::chrono::duration<double>(stallTimeoutSeconds()));
    for (Clock::time_point now = Clock::now(); now < giveUp; now = Clock::now()) {
        // A short wait at a time, never beyond the deadline, so that a stalled camera is noticed on time.
        const auto waitMs = std::chrono::ceil<std::chrono::milliseconds>(giveUp - now).count();
        pollfd ready{fd_.get(), POLLIN, 0};
        const int polled = ::poll(&ready, 1, static_cast<int>(std::clamp<std::int64_t>(waitMs, 1, 100)));
        if (polled < 0 && errno != EINTR)
            lose(description_ + ": " + std::strerror(errno));
        if (polled <= 0)
            continue;
        if (!(ready.revents & POLLIN) && (ready.revents & (POLLERR | POLLHUP | POLLNVAL)))
            lose(description_ + ": the camera went away");
        v4l2_buffer buffer{};
        buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buffer.memory = V4L2_MEMORY_MMAP;
        if (const int r = control(fd_.get(), VIDIOC_DQBUF, &buffer); r == -EAGAIN)
            continue;
        else if (r < 0)
            lose(description_ + ": " + errorText(r));
        if (buffer.index >= buffers_.size())
            lose(description_ + ": the driver returned a buffer it never gave");

        core::Frame frame;
        frame.image = spare;
        const MemoryMapping& mapping = buffers_[buffer.index];
        const bool complete =
            !(buffer.flags & V4L2_BUF_FLAG_ERROR) && buffer.bytesused <= mapping.length() &&
            convertV4l2Pixels(mapping.data(), buffer.bytesused, size_, bytesPerLine_, pixels_, frame.image);
        if (const int r = control(fd_.get(), VIDIOC_QBUF, &buffer); r < 0)
            lose(description_ + ": the camera does not take its buffer back: " + errorText(r));
        // Frames lost on the way keep their places in the indices, so that the polarity stays with the count.
        const std::uint32_t step = lastSequence_ ? buffer.sequence - *lastSequence_ : 1;
        const std::uint64_t missed = (step >= 1 && step <= kMostMissed ? step - 1 : 0) + (complete ? 0 : 1);
        dropped_ += missed;
        nextIndex_ += missed;
        lastSequence_ = buffer.sequence;
        if (!complete)
            continue;
        const bool monotonic =
            (buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC &&
            (buffer.timestamp.tv_sec != 0 || buffer.timestamp.tv_usec != 0);
        frame.timestampUs = monotonic ? static_cast<std::int64_t>(buffer.timestamp.tv_sec) * 1'000'000 +
                                            buffer.timestamp.tv_usec
                                      : monotonicNowUs();
        frame.index = nextIndex_++;
        frame.polarity = frame.index % 2 == 0 ? core::Polarity::Positive : core::Polarity::Negative;
        return frame;
    }
    char waited[32];
    std::snprintf(waited, sizeof waited, "%.1f", stallTimeoutSeconds());
    lose(description_ + ": no complete frame for " + waited + " s");
}

}  // namespace everytouch::io

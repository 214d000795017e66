#include "io/aravis_source.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "io/input_error.h"
#include "io/thread_name.h"

namespace everytouch::io {

namespace {

constexpr int kStreamBuffers = 8;
// The camera's frame counter: GigE Vision's wraps after 65535 and skips 0.
constexpr std::uint64_t kGvFrameIdLimit = 0xFFFF;
// A triggered camera waits for its trigger: a projector that pauses is no lost camera yet.
constexpr double kTriggeredStallSeconds = 2.0;
// A jump of the counter larger than this is the camera starting over, not frames lost.
constexpr std::uint64_t kMostMissed = 1000;

std::string messageOf(const GErrorHandle& error) {
    return error && error->message ? error->message : "unknown error";
}

// Runs one Aravis call that reports its failure through a GError; throws InputError naming `field` when it
// fails.
template <typename Call>
void require(const std::string& input, const std::string& field, const std::string& what, Call call) {
    GError* raw = nullptr;
    call(&raw);
    const GErrorHandle error(raw);
    if (error)
        throw InputError(input, field, what + ": " + messageOf(error));
}

// What one of Aravis's arv_camera_dup_available_* functions lists: the array is ours, its strings the
// camera's.
using AvailableNames = const char** (*)(ArvCamera*, guint*, GError**);

std::vector<std::string> available(ArvCamera* camera, AvailableNames list) {
    std::vector<std::string> names;
    guint count = 0;
    GError* error = nullptr;
    const char** array = list(camera, &count, &error);
    GErrorHandle owned(error);
    for (guint i = 0; array && i < count; ++i)
        names.emplace_back(array[i]);
    g_free(array);
    return names;
}

std::string joined(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names)
        text += (text.empty() ? "" : ", ") + name;
    return text.empty() ? "none" : text;
}

}  // namespace

std::uint64_t framesMissedBetween(std::uint64_t last, std::uint64_t next) {
    std::uint64_t step = 0;
    if (last <= kGvFrameIdLimit && next <= kGvFrameIdLimit)
        step = (next + kGvFrameIdLimit - last % kGvFrameIdLimit) % kGvFrameIdLimit;
    else if (next > last)
        step = next - last;
    return step >= 1 && step <= kMostMissed ? step - 1 : 0;
}

AravisSource::AravisSource(const std::string& input, const std::string& id, const CameraSettings& settings)
    : input_(input), id_(id), settings_(settings) {
    connect();
}

void AravisSource::connect() {
    const std::string& input = input_;
    const std::string& id = id_;
    const CameraSettings& settings = settings_;
    GError* raw = nullptr;
    if (id.empty()) {
        arv_update_device_list();
        if (arv_get_n_devices() == 0)
            throw std::runtime_error(
                input + ": no GenICam camera found (arv-tool-0.8 lists the cameras Aravis sees)");
    }
    camera_.reset(arv_camera_new(id.empty() ? nullptr : id.c_str(), &raw));
    GErrorHandle error(raw);
    if (!camera_)
        throw std::runtime_error(input + ": no camera answers" +
                                 (id.empty() ? std::string() : " as \"" + id + "\"") + ": " +
                                 messageOf(error) + " (arv-tool-0.8 lists the cameras Aravis sees)");

    ArvCamera* camera = camera_.get();
    const std::vector<std::string> offered =
        available(camera, arv_camera_dup_available_pixel_formats_as_strings);
    const std::optional<CameraPixels> pixels =
        settings.pixels ? settings.pixels : preferredCameraPixels(offered);
    if (!pixels)
        throw InputError(input, "",
                         "the camera offers no pixel format everytouchd reads (it offers " + joined(offered) +
                             "; everytouchd reads " + cameraPixelsNames() + ")");
    if (std::find(offered.begin(), offered.end(), cameraPixelsName(*pixels)) == offered.end())
        throw InputError(
            input, "[Camera] PixelFormat",
            std::string(cameraPixelsName(*pixels)) + " is not offered; the camera offers " + joined(offered));
    pixels_ = *pixels;
    const std::string pixelsName(cameraPixelsName(pixels_));
    require(input, "[Camera] PixelFormat", "the camera refused it", [&](GError** error) {
        arv_camera_set_pixel_format_from_string(camera, pixelsName.c_str(), error);
    });

    if (const std::optional<cv::Rect>& region = settings.region)
        require(input, "[Camera] Region", "the camera refused it", [&](GError** error) {
            arv_camera_set_region(camera, region->x, region->y, region->width, region->height, error);
        });
    if (settings.frameRate)
        require(input, "[Camera] FrameRate", "the camera refused it",
                [&](GError** error) { arv_camera_set_frame_rate(camera, *settings.frameRate, error); });
    if (settings.exposureUs)
        require(input, "[Camera] ExposureUs", "the camera refused it",
                [&](GError** error) { arv_camera_set_exposure_time(camera, *settings.exposureUs, error); });
    if (settings.gainDb)
        require(input, "[Camera] GainDb", "the camera refused it",
                [&](GError** error) { arv_camera_set_gain(camera, *settings.gainDb, error); });
    // Last: setting the frame rate turns the frame trigger off on some cameras (Aravis does so for them).
    if (settings.trigger == "off") {
        require(input, "[Camera] Trigger", "the camera cannot run free",
                [&](GError** error) { arv_camera_clear_triggers(camera, error); });
    } else if (settings.trigger) {
        const std::vector<std::string> sources = available(camera, arv_camera_dup_available_trigger_sources);
        if (std::find(sources.begin(), sources.end(), *settings.trigger) == sources.end())
            throw InputError(
                input, "[Camera] Trigger",
                "the camera has no trigger source " + *settings.trigger + "; it offers " + joined(sources));
        require(input, "[Camera] Trigger", "the camera refused it",
                [&](GError** error) { arv_camera_set_trigger(camera, settings.trigger->c_str(), error); });
        trigger_ = *settings.trigger;
    }
    require(input, "", "the camera cannot run continuously", [&](GError** error) {
        arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, error);
    });
    if (arv_camera_is_gv_device(camera)) {
        // The largest packet the link carries: fewer packets a frame, fewer lost. A link that takes none
        // larger keeps the default.
        arv_camera_gv_auto_packet_size(camera, &raw);
        error.reset(raw);
    }

    gint x = 0, y = 0, width = 0, height = 0;
    require(input, "", "the camera does not tell its image size",
            [&](GError** error) { arv_camera_get_region(camera, &x, &y, &width, &height, error); });
    frameRate_ = arv_camera_get_frame_rate(camera, &raw);
    error.reset(raw);
    if (error || !(frameRate_ > 0.0))
        frameRate_ = 0.0;
    std::size_t payload = 0;
    require(input, "", "the camera does not tell its frame size",
            [&](GError** error) { payload = arv_camera_get_payload(camera, error); });
    if (payload < cameraPixelsBytes(cv::Size(width, height), pixels_))
        throw InputError(input, "",
                         "the camera's frames (" + std::to_string(payload) + " bytes) are smaller than " +
                             std::to_string(width) + "x" + std::to_string(height) + " " +
                             std::string(cameraPixelsName(pixels_)));

    stream_.reset(arv_camera_create_stream(camera, nullptr, nullptr, &raw));
    error.reset(raw);
    if (!stream_)
        throw std::runtime_error(input + ": no stream from the camera: " + messageOf(error));
    for (int i = 0; i < kStreamBuffers; ++i)
        arv_stream_push_buffer(stream_.get(), arv_buffer_new_allocate(payload));
    arv_camera_start_acquisition(camera, &raw);
    error.reset(raw);
    if (error)
        throw std::runtime_error(input + ": the camera does not start: " + messageOf(error));

    const char* vendor = arv_camera_get_vendor_name(camera, nullptr);
    const char* model = arv_camera_get_model_name(camera, nullptr);
    const char* serial = arv_camera_get_device_serial_number(camera, nullptr);
    char rate[32];
    std::snprintf(rate, sizeof rate, "%.4g", frameRate_);
    description_ =
        std::string("camera ") + (vendor ? vendor : "?") + " " + (model ? model : "?") + " (serial " +
        (serial ? serial : "?") + "), " + std::to_string(width) + "x" + std::to_string(height) + " " +
        pixelsName +
        (trigger_.empty() ? " at " + std::string(rate) + " frames/s" : ", triggered by " + trigger_);
}

AravisSource::~AravisSource() {
    if (camera_)
        arv_camera_stop_acquisition(camera_.get(), nullptr);
    if (releaser_.joinable())
        releaser_.join();
}

void AravisSource::releaseLostCamera() {
    if (releaser_.joinable())
        releaser_.join();
    // Aravis waits for its protocol's timeouts while it lets go of a camera that no longer answers (some
    // 10 s for a GigE camera): on a thread of their own, so that the camera can be tried again meanwhile.
    releaser_ = std::thread([camera = std::move(camera_), stream = std::move(stream_)]() mutable {
        nameThisThread("et-cam-release");
        stream.reset();
        camera.reset();
    });
    lastFrameId_.reset();
}

double AravisSource::stallTimeoutSeconds() const {
    if (!trigger_.empty())
        return kTriggeredStallSeconds;
    return cameraStallSeconds(frameRate_);
}

std::optional<core::Frame> AravisSource::read(cv::Mat spare) {
    if (!stream_) {
        try {
            connect();
        } catch (const std::runtime_error& error) {
            camera_.reset();
            stream_.reset();
            throw SourceLost(error.what());
        }
    }
    using Clock = std::chrono::steady_clock;
    const Clock::time_point giveUp = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                        std::chrono::duration<double>(stallTimeoutSeconds()));
    for (Clock::time_point now = Clock::now(); now < giveUp; now = Clock::now()) {
        // A short wait at a time, never beyond the deadline, so that a stalled camera is noticed on time.
        const auto waitUs = std::chrono::duration_cast<std::chrono::microseconds>(giveUp - now).count();
        ArvBuffer* buffer = arv_stream_timeout_pop_buffer(
            stream_.get(), static_cast<guint64>(std::clamp<std::int64_t>(waitUs, 1, 100'000)));
        if (!buffer)
            continue;
        const std::uint64_t frameId = arv_buffer_get_frame_id(buffer);
        // An incomplete buffer may not describe an image at all: its geometry is asked only of a whole one.
        const bool received = arv_buffer_get_status(buffer) == ARV_BUFFER_STATUS_SUCCESS &&
                              arv_buffer_get_n_parts(buffer) > 0 &&
                              arv_buffer_get_part_data_type(buffer, 0) == ARV_BUFFER_PART_DATA_TYPE_2D_IMAGE;
        std::size_t bytes = 0;
        const void* data = received ? arv_buffer_get_image_data(buffer, &bytes) : nullptr;
        const cv::Size size =
            received ? cv::Size(arv_buffer_get_image_width(buffer), arv_buffer_get_image_height(buffer))
                     : cv::Size();
        const bool complete =
            data != nullptr && size.width > 0 && size.height > 0 && bytes >= cameraPixelsBytes(size, pixels_);
        // Frames lost on the way keep their places in the indices, so that the polarity stays with the count.
        const std::uint64_t missed =
            (lastFrameId_ ? framesMissedBetween(*lastFrameId_, frameId) : 0) + (complete ? 0 : 1);
        dropped_ += missed;
        nextIndex_ += missed;
        lastFrameId_ = frameId;
        if (!complete) {
            arv_stream_push_buffer(stream_.get(), buffer);
            continue;
        }

        core::Frame frame;
        frame.image = spare;
        convertCameraPixels(static_cast<const std::uint8_t*>(data), size, pixels_, frame.image);
        const guint64 cameraNs = arv_buffer_get_timestamp(buffer);
        const guint64 hostNs = arv_buffer_get_system_timestamp(buffer);
        arv_stream_push_buffer(stream_.get(), buffer);
        frame.timestampUs = static_cast<std::int64_t>((cameraNs != 0 ? cameraNs : hostNs) / 1000);
        frame.index = nextIndex_++;
        frame.polarity = frame.index % 2 == 0 ? core::Polarity::Positive : core::Polarity::Negative;
        return frame;
    }
    char waited[32];
    std::snprintf(waited, sizeof waited, "%.1f", stallTimeoutSeconds());
    const std::string problem =
        description_ + ": no complete frame for " + waited + " s" +
        (trigger_.empty() ? std::string() : " (is the trigger on " + trigger_ + " running?)");
    releaseLostCamera();
    throw SourceLost(problem);
}

}  // namespace everytouch::io

#include "io/wayland_overlay_projector.h"

#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "io/input_error.h"
#include "io/log.h"
#include "io/overlay_buffers.h"
#include "io/projector_image.h"
#include "io/wayland_handles.h"

namespace everytouch::io {

namespace {

constexpr const char* kDisplayKey = "[Projector] Display=";
// How long the overlay's thread waits for the compositor before it looks whether it should stop.
constexpr int kPollMs = 100;
// How often the overlay tries to reach a compositor that went away.
constexpr std::chrono::seconds kReconnectInterval(1);
// What an output that states no refresh rate is taken to refresh at.
constexpr double kAssumedRefreshHz = 60.0;

std::string environment(const char* name) {
    const char* value = std::getenv(name);
    return value ? value : "";
}

}  // namespace

// An output as the compositor describes it. (Outside the unnamed namespace: the connection holds them.)
struct CompositorOutput {
    WaylandOutput output;
    std::string name;  // version 4 of wl_output; empty before
    cv::Size modeSize;
    double refreshHz = 0.0;
    int scale = 1;
};

namespace {

std::string describeOutput(const std::vector<std::unique_ptr<CompositorOutput>>& outputs, std::size_t index) {
    const CompositorOutput& output = *outputs[index];
    return std::to_string(index) + " \"" + output.name + "\" (" + std::to_string(output.modeSize.width) +
           "x" + std::to_string(output.modeSize.height) + ")";
}

const wl_output_listener kOutputListener = {
    .geometry = [](void*, wl_output*, int32_t, int32_t, int32_t, int32_t, int32_t, const char*, const char*,
                   int32_t) {},
    .mode =
        [](void* data, wl_output*, uint32_t flags, int32_t width, int32_t height, int32_t refreshMilliHz) {
            if (!(flags & WL_OUTPUT_MODE_CURRENT))
                return;
            auto* output = static_cast<CompositorOutput*>(data);
            output->modeSize = cv::Size(width, height);
            output->refreshHz = refreshMilliHz / 1000.0;
        },
    .done = [](void*, wl_output*) {},
    .scale = [](void* data, wl_output*,
                int32_t factor) { static_cast<CompositorOutput*>(data)->scale = factor; },
    .name = [](void* data, wl_output*,
               const char* name) { static_cast<CompositorOutput*>(data)->name = name; },
    .description = [](void*, wl_output*, const char*) {},
};

}  // namespace

// The overlay's Wayland objects, made and used on the overlay's thread only.
class WaylandOverlayProjector::Connection {
public:
    explicit Connection(const std::string& display) {
        compositorName_ = environment("WAYLAND_DISPLAY");
        display_.reset(wl_display_connect(nullptr));
        if (!display_)
            throw std::runtime_error(
                "the code overlay cannot connect to the Wayland compositor at "
                "WAYLAND_DISPLAY=" +
                compositorName_ + " (in XDG_RUNTIME_DIR=" + environment("XDG_RUNTIME_DIR") +
                "): " + std::strerror(errno));
        registry_.reset(wl_display_get_registry(display_.get()));
        wl_registry_add_listener(registry_.get(), &kRegistryListener, this);
        // The globals, then each output's description.
        roundtrip();
        roundtrip();
        if (!compositor_ || !shm_)
            throw std::runtime_error("the Wayland compositor at WAYLAND_DISPLAY=" + compositorName_ +
                                     " offers no wl_compositor or wl_shm");
        if (!layerShell_)
            throw std::runtime_error(
                "the Wayland compositor at WAYLAND_DISPLAY=" + compositorName_ +
                " does not offer the layer-shell protocol (zwlr_layer_shell_v1), which the code overlay "
                "needs: sway, KDE Plasma and Hyprland offer it, GNOME does not; on GNOME use its X11 session "
                "or [Projector] Output=window");
        if (outputs_.empty())
            throw std::runtime_error("the Wayland compositor at WAYLAND_DISPLAY=" + compositorName_ +
                                     " has no output");
        const std::size_t index = findOutput(display);
        const CompositorOutput& output = *outputs_[index];
        refreshHz_ = output.refreshHz > 0.0 ? output.refreshHz : kAssumedRefreshHz;
        scale_ = std::max(output.scale, 1);

        surface_.reset(wl_compositor_create_surface(compositor_.get()));
        // An empty input region: every click and touch goes to what lies below.
        wl_region* nothing = wl_compositor_create_region(compositor_.get());
        wl_surface_set_input_region(surface_.get(), nothing);
        wl_region_destroy(nothing);
        wl_surface_set_buffer_scale(surface_.get(), scale_);
        layerSurface_.reset(zwlr_layer_shell_v1_get_layer_surface(
            layerShell_.get(), surface_.get(), output.output.get(), ZWLR_LAYER_SHELL_V1_LAYER_OVERLAY,
            "everytouch-code-overlay"));
        zwlr_layer_surface_v1_add_listener(layerSurface_.get(), &kLayerSurfaceListener, this);
        zwlr_layer_surface_v1_set_anchor(
            layerSurface_.get(), ZWLR_LAYER_SURFACE_V1_ANCHOR_TOP | ZWLR_LAYER_SURFACE_V1_ANCHOR_BOTTOM |
                                     ZWLR_LAYER_SURFACE_V1_ANCHOR_LEFT | ZWLR_LAYER_SURFACE_V1_ANCHOR_RIGHT);
        // Over the whole output, panels included, moving nothing aside.
        zwlr_layer_surface_v1_set_exclusive_zone(layerSurface_.get(), -1);
        zwlr_layer_surface_v1_set_keyboard_interactivity(layerSurface_.get(),
                                                         ZWLR_LAYER_SURFACE_V1_KEYBOARD_INTERACTIVITY_NONE);
        wl_surface_commit(surface_.get());
        while (!configured_ && !closed_)
            if (wl_display_dispatch(display_.get()) < 0)
                throw std::runtime_error(lost());
        if (closed_ || configuredSize_.empty())
            throw std::runtime_error("the Wayland compositor at WAYLAND_DISPLAY=" + compositorName_ +
                                     " refused the code overlay on output " +
                                     describeOutput(outputs_, index));
        size_ = configuredSize_ * scale_;
        description_ = "the overlay on the Wayland compositor " + compositorName_ + " output " +
                       describeOutput(outputs_, index) + ", on its overlay layer";
    }

    cv::Size size() const { return size_; }
    const std::string& description() const { return description_; }
    double refreshHz() const { return refreshHz_; }
    wl_display* display() const { return display_.get(); }
    bool closed() const { return closed_; }

    // Makes the two images (premultiplied BGRA, size()) the compositor's buffers for draw().
    void upload(const cv::Mat images[2]) { buffers_.replace(shmBuffer(images[0]), shmBuffer(images[1])); }

    // Shows image `polarity` from the next frame on and asks to be told when to draw the next one.
    void draw(int polarity) {
        wl_surface_attach(surface_.get(), buffers_.attach(polarity).get(), 0, 0);
        wl_surface_damage_buffer(surface_.get(), 0, 0, size_.width, size_.height);
        frame_.reset(wl_surface_frame(surface_.get()));
        wl_callback_add_listener(frame_.get(), &kFrameListener, this);
        wl_surface_commit(surface_.get());
        framePending_ = true;
    }

    bool framePending() const { return framePending_; }
    // The compositor's time of the last frame it asked for, ms; 0 before the first.
    std::uint32_t lastFrameMs() const { return lastFrameMs_; }
    // Whether a frame was asked for since the last call.
    bool takeFrameDone() {
        if (!frameDone_)
            return false;
        frameDone_ = false;
        buffers_.frameShown();
        return true;
    }

    std::string lost() const {
        return "the Wayland compositor at WAYLAND_DISPLAY=" + compositorName_ + " closed the connection (" +
               std::strerror(wl_display_get_error(display_.get())) + ")";
    }

private:
    // A buffer of the compositor's holding `image` (premultiplied BGRA, size()): ARGB8888 is premultiplied,
    // little-endian B, G, R, A, the image's own layout.
    WaylandBuffer shmBuffer(const cv::Mat& image) {
        CV_Assert(image.type() == CV_8UC4 && image.size() == size_ && image.isContinuous());
        const std::size_t bytes = image.total() * image.elemSize();
        const UniqueFd memory(memfd_create("everytouch-overlay", MFD_CLOEXEC));
        if (!memory || ftruncate(memory.get(), static_cast<off_t>(bytes)) != 0)
            throw std::runtime_error(std::string("the code overlay's images: ") + std::strerror(errno));
        std::size_t written = 0;
        while (written < bytes) {
            const ssize_t count =
                pwrite(memory.get(), image.data + written, bytes - written, static_cast<off_t>(written));
            if (count < 0 && errno == EINTR)
                continue;
            if (count <= 0)
                throw std::runtime_error(std::string("the code overlay's images: ") + std::strerror(errno));
            written += static_cast<std::size_t>(count);
        }
        wl_shm_pool* pool = wl_shm_create_pool(shm_.get(), memory.get(), static_cast<int32_t>(bytes));
        WaylandBuffer buffer(wl_shm_pool_create_buffer(
            pool, 0, size_.width, size_.height, static_cast<int32_t>(image.step), WL_SHM_FORMAT_ARGB8888));
        // The buffer keeps the pool's memory.
        wl_shm_pool_destroy(pool);
        return buffer;
    }

    void roundtrip() {
        if (wl_display_roundtrip(display_.get()) < 0)
            throw std::runtime_error(lost());
    }

    std::size_t findOutput(const std::string& display) const {
        if (display.empty())
            return 0;
        for (std::size_t index = 0; index < outputs_.size(); ++index)
            if (display == outputs_[index]->name || display == std::to_string(index))
                return index;
        std::string known;
        for (std::size_t index = 0; index < outputs_.size(); ++index)
            known += (known.empty() ? "" : ", ") + describeOutput(outputs_, index);
        throw InputError(kDisplayKey, display,
                         "no such output on the Wayland compositor " + compositorName_ + "; it has " + known);
    }

    static void global(void* data, wl_registry* registry, uint32_t name, const char* interface,
                       uint32_t version) {
        auto* self = static_cast<Connection*>(data);
        const auto bind = [&](const wl_interface* type, uint32_t highest) {
            return wl_registry_bind(registry, name, type, std::min(version, highest));
        };
        if (std::strcmp(interface, wl_compositor_interface.name) == 0) {
            self->compositor_.reset(static_cast<wl_compositor*>(bind(&wl_compositor_interface, 4)));
        } else if (std::strcmp(interface, wl_shm_interface.name) == 0) {
            self->shm_.reset(static_cast<wl_shm*>(bind(&wl_shm_interface, 1)));
        } else if (std::strcmp(interface, zwlr_layer_shell_v1_interface.name) == 0) {
            self->layerShell_.reset(
                static_cast<zwlr_layer_shell_v1*>(bind(&zwlr_layer_shell_v1_interface, 4)));
        } else if (std::strcmp(interface, wl_output_interface.name) == 0) {
            auto output = std::make_unique<CompositorOutput>();
            output->output.reset(static_cast<wl_output*>(bind(&wl_output_interface, 4)));
            wl_output_add_listener(output->output.get(), &kOutputListener, output.get());
            self->outputs_.push_back(std::move(output));
        }
    }

    static const wl_registry_listener kRegistryListener;
    static const zwlr_layer_surface_v1_listener kLayerSurfaceListener;
    static const wl_callback_listener kFrameListener;

    std::string compositorName_;
    WaylandDisplay display_;  // first: the objects below go before it
    WaylandRegistry registry_;
    WaylandCompositor compositor_;
    WaylandShm shm_;
    LayerShell layerShell_;
    std::vector<std::unique_ptr<CompositorOutput>> outputs_;
    WaylandSurface surface_;
    LayerSurface layerSurface_;
    OverlayBuffers<WaylandBuffer> buffers_;
    WaylandCallback frame_;
    double refreshHz_ = kAssumedRefreshHz;
    int scale_ = 1;
    cv::Size configuredSize_;
    cv::Size size_;
    std::string description_;
    bool configured_ = false;
    bool closed_ = false;
    bool framePending_ = false;
    bool frameDone_ = false;
    std::uint32_t lastFrameMs_ = 0;
};

const wl_registry_listener WaylandOverlayProjector::Connection::kRegistryListener = {
    .global = global,
    .global_remove = [](void*, wl_registry*, uint32_t) {},
};

const zwlr_layer_surface_v1_listener WaylandOverlayProjector::Connection::kLayerSurfaceListener = {
    .configure =
        [](void* data, zwlr_layer_surface_v1* surface, uint32_t serial, uint32_t width, uint32_t height) {
            auto* self = static_cast<Connection*>(data);
            zwlr_layer_surface_v1_ack_configure(surface, serial);
            const cv::Size size(static_cast<int>(width), static_cast<int>(height));
            if (self->configured_ && size != self->configuredSize_)
                ET_LOG(Warning) << self->description_ << ": the output is now " << size.width << "x"
                                << size.height << "; the code stays at its size until everytouchd restarts";
            self->configuredSize_ = size;
            self->configured_ = true;
        },
    .closed = [](void* data, zwlr_layer_surface_v1*) { static_cast<Connection*>(data)->closed_ = true; },
};

const wl_callback_listener WaylandOverlayProjector::Connection::kFrameListener = {
    .done =
        [](void* data, wl_callback*, uint32_t timeMs) {
            auto* self = static_cast<Connection*>(data);
            self->framePending_ = false;
            self->frameDone_ = true;
            self->lastFrameMs_ = timeMs;
        },
};

WaylandOverlayProjector::WaylandOverlayProjector(const std::string& display, std::uint64_t seed, int delta,
                                                 const std::filesystem::path& patternDirectory) {
    checkCodeDelta(delta);
    takeOutput(thread_.start("et-overlay",
                             [this, display](std::promise<OpenedOutput>& promise) { run(display, promise); }),
               seed, delta, patternDirectory);
}

WaylandOverlayProjector::~WaylandOverlayProjector() = default;

std::optional<std::string> WaylandOverlayProjector::problem() const {
    const std::lock_guard lock(problemMutex_);
    return problem_;
}

void WaylandOverlayProjector::setProblem(std::optional<std::string> problem) {
    if (problem)
        ET_LOG(Error) << *problem << "; touches are not detected meanwhile";
    {
        const std::lock_guard lock(problemMutex_);
        problem_ = std::move(problem);
    }
    problemChanged();
}

void WaylandOverlayProjector::run(const std::string& display, std::promise<OpenedOutput>& opened) {
    std::optional<Connection> connection;
    try {
        connection.emplace(display);
        opened.set_value(OpenedOutput{connection->size(), connection->description()});
    } catch (...) {
        opened.set_exception(std::current_exception());
        return;
    }
    const cv::Size size = connection->size();  // the code's

    cv::Mat images[2];
    bool haveImages = false;
    int polarity = 0;
    std::uint32_t lastFrameMs = 0;
    using Clock = std::chrono::steady_clock;
    Clock::time_point nextAttempt;
    while (!thread_.stopping()) {
        if (!connection) {
            // A compositor that restarts (a new session, a crash) takes the same socket again.
            if (Clock::now() < nextAttempt) {
                poll(nullptr, 0, kPollMs);
                continue;
            }
            nextAttempt = Clock::now() + kReconnectInterval;
            try {
                connection.emplace(display);
            } catch (const std::exception&) {
                continue;
            }
            if (connection->size() != size) {
                setProblem(connection->description() + ": the output is no longer " +
                           std::to_string(size.width) + "x" + std::to_string(size.height) +
                           ", the code's size; restart everytouchd");
                connection.reset();
                nextAttempt = Clock::time_point::max();
                continue;
            }
            lastFrameMs = 0;
            haveImages = false;
            images_.handOverAgain(images);
            ET_LOG(Notice) << connection->description() << ": the code is back over the desktop";
            setProblem(std::nullopt);
        }
        try {
            if (images_.takeNewest(images)) {
                connection->upload(images);
                haveImages = true;
            }
        } catch (const std::exception& error) {
            ET_LOG(Error) << connection->description() << ": " << error.what();
        }
        if (connection->takeFrameDone()) {
            const std::uint32_t frameMs = connection->lastFrameMs();
            if (lastFrameMs != 0) {
                const double periods =
                    static_cast<std::uint32_t>(frameMs - lastFrameMs) * connection->refreshHz() / 1000.0;
                if (periods > 1.5)
                    thread_.countMissed(static_cast<std::uint64_t>(std::lround(periods)) - 1);
            }
            lastFrameMs = frameMs;
            thread_.countPresented();
            polarity ^= 1;
        }
        if (haveImages && !connection->framePending())
            connection->draw(polarity);

        wl_display* wayland = connection->display();
        while (wl_display_prepare_read(wayland) != 0)
            wl_display_dispatch_pending(wayland);
        wl_display_flush(wayland);
        pollfd descriptor{wl_display_get_fd(wayland), POLLIN, 0};
        if (poll(&descriptor, 1, kPollMs) > 0 && (descriptor.revents & POLLIN))
            wl_display_read_events(wayland);
        else
            wl_display_cancel_read(wayland);
        std::optional<std::string> gone;
        if (wl_display_dispatch_pending(wayland) < 0 || wl_display_get_error(wayland) != 0)
            gone = connection->lost();
        else if (connection->closed())
            gone = "the compositor closed the overlay (its output may have gone away)";
        if (gone) {
            setProblem(connection->description() + ": " + *gone);
            connection.reset();
            nextAttempt = Clock::now() + kReconnectInterval;
        }
    }
}

}  // namespace everytouch::io

#include "io/window_projector.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

#include "core/embedding.h"
#include "core/keystone.h"
#include "io/input_error.h"
#include "io/kept_pattern.h"
#include "io/log.h"
#include "io/output_thread.h"
#include "io/projector_image.h"
#include "io/sdl_handles.h"

namespace everytouch::io {

namespace {

constexpr const char* kDisplayKey = "[Projector] Display=";
// What a display server that states no refresh rate (Xvfb, some KMS drivers) is taken to refresh at.
constexpr int kAssumedRefreshHz = 60;

// SDL's video subsystem for as long as it lives.
class SdlVideo {
public:
    // Tries the drivers that put pixels on a real output, in turn; SDL would otherwise fall back to its
    // offscreen driver, which draws nowhere. A driver the user chose with SDL_VIDEODRIVER is taken as it is.
    SdlVideo() {
        // A fullscreen window on a second output must stay up while the user works on the first.
        SDL_SetHint(SDL_HINT_VIDEO_MINIMIZE_ON_FOCUS_LOSS, "0");
        std::string failures;
        const char* chosen = std::getenv("SDL_VIDEODRIVER");
        const std::vector<std::string> drivers = chosen && *chosen
                                                     ? std::vector<std::string>{chosen}
                                                     : std::vector<std::string>{"x11", "wayland", "kmsdrm"};
        for (const std::string& driver : drivers) {
            if (SDL_VideoInit(driver.c_str()) == 0) {
                const std::string_view name = SDL_GetCurrentVideoDriver();
                if (name == "offscreen" || name == "dummy") {
                    SDL_VideoQuit();
                    failures += "; " + driver + ": draws on no output";
                    continue;
                }
                return;
            }
            failures += "; " + driver + ": " + SDL_GetError();
        }
        throw std::runtime_error(
            "no display server is reachable for the projector window (set DISPLAY or WAYLAND_DISPLAY to the "
            "display server's, or run where the console's KMS device is free)" +
            failures);
    }
    ~SdlVideo() {
        SDL_VideoQuit();
        SDL_Quit();
    }
    SdlVideo(const SdlVideo&) = delete;
    SdlVideo& operator=(const SdlVideo&) = delete;
};

std::string describeDisplay(int index) {
    SDL_Rect bounds{};
    SDL_GetDisplayBounds(index, &bounds);
    const char* name = SDL_GetDisplayName(index);
    return std::to_string(index) + " \"" + (name ? name : "") + "\" (" + std::to_string(bounds.w) + "x" +
           std::to_string(bounds.h) + ")";
}

int findDisplay(const std::string& display) {
    const int count = SDL_GetNumVideoDisplays();
    if (count < 1)
        throw std::runtime_error(std::string("the display server reports no display: ") + SDL_GetError());
    if (display.empty())
        return 0;
    for (int index = 0; index < count; ++index) {
        const char* name = SDL_GetDisplayName(index);
        if ((name && display == name) || display == std::to_string(index))
            return index;
    }
    std::string known;
    for (int index = 0; index < count; ++index)
        known += (known.empty() ? "" : ", ") + describeDisplay(index);
    throw InputError(kDisplayKey, display,
                     std::string("no such display on ") + SDL_GetCurrentVideoDriver() + "; it has " + known);
}

}  // namespace

WindowProjector::WindowProjector(const std::string& display, std::uint64_t seed, int delta,
                                 const std::filesystem::path& patternDirectory)
    : delta_(delta) {
    checkCodeDelta(delta);
    OpenedOutput opened = thread_.start(
        "et-projector", [this, display](std::promise<OpenedOutput>& promise) { run(display, promise); });
    size_ = opened.size;
    description_ = std::move(opened.description);
    pattern_ = keptPattern(seed, size_, patternDirectory);
    embedAndHandOver(idleImage());
}

WindowProjector::~WindowProjector() = default;

void WindowProjector::setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) {
    core::checkDisplayToProjector(displaySize, displayToProjector);
    displaySize_ = displaySize;
    displayToProjector_ = displayToProjector / displayToProjector(2, 2);
    if (!showing_)
        embedAndHandOver(idleImage());
}

void WindowProjector::show(const cv::Mat& projectorImage) {
    const cv::Mat colour = projectorImageInColour(projectorImage, size_);
    showing_ = true;
    embedAndHandOver(colour);
}

void WindowProjector::release() noexcept {
    showing_ = false;
    try {
        embedAndHandOver(idleImage());
    } catch (const std::exception& error) {
        ET_LOG(Error) << description_ << ": the display could not be drawn again: " << error.what();
    }
}

cv::Mat WindowProjector::idleImage() const {
    if (displaySize_.empty())
        return cv::Mat(size_, CV_8UC3, cv::Scalar::all(255));
    return core::drawThroughKeystone(cv::Mat(displaySize_, CV_8UC3, cv::Scalar::all(255)),
                                     displayToProjector_, size_);
}

void WindowProjector::embedAndHandOver(const cv::Mat& content) {
    cv::Mat positive, negative;
    core::embedCode(content, pattern_, delta_, positive, negative);
    const std::lock_guard lock(handOverMutex_);
    handedOver_[0] = std::move(positive);
    handedOver_[1] = std::move(negative);
    fresh_ = true;
}

void WindowProjector::run(const std::string& display, std::promise<OpenedOutput>& opened) {
    std::optional<SdlVideo> video;
    SdlWindow window;
    SdlRenderer renderer;
    SdlTexture textures[2];
    double periodS = 1.0 / kAssumedRefreshHz;
    std::string description;  // the thread's own copy, for its messages
    try {
        video.emplace();
        const int index = findDisplay(display);
        SDL_Rect bounds{};
        if (SDL_GetDisplayBounds(index, &bounds) != 0)
            throw std::runtime_error(std::string("display ") + describeDisplay(index) + ": " +
                                     SDL_GetError());
        window.reset(SDL_CreateWindow("everytouch projector", SDL_WINDOWPOS_CENTERED_DISPLAY(index),
                                      SDL_WINDOWPOS_CENTERED_DISPLAY(index), bounds.w, bounds.h,
                                      SDL_WINDOW_FULLSCREEN_DESKTOP | SDL_WINDOW_BORDERLESS |
                                          SDL_WINDOW_ALWAYS_ON_TOP | SDL_WINDOW_SKIP_TASKBAR));
        if (!window)
            throw std::runtime_error(std::string("the projector window cannot be made: ") + SDL_GetError());
        renderer.reset(SDL_CreateRenderer(window.get(), -1, SDL_RENDERER_PRESENTVSYNC));
        if (!renderer)
            renderer.reset(SDL_CreateRenderer(window.get(), -1, SDL_RENDERER_SOFTWARE));
        if (!renderer)
            throw std::runtime_error(std::string("the projector window cannot be drawn: ") + SDL_GetError());
        int width = 0, height = 0;
        if (SDL_GetRendererOutputSize(renderer.get(), &width, &height) != 0 || width <= 0 || height <= 0)
            throw std::runtime_error(std::string("the projector window has no size: ") + SDL_GetError());
        for (SdlTexture& texture : textures) {
            texture.reset(SDL_CreateTexture(renderer.get(), SDL_PIXELFORMAT_BGR24,
                                            SDL_TEXTUREACCESS_STREAMING, width, height));
            if (!texture)
                throw std::runtime_error(std::string("the projector window's images: ") + SDL_GetError());
        }
        SDL_DisplayMode mode{};
        int refreshHz = kAssumedRefreshHz;
        if (SDL_GetCurrentDisplayMode(index, &mode) == 0 && mode.refresh_rate > 0)
            refreshHz = mode.refresh_rate;
        periodS = 1.0 / refreshHz;
        SDL_RendererInfo info{};
        SDL_GetRendererInfo(renderer.get(), &info);
        description = "the window on " + std::string(SDL_GetCurrentVideoDriver()) + " display " +
                      describeDisplay(index) + " at " + std::to_string(refreshHz) + " Hz (" + info.name + ")";
        opened.set_value(OpenedOutput{cv::Size(width, height), description});
    } catch (...) {
        opened.set_exception(std::current_exception());
        return;
    }

    using Clock = std::chrono::steady_clock;
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(periodS));
    cv::Mat images[2];
    bool haveImages = false;
    int polarity = 0;
    Clock::time_point last = Clock::now();
    bool reported = false;
    while (!thread_.stopping()) {
        SDL_Event event;
        while (SDL_PollEvent(&event)) {
        }
        bool fresh = false;
        {
            const std::lock_guard lock(handOverMutex_);
            if (fresh_) {
                std::swap(images[0], handedOver_[0]);
                std::swap(images[1], handedOver_[1]);
                fresh_ = false;
                fresh = true;
            }
        }
        bool drawn = true;
        if (fresh) {
            for (int k = 0; k < 2; ++k)
                drawn = drawn && SDL_UpdateTexture(textures[k].get(), nullptr, images[k].data,
                                                   static_cast<int>(images[k].step)) == 0;
            haveImages = true;
        }
        if (haveImages)
            drawn = drawn && SDL_RenderCopy(renderer.get(), textures[polarity].get(), nullptr, nullptr) == 0;
        else
            drawn = drawn && SDL_RenderClear(renderer.get()) == 0;
        if (!drawn && !reported) {
            ET_LOG(Error) << description << ": cannot draw: " << SDL_GetError();
            reported = true;
        }
        SDL_RenderPresent(renderer.get());
        thread_.countPresented();
        polarity ^= 1;

        // With vertical sync the present returns at the next refresh; without it (a virtual display server),
        // the loop keeps the refresh's pace itself.
        Clock::time_point now = Clock::now();
        if (now - last < period / 2) {
            std::this_thread::sleep_until(last + period);
            now = Clock::now();
        }
        const double periods =
            std::chrono::duration<double>(now - last) / std::chrono::duration<double>(period);
        if (thread_.presented() > 1 && periods > 1.5)
            thread_.countMissed(static_cast<std::uint64_t>(std::lround(periods)) - 1);
        last = now;
    }
}

}  // namespace everytouch::io

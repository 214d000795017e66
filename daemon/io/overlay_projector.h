#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <future>
#include <mutex>
#include <string>

#include "io/desktop_overlay.h"
#include "io/output_thread.h"

namespace everytouch::io {

// The code over the desktop as it is, on X11: a topmost, input-transparent, translucent window over one
// output, which the compositing manager blends over everything on every refresh, alternating between the two
// images of core::makeCodeOverlay (Present paces them, one per refresh). People see the desktop and use it as
// always; the camera's subtraction of two frames sees the code.
//
// Without a compositing manager the overlay's pixels would cover the desktop as they are, so it needs one at
// start, hides while none runs and comes back when one does.
//
// Xlib lives on the overlay's own thread; the calls below only hand it new images. Called from one thread at
// a time, as every ProjectorOutput.
class OverlayProjector final : public DesktopOverlay {
public:
    // Opens the overlay on the X server of DISPLAY over `display`: a RandR monitor's name or its number from
    // 0; empty for the first. The code is the pattern of `seed` at the monitor's size, `delta` levels strong
    // (1..127), kept in `patternDirectory` as the window projector keeps it. Throws InputError naming
    // [Projector] Display= for a monitor that does not exist (listing those that do) and for a bad delta,
    // std::runtime_error when no X server is reachable, it lacks what the overlay needs (a 32-bit visual,
    // Present, SHAPE, XFixes), or no compositing manager runs.
    OverlayProjector(const std::string& display, std::uint64_t seed, int delta,
                     const std::filesystem::path& patternDirectory);
    ~OverlayProjector() override;
    OverlayProjector(const OverlayProjector&) = delete;
    OverlayProjector& operator=(const OverlayProjector&) = delete;

    std::optional<std::string> problem() const override;

    // Refreshes that showed one of the two images so far, and whether the overlay is up.
    std::uint64_t presented() const { return thread_.presented(); }
    bool visible() const { return visible_; }

private:
    class Connection;
    void run(const std::string& display, std::promise<OpenedOutput>& opened);

    std::atomic<bool> visible_{false};
    std::atomic<bool> compositorGone_{false};  // the overlay hides meanwhile
    OutputThread thread_;                      // last: it stops before what it draws from goes away
};

}  // namespace everytouch::io

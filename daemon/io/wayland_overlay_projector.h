#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <string>

#include "io/desktop_overlay.h"
#include "io/output_thread.h"

namespace everytouch::io {

// The code over the desktop as it is, on a Wayland compositor that offers the layer-shell protocol
// (wlroots' compositors such as sway, KDE Plasma's KWin, Hyprland; not GNOME's Mutter): a surface on the
// overlay layer over one output, anchored to its four edges, with an empty input region, alternating between
// the two images of core::makeCodeOverlay on every frame the compositor asks for. The compositor blends it
// over everything, as every Wayland compositor composites. When the
// compositor goes away, problem() says so, and the overlay comes back once a compositor runs on the same
// socket with an output of the same name and size.
//
// libwayland lives on the overlay's own thread; the calls below only hand it new images. Called from one
// thread at a time, as every ProjectorOutput.
class WaylandOverlayProjector final : public DesktopOverlay {
public:
    // Opens the overlay on the compositor of WAYLAND_DISPLAY over `display`: an output's name as the
    // compositor gives it (e.g. DP-1) or its number from 0; empty for the first. The code is the pattern of
    // `seed` at the output's size in pixels, `delta` levels strong (1..127), kept in `patternDirectory` as
    // the window projector keeps it. Throws InputError naming [Projector] Display= for an output that does
    // not exist (listing those that do) and for a bad delta, std::runtime_error when the compositor is not
    // reachable or does not offer the layer shell.
    WaylandOverlayProjector(const std::string& display, std::uint64_t seed, int delta,
                            const std::filesystem::path& patternDirectory);
    ~WaylandOverlayProjector() override;
    WaylandOverlayProjector(const WaylandOverlayProjector&) = delete;
    WaylandOverlayProjector& operator=(const WaylandOverlayProjector&) = delete;

    std::optional<std::string> problem() const override;

    // Frames that showed one of the two images so far.
    std::uint64_t presented() const { return thread_.presented(); }

private:
    class Connection;
    void run(const std::string& display, std::promise<OpenedOutput>& opened);
    void setProblem(std::optional<std::string> problem);

    mutable std::mutex problemMutex_;
    std::optional<std::string> problem_;
    OutputThread thread_;  // last: it stops before what it draws from goes away
};

}  // namespace everytouch::io

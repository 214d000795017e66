#include "io/overlay_projector.h"

#include <poll.h>

#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "io/input_error.h"
#include "io/log.h"
#include "io/output_thread.h"
#include "io/overlay_images.h"
#include "io/projector_image.h"

// Xlib's macros (None, Status, Bool) would clash with the C++ headers above: it comes last, and this file
// stays out of unity builds.
#include <X11/Xatom.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/extensions/Xfixes.h>
#include <X11/extensions/Xpresent.h>
#include <X11/extensions/Xrandr.h>
#include <X11/extensions/shape.h>

#include "io/x11_handles.h"

namespace everytouch::io {

namespace {

constexpr const char* kDisplayKey = "[Projector] Display=";
// How long the overlay's thread waits for the X server before it looks whether it should stop.
constexpr int kPollMs = 100;

// Xlib reports a failed request to a handler of the whole process, which by default ends it. The overlay's
// requests fail only while it sets up (on the thread that reads the replies), and it checks for that then.
thread_local int lastXError = 0;
int recordXError(Display* /*display*/, XErrorEvent* event) {
    lastXError = event->error_code;
    return 0;
}

struct Monitor {
    std::string name;
    cv::Rect area;
};

std::vector<Monitor> monitorsOf(Display* display) {
    const Window root = DefaultRootWindow(display);
    std::vector<Monitor> monitors;
    int count = 0;
    const UniqueHandle<XRRMonitorInfo, XRRFreeMonitors> info(XRRGetMonitors(display, root, True, &count));
    for (int k = 0; info && k < count; ++k) {
        const UniqueHandle<char, XFree> name(XGetAtomName(display, info.get()[k].name));
        monitors.push_back({name ? name.get() : "", cv::Rect(info.get()[k].x, info.get()[k].y,
                                                             info.get()[k].width, info.get()[k].height)});
    }
    if (monitors.empty()) {
        const int screen = DefaultScreen(display);
        monitors.push_back(
            {"screen", cv::Rect(0, 0, DisplayWidth(display, screen), DisplayHeight(display, screen))});
    }
    return monitors;
}

std::string describeMonitor(const std::vector<Monitor>& monitors, std::size_t index) {
    const cv::Rect& area = monitors[index].area;
    return std::to_string(index) + " \"" + monitors[index].name + "\" (" + std::to_string(area.width) + "x" +
           std::to_string(area.height) + ")";
}

std::size_t findMonitor(const std::vector<Monitor>& monitors, const std::string& display,
                        const std::string& server) {
    if (display.empty())
        return 0;
    for (std::size_t index = 0; index < monitors.size(); ++index)
        if (display == monitors[index].name || display == std::to_string(index))
            return index;
    std::string known;
    for (std::size_t index = 0; index < monitors.size(); ++index)
        known += (known.empty() ? "" : ", ") + describeMonitor(monitors, index);
    throw InputError(kDisplayKey, display, "no such monitor on the X server " + server + "; it has " + known);
}

Atom compositorSelection(Display* display) {
    const std::string name = "_NET_WM_CM_S" + std::to_string(DefaultScreen(display));
    return XInternAtom(display, name.c_str(), False);
}

bool compositorRuns(Display* display, Atom selection) {
    return XGetSelectionOwner(display, selection) != None;
}

}  // namespace

// The overlay's X resources. Closing the connection frees every resource it made on the server.
class OverlayProjector::Connection {
public:
    explicit Connection(const std::string& display) {
        XSetErrorHandler(recordXError);
        const char* server = std::getenv("DISPLAY");
        server_ = server ? server : "";
        display_.reset(XOpenDisplay(nullptr));
        if (!display_)
            throw std::runtime_error(
                server_.empty()
                    ? std::string("the code overlay needs a Wayland compositor or an X server, and neither "
                                  "WAYLAND_DISPLAY nor DISPLAY is set")
                    : "the code overlay cannot connect to the X server " + server_);
        Display* x = display_.get();
        int eventBase = 0, errorBase = 0;
        if (!XShapeQueryExtension(x, &eventBase, &errorBase))
            throw std::runtime_error(lacks("SHAPE, for a window that lets input through"));
        if (!XFixesQueryExtension(x, &fixesEventBase_, &errorBase))
            throw std::runtime_error(lacks("XFixes, to follow the compositing manager"));
        if (!XPresentQueryExtension(x, &presentOpcode_, &eventBase, &errorBase))
            throw std::runtime_error(lacks("Present, to show one image per refresh"));

        const std::vector<Monitor> monitors = monitorsOf(x);
        const std::size_t index = findMonitor(monitors, display, server_);
        area_ = monitors[index].area;

        selection_ = compositorSelection(x);
        if (!compositorRuns(x, selection_))
            throw std::runtime_error("no compositing manager runs on the X server " + server_ +
                                     " (nothing owns _NET_WM_CM_S" + std::to_string(DefaultScreen(x)) +
                                     "): the code over the desktop is blended by one; start one (picom, "
                                     "xfwm4's, KWin's, Mutter's) or "
                                     "use [Projector] Output=window");

        XVisualInfo visual{};
        if (!XMatchVisualInfo(x, DefaultScreen(x), 32, TrueColor, &visual))
            throw std::runtime_error(lacks("a 32-bit TrueColor visual, for a translucent window"));
        const Window root = DefaultRootWindow(x);
        XSetWindowAttributes attributes{};
        attributes.override_redirect = True;
        attributes.colormap = XCreateColormap(x, root, visual.visual, AllocNone);
        attributes.border_pixel = 0;
        attributes.background_pixel = 0;  // transparent until the first image
        window_ = XCreateWindow(x, root, area_.x, area_.y, static_cast<unsigned>(area_.width),
                                static_cast<unsigned>(area_.height), 0, 32, InputOutput, visual.visual,
                                CWOverrideRedirect | CWColormap | CWBorderPixel | CWBackPixel, &attributes);
        // An empty input region: every click and touch goes to what lies below.
        XShapeCombineRectangles(x, window_, ShapeInput, 0, 0, nullptr, 0, ShapeSet, Unsorted);
        XStoreName(x, window_, "everytouch code overlay");
        // Bypassing the compositor would show the overlay's pixels as they are, over the desktop.
        const long doNotBypass = 2;
        XChangeProperty(x, window_, XInternAtom(x, "_NET_WM_BYPASS_COMPOSITOR", False), XA_CARDINAL, 32,
                        PropModeReplace, reinterpret_cast<const unsigned char*>(&doNotBypass), 1);
        for (Pixmap& pixmap : pixmaps_)
            pixmap = XCreatePixmap(x, window_, static_cast<unsigned>(area_.width),
                                   static_cast<unsigned>(area_.height), 32);
        gc_ = XCreateGC(x, pixmaps_[0], 0, nullptr);
        XPresentSelectInput(x, window_, PresentCompleteNotifyMask);
        XFixesSelectSelectionInput(x, root, selection_,
                                   XFixesSetSelectionOwnerNotifyMask |
                                       XFixesSelectionWindowDestroyNotifyMask |
                                       XFixesSelectionClientCloseNotifyMask);
        // Windows mapped or raised later must stay below the code.
        XSelectInput(x, root, SubstructureNotifyMask);
        XSync(x, False);
        if (lastXError != 0) {
            char text[160] = {};
            XGetErrorText(x, lastXError, text, sizeof text);
            throw std::runtime_error("the code overlay's window cannot be made on the X server " + server_ +
                                     ": " + text);
        }
        description_ = "the overlay on the X server " + server_ + " monitor " +
                       describeMonitor(monitors, index) + ", blended by its compositing manager";
    }

    Display* display() const { return display_.get(); }
    cv::Size size() const { return area_.size(); }
    const std::string& description() const { return description_; }
    Atom selection() const { return selection_; }
    int fixesEventBase() const { return fixesEventBase_; }
    int presentOpcode() const { return presentOpcode_; }
    Window window() const { return window_; }

    // Uploads the two images (premultiplied BGRA, size()) for present().
    void upload(const cv::Mat images[2]) {
        for (int k = 0; k < 2; ++k) {
            CV_Assert(images[k].type() == CV_8UC4 && images[k].size() == size() && images[k].isContinuous());
            XImage image{};
            image.width = area_.width;
            image.height = area_.height;
            image.format = ZPixmap;
            image.data = reinterpret_cast<char*>(images[k].data);
            image.byte_order = LSBFirst;
            image.bitmap_unit = 32;
            image.bitmap_bit_order = LSBFirst;
            image.bitmap_pad = 32;
            image.depth = 32;
            image.bytes_per_line = static_cast<int>(images[k].step);
            image.bits_per_pixel = 32;
            image.red_mask = 0xff0000;
            image.green_mask = 0xff00;
            image.blue_mask = 0xff;
            XInitImage(&image);
            XPutImage(display(), pixmaps_[k], gc_, &image, 0, 0, 0, 0, static_cast<unsigned>(area_.width),
                      static_cast<unsigned>(area_.height));
        }
    }

    // Shows image `polarity` from the next refresh on; returns the request's serial.
    std::uint32_t present(int polarity) {
        if (++serial_ == 0)  // 0 stands for none in run()
            ++serial_;
        XPresentPixmap(display(), window_, pixmaps_[polarity], serial_, None, None, 0, 0, None, None, None,
                       PresentOptionNone, 0, 0, 0, nullptr, 0);
        return serial_;
    }

    void map() { XMapRaised(display(), window_); }
    void unmap() { XUnmapWindow(display(), window_); }
    void raise() { XRaiseWindow(display(), window_); }

private:
    std::string lacks(const std::string& what) const {
        return "the X server " + server_ + " lacks " + what + ", which the code overlay needs";
    }

    std::string server_;
    XDisplay display_;
    cv::Rect area_;
    std::string description_;
    Atom selection_ = None;
    int fixesEventBase_ = 0;
    int presentOpcode_ = 0;
    Window window_ = None;
    Pixmap pixmaps_[2] = {None, None};
    GC gc_ = nullptr;
    std::uint32_t serial_ = 0;
};

OverlayProjector::OverlayProjector(const std::string& display, std::uint64_t seed, int delta,
                                   const std::filesystem::path& patternDirectory) {
    checkCodeDelta(delta);
    takeOutput(thread_.start("et-overlay",
                             [this, display](std::promise<OpenedOutput>& promise) { run(display, promise); }),
               seed, delta, patternDirectory);
}

OverlayProjector::~OverlayProjector() = default;

std::optional<std::string> OverlayProjector::problem() const {
    if (compositorGone_)
        return "no compositing manager runs on its X server, so the code overlay hides until one does (" +
               describe() + ")";
    return std::nullopt;
}

void OverlayProjector::run(const std::string& display, std::promise<OpenedOutput>& opened) {
    std::optional<Connection> connection;
    try {
        connection.emplace(display);
        opened.set_value(OpenedOutput{connection->size(), connection->description()});
    } catch (...) {
        opened.set_exception(std::current_exception());
        return;
    }
    Display* x = connection->display();
    const std::string& description = connection->description();

    cv::Mat images[2];
    bool haveImages = false;
    bool compositor = true;
    bool mapped = false;
    std::uint32_t inFlight = 0;  // the serial of the image being presented; 0: none
    std::uint64_t lastMsc = 0;   // the refresh counter when the last image went up; 0: none yet
    int polarity = 0;
    while (!thread_.stopping()) {
        if (images_.takeNewest(images)) {
            connection->upload(images);
            haveImages = true;
        }
        if (haveImages && compositor && !mapped) {
            connection->map();
            mapped = true;
            inFlight = 0;
            lastMsc = 0;
        } else if (!compositor && mapped) {
            connection->unmap();
            mapped = false;
        }
        visible_ = mapped;
        if (mapped && inFlight == 0)
            inFlight = connection->present(polarity);
        XFlush(x);

        if (XPending(x) == 0) {
            pollfd descriptor{ConnectionNumber(x), POLLIN, 0};
            poll(&descriptor, 1, kPollMs);
        }
        while (XPending(x) > 0) {
            XEvent event;
            XNextEvent(x, &event);
            if (event.type == connection->fixesEventBase() + XFixesSelectionNotify) {
                const bool runs = compositorRuns(x, connection->selection());
                if (runs && !compositor)
                    ET_LOG(Notice) << description
                                   << ": a compositing manager runs again; the code is back over the desktop";
                if (!runs && compositor)
                    ET_LOG(Warning)
                        << description
                        << ": the compositing manager went away; the code overlay hides until one "
                           "runs again, and touches are not detected meanwhile";
                if (runs != compositor) {
                    compositorGone_ = !runs;
                    problemChanged();
                }
                compositor = runs;
            } else if (event.type == MapNotify || event.type == ConfigureNotify) {
                const Window moved = event.type == MapNotify ? event.xmap.window : event.xconfigure.window;
                if (mapped && moved != connection->window())
                    connection->raise();
            } else if (event.type == GenericEvent && event.xcookie.extension == connection->presentOpcode() &&
                       XGetEventData(x, &event.xcookie)) {
                if (event.xcookie.evtype == PresentCompleteNotify) {
                    const auto* complete =
                        static_cast<const XPresentCompleteNotifyEvent*>(event.xcookie.data);
                    if (inFlight != 0 && complete->serial_number == inFlight) {
                        if (lastMsc != 0 && complete->msc > lastMsc + 1)
                            thread_.countMissed(complete->msc - lastMsc - 1);
                        lastMsc = complete->msc;
                        inFlight = 0;
                        thread_.countPresented();
                        polarity ^= 1;
                    }
                }
                XFreeEventData(x, &event.xcookie);
            }
        }
    }
    visible_ = false;
}

}  // namespace everytouch::io

#include "support/wayland_compositor.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "support/screen_grabs.h"

namespace everytouch::test {

namespace {

constexpr int kNobody = 65534;

std::string hexColour(const cv::Vec3b& bgr) {
    char text[8];
    std::snprintf(text, sizeof text, "#%02x%02x%02x", bgr[2], bgr[1], bgr[0]);
    return text;
}

}  // namespace

WaylandCompositor::WaylandCompositor(cv::Size size, const cv::Vec3b& background)
    : size_(size), background_(background) {
    if (::geteuid() == 0 && ::chown(directory_.path().c_str(), kNobody, kNobody) != 0)
        throw std::runtime_error("cannot give " + directory_.path().string() + " to nobody for sway");
    std::ofstream(directory_ / "sway.conf") << "output HEADLESS-1 mode " << size.width << "x" << size.height
                                            << "@60Hz bg " << hexColour(background) << " solid_color\n";
    start();
}

void WaylandCompositor::start() {
    // A compositor that was killed leaves its socket and lock behind.
    socket_.clear();
    for (const auto& entry : std::filesystem::directory_iterator(directory_.path()))
        if (entry.path().filename().string().starts_with("wayland-"))
            std::filesystem::remove(entry.path());
    std::vector<std::string> argv;
    if (::geteuid() == 0) {
        argv = {"setpriv", "--reuid=" + std::to_string(kNobody), "--regid=" + std::to_string(kNobody),
                "--clear-groups"};
    }
    argv.insert(argv.end(), {"sway", "--config", (directory_ / "sway.conf").string()});
    process_ = std::make_unique<BackgroundProcess>(
        argv, directory_ / "sway.log",
        std::vector<std::pair<std::string, std::string>>{{"XDG_RUNTIME_DIR", directory_.path().string()},
                                                         {"HOME", directory_.path().string()},
                                                         {"WLR_BACKENDS", "headless"},
                                                         {"WLR_HEADLESS_OUTPUTS", "1"},
                                                         {"WLR_RENDERER", "pixman"},
                                                         {"WLR_LIBINPUT_NO_DEVICES", "1"}});
    const cv::Mat desktop(size_, CV_8UC3, cv::Scalar(background_[0], background_[1], background_[2]));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
        if (!process_->running())
            break;
        // The first free name: the same again after a restart.
        for (const char* name : {"wayland-0", "wayland-1", "wayland-2"})
            if (socket_.empty() && std::filesystem::exists(directory_ / (std::string(name) + ".lock")) &&
                std::filesystem::exists(directory_ / name))
                socket_ = (directory_ / name).string();
        if (!socket_.empty() && sameImage(grab(), desktop))
            return;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    throw std::runtime_error("sway did not show its desktop within 20 s: " + process_->output());
}

cv::Mat WaylandCompositor::grab() const {
    const ProcessResult grim =
        runProcess({"/usr/bin/env", "WAYLAND_DISPLAY=" + socket_, "grim", "-t", "png", "-"});
    if (grim.exitCode != 0 || grim.out.empty())
        return {};
    const std::vector<uchar> png(grim.out.begin(), grim.out.end());
    return cv::imdecode(png, cv::IMREAD_COLOR);
}

}  // namespace everytouch::test

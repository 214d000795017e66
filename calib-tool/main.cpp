// everytouch-calib: calibrates everytouchd and shows its status, over D-Bus.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include <systemd/sd-bus.h>
#include <CLI/CLI.hpp>

#include "version.h"

namespace {

constexpr const char* kBusName = "org.everytouch.Daemon1";
constexpr const char* kObjectPath = "/org/everytouch/Daemon1";
constexpr const char* kInterface = "org.everytouch.Daemon1";

// Exit codes, as documented in --help.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitNotRunning = 3;

struct BusDeleter {
    void operator()(sd_bus* bus) const { sd_bus_flush_close_unref(bus); }
};
using Bus = std::unique_ptr<sd_bus, BusDeleter>;

struct ErrorGuard {
    sd_bus_error error = SD_BUS_ERROR_NULL;
    ~ErrorGuard() { sd_bus_error_free(&error); }
};

std::string readStringProperty(sd_bus* bus, const char* name, int& result) {
    ErrorGuard guard;
    char* value = nullptr;
    result = sd_bus_get_property_string(bus, kBusName, kObjectPath, kInterface, name, &guard.error, &value);
    std::string text = result >= 0 && value ? value : "";
    std::free(value);
    return text;
}

int status() {
    sd_bus* raw = nullptr;
    int r = sd_bus_open_system(&raw);
    Bus bus(raw);
    if (r < 0) {
        std::fprintf(stderr, "Cannot connect to the system bus: %s\n", std::strerror(-r));
        return kExitFailure;
    }
    r = sd_bus_get_name_creds(bus.get(), kBusName, 0, nullptr);
    if (r < 0) {
        std::fprintf(stderr,
                     "everytouchd is not running (no %s on the system bus). Start it with "
                     "\"systemctl start everytouchd\".\n",
                     kBusName);
        return kExitNotRunning;
    }
    const std::string state = readStringProperty(bus.get(), "State", r);
    if (r < 0) {
        std::fprintf(stderr, "everytouchd did not report its state: %s\n", std::strerror(-r));
        return kExitFailure;
    }
    const std::string rig = readStringProperty(bus.get(), "Rig", r);
    const std::string device = readStringProperty(bus.get(), "DevicePath", r);
    std::printf("State:  %s\nRig:    %s\nDevice: %s\n", state.c_str(), rig.c_str(),
                device.empty() ? "(none)" : device.c_str());
    return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"everytouch-calib - calibrate everytouchd and show its status (talks to it over D-Bus)"};
    app.set_version_flag("--version", std::string("everytouch-calib ") + everytouch::kVersion);
    app.footer("Exit status: 0 success, 1 failure, 2 bad usage, 3 everytouchd is not running.");
    app.require_subcommand(1);
    CLI::App* statusCommand = app.add_subcommand("status", "Show the daemon's state, rig and touch device");
    CLI11_PARSE(app, argc, argv);
    if (statusCommand->parsed())
        return status();
    return kExitFailure;
}

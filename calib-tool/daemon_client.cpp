#include "daemon_client.h"

#include <cerrno>
#include <cstring>

#include "service/bus_names.h"

namespace everytouch::calib {

namespace {

constexpr const char* kPropertiesInterface = "org.freedesktop.DBus.Properties";

Failure notRunning() {
    return {kExitNotRunning, std::string("everytouchd is not running (nobody owns ") + bus::kBusName +
                                 " on the system bus). Start it with \"systemctl start everytouchd\"."};
}

// Reads one variant of a GetAll reply.
std::optional<PropertyValue> readVariant(sd_bus_message* message) {
    char type = 0;
    const char* contents = nullptr;
    if (sd_bus_message_peek_type(message, &type, &contents) < 0 || !contents)
        return std::nullopt;
    const std::string signature = contents;
    if (signature == "s") {
        const char* text = nullptr;
        if (sd_bus_message_read(message, "v", "s", &text) >= 0)
            return std::string(text);
    } else if (signature == "b") {
        int value = 0;
        if (sd_bus_message_read(message, "v", "b", &value) >= 0)
            return value != 0;
    } else if (signature == "d") {
        double value = 0;
        if (sd_bus_message_read(message, "v", "d", &value) >= 0)
            return value;
    } else if (signature == "u") {
        std::uint32_t value = 0;
        if (sd_bus_message_read(message, "v", "u", &value) >= 0)
            return value;
    } else if (signature == "t") {
        std::uint64_t value = 0;
        if (sd_bus_message_read(message, "v", "t", &value) >= 0)
            return value;
    }
    sd_bus_message_skip(message, "v");
    return std::nullopt;
}

}  // namespace

std::variant<DaemonClient, Failure> DaemonClient::connect() {
    sd_bus* raw = nullptr;
    const int r = sd_bus_open_system(&raw);
    io::Bus bus(raw);
    if (r < 0)
        return Failure{kExitNotRunning,
                       std::string("Cannot connect to the system bus: ") + std::strerror(-r)};
    if (sd_bus_get_name_creds(bus.get(), bus::kBusName, 0, nullptr) < 0)
        return notRunning();
    return DaemonClient(std::move(bus));
}

Failure DaemonClient::explain(const io::UniqueBusError& error, int r, const std::string& action) {
    if (error.has(SD_BUS_ERROR_ACCESS_DENIED))
        return {kExitDenied, action + " needs root or membership in the \"" + bus::kPrivilegedGroup +
                                 "\" group (log in again after joining it)."};
    if (error.has(SD_BUS_ERROR_SERVICE_UNKNOWN) || error.has(SD_BUS_ERROR_NAME_HAS_NO_OWNER) ||
        error.has(SD_BUS_ERROR_NO_REPLY) || error.has(SD_BUS_ERROR_DISCONNECTED))
        return notRunning();
    if (error.has(SD_BUS_ERROR_INVALID_ARGS))
        return {kExitUsage, std::string(error.message()) + "."};
    if (error.has(bus::kErrorNotCalibrated))
        return {kExitFailure, std::string(error.message()) + ". Run \"everytouch-calib calibrate\" first."};
    if (error.has(bus::kErrorCalibrationFailed))
        return {kExitFailure, std::string("Calibration failed: ") + error.message() + "."};
    if (error.has(bus::kErrorBusy))
        return {kExitFailure, std::string("everytouchd is busy: ") + error.message() + "."};
    if (error.has(bus::kErrorNoCamera))
        return {kExitFailure, std::string("everytouchd gets no camera frames: ") + error.message() +
                                  ". Check the camera and \"journalctl -u everytouchd\"."};
    if (error.has(bus::kErrorInvalidConfig))
        return {kExitFailure, std::string(error.message()) + "."};
    if (error.name()[0] != '\0')
        return {kExitFailure, action + " failed: " + error.message() + "."};
    return {kExitFailure, action + " failed: " + std::strerror(-r) + "."};
}

std::variant<std::map<std::string, PropertyValue>, Failure> DaemonClient::allProperties() {
    io::UniqueBusError error;
    sd_bus_message* raw = nullptr;
    const int r = sd_bus_call_method(bus_.get(), bus::kBusName, bus::kObjectPath, kPropertiesInterface,
                                     "GetAll", error.get(), &raw, "s", bus::kInterface);
    const io::BusMessage reply(raw);
    if (r < 0)
        return explain(error, r, "Reading the status");
    std::map<std::string, PropertyValue> properties;
    if (sd_bus_message_enter_container(reply.get(), 'a', "{sv}") < 0)
        return Failure{kExitFailure, "everytouchd sent a malformed status."};
    while (sd_bus_message_enter_container(reply.get(), 'e', "sv") > 0) {
        const char* name = nullptr;
        if (sd_bus_message_read(reply.get(), "s", &name) < 0)
            return Failure{kExitFailure, "everytouchd sent a malformed status."};
        const std::string key = name;
        if (std::optional<PropertyValue> value = readVariant(reply.get()))
            properties[key] = *value;
        sd_bus_message_exit_container(reply.get());
    }
    return properties;
}

std::optional<Failure> DaemonClient::setTouchHeightMm(double heightMm) {
    io::UniqueBusError error;
    const int r = sd_bus_set_property(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                      "TouchHeightMm", error.get(), "d", heightMm);
    if (r < 0)
        return explain(error, r, "Setting the touch height");
    return std::nullopt;
}

std::optional<Failure> DaemonClient::snapshot(const std::string& what, int fd) {
    io::UniqueBusError error;
    const int r = sd_bus_call_method(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface, "Snapshot",
                                     error.get(), nullptr, "sh", what.c_str(), fd);
    if (r < 0)
        return explain(error, r, "Taking a snapshot");
    return std::nullopt;
}

std::optional<Failure> DaemonClient::saveCalibration() {
    io::UniqueBusError error;
    const int r = sd_bus_call_method(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                     "SaveCalibration", error.get(), nullptr, "");
    if (r < 0)
        return explain(error, r, "Saving the calibration");
    return std::nullopt;
}

namespace {

struct CalibrationFollower {
    const DaemonClient::ProgressHandler* onProgress = nullptr;
    std::optional<DaemonClient::CalibrationResult> result;
    bool daemonGone = false;
};

int onProgressSignal(sd_bus_message* message, void* userdata, sd_bus_error*) noexcept {
    auto* follower = static_cast<CalibrationFollower*>(userdata);
    const char* step = nullptr;
    const char* text = nullptr;
    double fraction = 0.0;
    try {
        if (sd_bus_message_read(message, "sds", &step, &fraction, &text) >= 0)
            (*follower->onProgress)(step, fraction, text);
    } catch (const std::exception&) {
        // A progress line that cannot be shown is not worth stopping the calibration for.
    }
    return 0;
}

int onFinishedSignal(sd_bus_message* message, void* userdata, sd_bus_error*) noexcept {
    auto* follower = static_cast<CalibrationFollower*>(userdata);
    int ok = 0;
    const char* text = nullptr;
    double rmsPx = 0.0;
    try {
        if (sd_bus_message_read(message, "bsd", &ok, &text, &rmsPx) >= 0)
            follower->result = DaemonClient::CalibrationResult{ok != 0, text, rmsPx};
    } catch (const std::exception&) {
        follower->daemonGone = true;  // out of memory: stop waiting rather than wait forever
    }
    return 0;
}

int onOwnerChanged(sd_bus_message* message, void* userdata, sd_bus_error*) noexcept {
    const char* name = nullptr;
    const char* oldOwner = nullptr;
    const char* newOwner = nullptr;
    // Matched on arg0, so `name` is everytouchd's; an empty new owner means it left the bus.
    if (sd_bus_message_read(message, "sss", &name, &oldOwner, &newOwner) >= 0 && newOwner[0] == '\0')
        static_cast<CalibrationFollower*>(userdata)->daemonGone = true;
    return 0;
}

}  // namespace

std::variant<DaemonClient::CalibrationResult, Failure> DaemonClient::calibrate(
    const std::string& step, const CalibrationOptions& options, const ProgressHandler& onProgress) {
    CalibrationFollower follower;
    follower.onProgress = &onProgress;
    sd_bus_slot* raw = nullptr;
    // Subscribe before calling, so that no signal of this job can slip past.
    int r = sd_bus_match_signal(bus_.get(), &raw, bus::kBusName, bus::kObjectPath, bus::kInterface,
                                "CalibrationProgress", onProgressSignal, &follower);
    const io::BusSlot progressSlot(raw);
    if (r >= 0)
        r = sd_bus_match_signal(bus_.get(), &raw, bus::kBusName, bus::kObjectPath, bus::kInterface,
                                "CalibrationFinished", onFinishedSignal, &follower);
    const io::BusSlot finishedSlot(r >= 0 ? raw : nullptr);
    if (r >= 0)
        r = sd_bus_add_match(bus_.get(), &raw,
                             "type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
                             "interface='org.freedesktop.DBus',member='NameOwnerChanged',"
                             "arg0='" EVERYTOUCH_BUS_ROOT "'",
                             onOwnerChanged, &follower);
    const io::BusSlot ownerSlot(r >= 0 ? raw : nullptr);
    if (r < 0)
        return Failure{kExitFailure,
                       std::string("Cannot follow the calibration: ") + std::strerror(-r) + "."};

    sd_bus_message* call = nullptr;
    r = sd_bus_message_new_method_call(bus_.get(), &call, bus::kBusName, bus::kObjectPath, bus::kInterface,
                                       "Calibrate");
    const io::BusMessage message(call);
    if (r >= 0)
        r = sd_bus_message_append(message.get(), "s", step.c_str());
    if (r >= 0)
        r = sd_bus_message_open_container(message.get(), 'a', "{sv}");
    if (r >= 0 && options.frames)
        r = sd_bus_message_append(message.get(), "{sv}", "frames", "u", *options.frames);
    if (r >= 0 && options.cardWidthMm)
        r = sd_bus_message_append(message.get(), "{sv}", "card_width_mm", "d", *options.cardWidthMm);
    if (r >= 0 && options.cardHeightMm)
        r = sd_bus_message_append(message.get(), "{sv}", "card_height_mm", "d", *options.cardHeightMm);
    if (r >= 0 && options.views)
        r = sd_bus_message_append(message.get(), "{sv}", "views", "u", *options.views);
    if (r >= 0 && options.viewTimeoutS)
        r = sd_bus_message_append(message.get(), "{sv}", "view_timeout_s", "d", *options.viewTimeoutS);
    if (r >= 0)
        r = sd_bus_message_close_container(message.get());
    io::UniqueBusError error;
    if (r >= 0)
        r = sd_bus_call(bus_.get(), message.get(), 0, error.get(), nullptr);
    if (r < 0)
        return explain(error, r, "Calibrating");

    while (!follower.result && !follower.daemonGone) {
        r = sd_bus_process(bus_.get(), nullptr);
        if (r < 0)
            return Failure{kExitFailure, std::string("Lost everytouchd: ") + std::strerror(-r) + "."};
        if (r > 0)
            continue;
        r = sd_bus_wait(bus_.get(), UINT64_MAX);
        if (r < 0 && r != -EINTR)
            return Failure{kExitFailure, std::string("Lost everytouchd: ") + std::strerror(-r) + "."};
    }
    if (!follower.result)
        return Failure{kExitFailure,
                       "everytouchd stopped during the calibration; the previous calibration "
                       "is kept. See \"journalctl -u everytouchd\"."};
    return *follower.result;
}

}  // namespace everytouch::calib

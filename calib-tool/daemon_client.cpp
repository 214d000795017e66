#include "daemon_client.h"

#include <sys/signalfd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>

#include "service/bus_names.h"

namespace everytouch::calib {

namespace {

// The bus's signal that the daemon's name changed owner: it started, or it left the bus.
constexpr const char* kDaemonOwnerChanged =
    "type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
    "interface='org.freedesktop.DBus',member='NameOwnerChanged',arg0='" EVERYTOUCH_BUS_ROOT "'";

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

std::variant<DaemonClient::Display, Failure> DaemonClient::display() {
    Display display;
    io::UniqueBusError error;
    sd_bus_message* raw = nullptr;
    int r = sd_bus_get_property(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                bus::kPropertyDisplaySize, error.get(), &raw, "(uu)");
    io::BusMessage size(raw);
    if (r >= 0)
        r = sd_bus_message_read(size.get(), "(uu)", &display.widthPx, &display.heightPx);
    if (r >= 0) {
        raw = nullptr;
        r = sd_bus_get_property(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                bus::kPropertyDisplaySizeMm, error.get(), &raw, "(dd)");
        size.reset(raw);
    }
    if (r >= 0)
        r = sd_bus_message_read(size.get(), "(dd)", &display.widthMm, &display.heightMm);
    if (r < 0)
        return explain(error, r, "Reading the display's size");
    return display;
}

std::optional<Failure> DaemonClient::setTouchHeightMm(double heightMm) {
    io::UniqueBusError error;
    const int r = sd_bus_set_property(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                      bus::kPropertyTouchHeightMm, error.get(), "d", heightMm);
    if (r < 0)
        return explain(error, r, "Setting the touch height");
    return std::nullopt;
}

std::optional<Failure> DaemonClient::snapshot(const std::string& what, int fd) {
    io::UniqueBusError error;
    const int r = sd_bus_call_method(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                     bus::kMethodSnapshot, error.get(), nullptr, "sh", what.c_str(), fd);
    if (r < 0)
        return explain(error, r, "Taking a snapshot");
    return std::nullopt;
}

std::optional<Failure> DaemonClient::saveCalibration() {
    io::UniqueBusError error;
    const int r = sd_bus_call_method(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                     bus::kMethodSaveCalibration, error.get(), nullptr, "");
    if (r < 0)
        return explain(error, r, "Saving the calibration");
    return std::nullopt;
}

std::optional<Failure> DaemonClient::showAccuracyTargets(bool show) {
    io::UniqueBusError error;
    const int r = sd_bus_call_method(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                     bus::kMethodShowAccuracyTargets, error.get(), nullptr, "b", show);
    if (r < 0)
        return explain(error, r,
                       show ? "Showing the accuracy test's circles" : "Hiding the accuracy test's circles");
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
                                bus::kSignalCalibrationProgress, onProgressSignal, &follower);
    const io::BusSlot progressSlot(raw);
    if (r >= 0)
        r = sd_bus_match_signal(bus_.get(), &raw, bus::kBusName, bus::kObjectPath, bus::kInterface,
                                bus::kSignalCalibrationFinished, onFinishedSignal, &follower);
    const io::BusSlot finishedSlot(r >= 0 ? raw : nullptr);
    if (r >= 0)
        r = sd_bus_add_match(bus_.get(), &raw, kDaemonOwnerChanged, onOwnerChanged, &follower);
    const io::BusSlot ownerSlot(r >= 0 ? raw : nullptr);
    if (r < 0)
        return Failure{kExitFailure,
                       std::string("Cannot follow the calibration: ") + std::strerror(-r) + "."};

    sd_bus_message* call = nullptr;
    r = sd_bus_message_new_method_call(bus_.get(), &call, bus::kBusName, bus::kObjectPath, bus::kInterface,
                                       bus::kMethodCalibrate);
    const io::BusMessage message(call);
    if (r >= 0)
        r = sd_bus_message_append(message.get(), "s", step.c_str());
    if (r >= 0)
        r = sd_bus_message_open_container(message.get(), 'a', "{sv}");
    if (r >= 0 && options.frames)
        r = sd_bus_message_append(message.get(), "{sv}", bus::kOptionFrames, "u", *options.frames);
    if (r >= 0 && options.cardWidthMm)
        r = sd_bus_message_append(message.get(), "{sv}", bus::kOptionCardWidthMm, "d", *options.cardWidthMm);
    if (r >= 0 && options.cardHeightMm)
        r = sd_bus_message_append(message.get(), "{sv}", bus::kOptionCardHeightMm, "d",
                                  *options.cardHeightMm);
    if (r >= 0 && options.views)
        r = sd_bus_message_append(message.get(), "{sv}", bus::kOptionViews, "u", *options.views);
    if (r >= 0 && options.viewTimeoutS)
        r = sd_bus_message_append(message.get(), "{sv}", bus::kOptionViewTimeoutS, "d",
                                  *options.viewTimeoutS);
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

namespace {

constexpr std::uint64_t kFrameRateIntervalUsec = 1'000'000;

// What the callbacks of followContacts leave for its loop; they only record, and never throw.
struct ContactsFollower {
    enum class End { None, Done, DaemonGone, Malformed, OutOfMemory };
    struct Received {
        double seconds = 0.0;
        std::vector<ContactReading> contacts;
    };

    double secondsSinceStart() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    sd_bus* bus = nullptr;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    std::optional<std::uint64_t> count;
    std::uint64_t signals = 0;
    std::vector<Received> received;  // Contacts signals not yet handed over
    double frameRate = 0.0;
    bool frameRateRead = false;  // a new frame rate not yet handed over
    io::BusSlot frameRateCall;   // the last Get of FrameRate
    bool frameRateCallPending = false;
    End end = End::None;
};

int readContacts(sd_bus_message* message, std::vector<ContactReading>& contacts) {
    int r = sd_bus_message_enter_container(message, 'a', "(uddbd)");
    while (r >= 0) {
        ContactReading contact;
        int touching = 0;
        r = sd_bus_message_read(message, "(uddbd)", &contact.id, &contact.x, &contact.y, &touching,
                                &contact.heightMm);
        if (r <= 0)
            break;
        contact.touching = touching != 0;
        contacts.push_back(contact);
    }
    return r < 0 ? r : sd_bus_message_exit_container(message);
}

int onContactsSignal(sd_bus_message* message, void* userdata, sd_bus_error*) noexcept {
    auto* follower = static_cast<ContactsFollower*>(userdata);
    if (follower->end != ContactsFollower::End::None)
        return 0;
    try {
        ContactsFollower::Received received{follower->secondsSinceStart(), {}};
        if (readContacts(message, received.contacts) < 0) {
            follower->end = ContactsFollower::End::Malformed;
            return 0;
        }
        follower->received.push_back(std::move(received));
    } catch (const std::exception&) {
        follower->end = ContactsFollower::End::OutOfMemory;
        return 0;
    }
    if (follower->count && ++follower->signals >= *follower->count)
        follower->end = ContactsFollower::End::Done;
    return 0;
}

int onFrameRateReply(sd_bus_message* reply, void* userdata, sd_bus_error*) noexcept {
    auto* follower = static_cast<ContactsFollower*>(userdata);
    follower->frameRateCallPending = false;
    double frameRate = 0.0;
    // An error means the daemon is going; its NameOwnerChanged says so.
    if (!sd_bus_message_is_method_error(reply, nullptr) &&
        sd_bus_message_read(reply, "v", "d", &frameRate) >= 0) {
        follower->frameRate = frameRate;
        follower->frameRateRead = true;
    }
    return 0;
}

// Asks for the frame rate once a second (the property does not signal its changes).
int onFrameRateTimer(sd_event_source* source, std::uint64_t, void* userdata) noexcept {
    auto* follower = static_cast<ContactsFollower*>(userdata);
    if (!follower->frameRateCallPending) {
        sd_bus_slot* raw = nullptr;
        if (sd_bus_call_method_async(follower->bus, &raw, bus::kBusName, bus::kObjectPath,
                                     kPropertiesInterface, "Get", onFrameRateReply, follower, "ss",
                                     bus::kInterface, bus::kPropertyFrameRate) >= 0) {
            follower->frameRateCall.reset(raw);
            follower->frameRateCallPending = true;
        }
    }
    sd_event_source_set_time_relative(source, kFrameRateIntervalUsec);
    return sd_event_source_set_enabled(source, SD_EVENT_ONESHOT);
}

int onDeadline(sd_event_source*, std::uint64_t, void* userdata) noexcept {
    auto* follower = static_cast<ContactsFollower*>(userdata);
    if (follower->end == ContactsFollower::End::None)
        follower->end = ContactsFollower::End::Done;
    return 0;
}

int onStopSignal(sd_event_source*, const signalfd_siginfo*, void* userdata) noexcept {
    auto* follower = static_cast<ContactsFollower*>(userdata);
    if (follower->end == ContactsFollower::End::None)
        follower->end = ContactsFollower::End::Done;
    return 0;
}

int onDaemonOwnerChanged(sd_bus_message* message, void* userdata, sd_bus_error*) noexcept {
    const char* name = nullptr;
    const char* oldOwner = nullptr;
    const char* newOwner = nullptr;
    // Matched on arg0, so `name` is everytouchd's; an empty new owner means it left the bus.
    if (sd_bus_message_read(message, "sss", &name, &oldOwner, &newOwner) >= 0 && newOwner[0] == '\0')
        static_cast<ContactsFollower*>(userdata)->end = ContactsFollower::End::DaemonGone;
    return 0;
}

// Takes the bus off an event loop when it goes; the bus itself stays open.
using EventAttachment = io::UniqueHandle<sd_bus, sd_bus_detach_event>;

Failure cannotFollow(int r) {
    return {kExitFailure, std::string("Cannot follow the contacts: ") + std::strerror(-r) + "."};
}

}  // namespace

std::optional<Failure> DaemonClient::followContacts(const ContactsOptions& options,
                                                    const ContactsHandler& onUpdate) {
    ContactsFollower follower;
    follower.bus = bus_.get();
    follower.count = options.count;

    // Subscribe first, then read the frame rate: that reply also shows that the daemon is still there.
    sd_bus_slot* rawSlot = nullptr;
    int r = sd_bus_match_signal(bus_.get(), &rawSlot, bus::kBusName, bus::kObjectPath, bus::kInterface,
                                bus::kSignalContacts, onContactsSignal, &follower);
    const io::BusSlot contactsSlot(r >= 0 ? rawSlot : nullptr);
    if (r >= 0)
        r = sd_bus_add_match(bus_.get(), &rawSlot, kDaemonOwnerChanged, onDaemonOwnerChanged, &follower);
    const io::BusSlot ownerSlot(r >= 0 ? rawSlot : nullptr);
    if (r < 0)
        return cannotFollow(r);
    io::UniqueBusError error;
    r = sd_bus_get_property_trivial(bus_.get(), bus::kBusName, bus::kObjectPath, bus::kInterface,
                                    bus::kPropertyFrameRate, error.get(), 'd', &follower.frameRate);
    if (r < 0)
        return explain(error, r, "Reading the frame rate");

    sd_event* rawEvent = nullptr;
    r = sd_event_new(&rawEvent);
    const io::Event event(r >= 0 ? rawEvent : nullptr);
    if (r < 0)
        return cannotFollow(r);
    std::vector<io::EventSource> sources;
    sd_event_source* rawSource = nullptr;
    // SD_EVENT_SIGNAL_PROCMASK blocks the signal while the source lives, then restores the mask.
    for (const int signal : {SIGINT, SIGTERM}) {
        if ((r = sd_event_add_signal(event.get(), &rawSource, signal | SD_EVENT_SIGNAL_PROCMASK, onStopSignal,
                                     &follower)) < 0)
            return cannotFollow(r);
        sources.emplace_back(rawSource);
    }
    if ((r = sd_event_add_time_relative(event.get(), &rawSource, CLOCK_MONOTONIC, kFrameRateIntervalUsec, 0,
                                        onFrameRateTimer, &follower)) < 0)
        return cannotFollow(r);
    sources.emplace_back(rawSource);
    if (options.durationS) {
        const auto usec = static_cast<std::uint64_t>(*options.durationS * 1e6);
        if ((r = sd_event_add_time_relative(event.get(), &rawSource, CLOCK_MONOTONIC, usec, 0, onDeadline,
                                            &follower)) < 0)
            return cannotFollow(r);
        sources.emplace_back(rawSource);
    }
    if ((r = sd_bus_attach_event(bus_.get(), event.get(), SD_EVENT_PRIORITY_NORMAL)) < 0)
        return cannotFollow(r);
    const EventAttachment attachment(bus_.get());

    // Hands over what the callbacks recorded, here and not inside them, so that the handler may throw.
    ContactsUpdate update;
    update.frameRate = follower.frameRate;
    bool following = onUpdate(update);
    while (following) {
        for (ContactsFollower::Received& received : follower.received) {
            update.seconds = received.seconds;
            update.contactsChanged = true;
            update.contacts = std::move(received.contacts);
            update.frameRate = follower.frameRate;
            if (!(following = onUpdate(update)))
                break;
        }
        follower.received.clear();
        if (following && follower.frameRateRead) {
            follower.frameRateRead = false;
            update.seconds = follower.secondsSinceStart();
            update.contactsChanged = false;
            update.frameRate = follower.frameRate;
            following = onUpdate(update);
        }
        if (!following || follower.end != ContactsFollower::End::None)
            break;
        r = sd_event_run(event.get(), UINT64_MAX);
        if (r < 0)
            return cannotFollow(r);
        if (sd_bus_is_open(bus_.get()) <= 0)
            return Failure{kExitFailure, "Lost the connection to the system bus."};
    }
    switch (follower.end) {
        case ContactsFollower::End::DaemonGone:
            return Failure{
                kExitNotRunning,
                "everytouchd stopped (it left the system bus); see \"journalctl -u everytouchd\"."};
        case ContactsFollower::End::Malformed:
            return Failure{kExitFailure, "everytouchd sent a malformed Contacts signal."};
        case ContactsFollower::End::OutOfMemory:
            return Failure{kExitFailure, "Out of memory."};
        default:
            return std::nullopt;
    }
}

}  // namespace everytouch::calib

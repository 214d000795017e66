#include "service/bus_service.h"

#include <cerrno>
#include <cstring>
#include <exception>

#include "io/log.h"
#include "service/bus_error.h"
#include "service/bus_names.h"
#include "service/calibrate_options.h"
#include "service/daemon.h"

namespace everytouch::service {

namespace {

BusService& serviceOf(void* userdata) {
    return *static_cast<BusService*>(userdata);
}

// Runs a callback body; a BusError becomes its error reply, anything else a logged internal error.
template <typename Body>
int guarded(sd_bus_error* error, Body&& body) noexcept {
    try {
        return body();
    } catch (const BusError& failure) {
        return sd_bus_error_set(error, failure.name(), failure.what());
    } catch (const std::exception& failure) {
        ET_LOG(Error) << "internal error: " << failure.what();
        return sd_bus_error_set(error, SD_BUS_ERROR_FAILED, failure.what());
    } catch (...) {
        return sd_bus_error_set(error, SD_BUS_ERROR_FAILED, "internal error");
    }
}

int getApiVersion(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void*,
                  sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "u", bus::kApiVersion);
}

int getState(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
             sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "s", toString(serviceOf(userdata).daemon().state()));
}

int getStateReason(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                   sd_bus_error*) noexcept {
    try {
        return sd_bus_message_append(reply, "s", serviceOf(userdata).daemon().stateReason().c_str());
    } catch (const std::exception&) {
        return -ENOMEM;
    }
}

int getRig(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
           sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "s", serviceOf(userdata).daemon().rig().c_str());
}

int getProjector(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                 sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "s", serviceOf(userdata).daemon().projector().c_str());
}

int getCalibrated(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                  sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "b", static_cast<int>(serviceOf(userdata).daemon().calibrated()));
}

// The display the touches are reported in, pixels; (0, 0) when not calibrated.
int getDisplaySize(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                   sd_bus_error*) noexcept {
    const std::optional<core::Calibration>& calibration = serviceOf(userdata).daemon().activeCalibration();
    const cv::Size size = calibration ? calibration->displaySize : cv::Size();
    return sd_bus_message_append(reply, "(uu)", static_cast<std::uint32_t>(size.width),
                                 static_cast<std::uint32_t>(size.height));
}

// The display's width and height on the table, mm (the mean of opposite sides); (0, 0) when not calibrated.
int getDisplaySizeMm(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                     sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        const std::optional<core::Calibration>& calibration =
            serviceOf(userdata).daemon().activeCalibration();
        const cv::Size2d sizeMm = calibration ? calibration->displaySizeMm() : cv::Size2d();
        return sd_bus_message_append(reply, "(dd)", sizeMm.width, sizeMm.height);
    });
}

int getFrameRate(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                 sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "d", serviceOf(userdata).daemon().statistics().frameRate);
}

int getLatencyMs(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                 sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "d", serviceOf(userdata).daemon().statistics().latencyMs);
}

int getDroppedFrames(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                     sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "t", serviceOf(userdata).daemon().statistics().dropped);
}

int getCalibrationErrorPx(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply,
                          void* userdata, sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "d", serviceOf(userdata).daemon().statistics().calibrationErrorPx);
}

int getTouchHeightMm(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                     sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "d", serviceOf(userdata).daemon().touchHeightMm());
}

int setTouchHeightMm(sd_bus* bus, const char*, const char*, const char*, sd_bus_message* value,
                     void* userdata, sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        BusService& service = serviceOf(userdata);
        service.requirePrivileged(sd_bus_get_current_message(bus), "Setting TouchHeightMm");
        double heightMm = 0.0;
        checkBusCall(sd_bus_message_read(value, "d", &heightMm), bus::kPropertyTouchHeightMm);
        service.daemon().setTouchHeightMm(heightMm);
        return 0;
    });
}

int getDevicePath(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata,
                  sd_bus_error*) noexcept {
    return sd_bus_message_append(reply, "s", serviceOf(userdata).daemon().devicePath().c_str());
}

int methodCalibrate(sd_bus_message* message, void* userdata, sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        BusService& service = serviceOf(userdata);
        service.requirePrivileged(message, "Calibrating");
        const char* step = nullptr;
        checkBusCall(sd_bus_message_read(message, "s", &step), "Calibrate step");
        const CalibrationOptions options = readCalibrationOptions(message);
        service.daemon().calibrate(step, options);
        return sd_bus_reply_method_return(message, nullptr);
    });
}

int methodSaveCalibration(sd_bus_message* message, void* userdata, sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        BusService& service = serviceOf(userdata);
        service.requirePrivileged(message, "Saving the calibration");
        service.daemon().saveCalibration();
        return sd_bus_reply_method_return(message, nullptr);
    });
}

int methodResetCalibration(sd_bus_message* message, void* userdata, sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        BusService& service = serviceOf(userdata);
        service.requirePrivileged(message, "Resetting the calibration");
        service.daemon().resetCalibration();
        return sd_bus_reply_method_return(message, nullptr);
    });
}

int methodReloadConfig(sd_bus_message* message, void* userdata, sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        BusService& service = serviceOf(userdata);
        service.requirePrivileged(message, "Reloading the configuration");
        service.daemon().reloadConfig();
        return sd_bus_reply_method_return(message, nullptr);
    });
}

int methodSnapshot(sd_bus_message* message, void* userdata, sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        BusService& service = serviceOf(userdata);
        // Camera images show whatever lies on the table and whoever sits at it.
        service.requirePrivileged(message, "Taking a snapshot");
        const char* what = nullptr;
        int fd = -1;
        checkBusCall(sd_bus_message_read(message, "sh", &what, &fd), "Snapshot arguments");
        service.daemon().snapshot(message, what, fd);
        return 1;  // the reply follows once a frame pair has been written
    });
}

int methodShowAccuracyTargets(sd_bus_message* message, void* userdata, sd_bus_error* error) noexcept {
    return guarded(error, [&] {
        BusService& service = serviceOf(userdata);
        service.requirePrivileged(message, "Showing the accuracy test's circles");
        int show = 0;
        checkBusCall(sd_bus_message_read(message, "b", &show), "ShowAccuracyTargets show");
        service.showAccuracyTargets(message, show != 0);
        return sd_bus_reply_method_return(message, nullptr);
    });
}

int onAccuracyTargetsClientGone(sd_bus_track* /*track*/, void* userdata) noexcept {
    serviceOf(userdata).daemon().hideAccuracyTargets();
    return 0;
}

const sd_bus_vtable kVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_PROPERTY(bus::kPropertyApiVersion, "u", getApiVersion, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY(bus::kPropertyState, "s", getState, 0, SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE),
    SD_BUS_PROPERTY(bus::kPropertyStateReason, "s", getStateReason, 0, SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE),
    SD_BUS_PROPERTY(bus::kPropertyRig, "s", getRig, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY(bus::kPropertyProjector, "s", getProjector, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY(bus::kPropertyCalibrated, "b", getCalibrated, 0, SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE),
    // Statistics change with every frame: clients poll them instead of being flooded with signals.
    SD_BUS_PROPERTY(bus::kPropertyDisplaySize, "(uu)", getDisplaySize, 0, 0),
    SD_BUS_PROPERTY(bus::kPropertyDisplaySizeMm, "(dd)", getDisplaySizeMm, 0, 0),
    SD_BUS_PROPERTY(bus::kPropertyFrameRate, "d", getFrameRate, 0, 0),
    SD_BUS_PROPERTY(bus::kPropertyLatencyMs, "d", getLatencyMs, 0, 0),
    SD_BUS_PROPERTY(bus::kPropertyDroppedFrames, "t", getDroppedFrames, 0, 0),
    SD_BUS_PROPERTY(bus::kPropertyCalibrationErrorPx, "d", getCalibrationErrorPx, 0, 0),
    SD_BUS_WRITABLE_PROPERTY(bus::kPropertyTouchHeightMm, "d", getTouchHeightMm, setTouchHeightMm, 0,
                             SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE | SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_PROPERTY(bus::kPropertyDevicePath, "s", getDevicePath, 0, SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE),
    SD_BUS_METHOD_WITH_ARGS(bus::kMethodCalibrate, SD_BUS_ARGS("s", step, "a{sv}", options), SD_BUS_NO_RESULT,
                            methodCalibrate, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_METHOD_WITH_ARGS(bus::kMethodSaveCalibration, SD_BUS_NO_ARGS, SD_BUS_NO_RESULT,
                            methodSaveCalibration, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_METHOD_WITH_ARGS(bus::kMethodResetCalibration, SD_BUS_NO_ARGS, SD_BUS_NO_RESULT,
                            methodResetCalibration, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_METHOD_WITH_ARGS(bus::kMethodReloadConfig, SD_BUS_NO_ARGS, SD_BUS_NO_RESULT, methodReloadConfig,
                            SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_METHOD_WITH_ARGS(bus::kMethodSnapshot, SD_BUS_ARGS("s", what, "h", fd), SD_BUS_NO_RESULT,
                            methodSnapshot, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_METHOD_WITH_ARGS(bus::kMethodShowAccuracyTargets, SD_BUS_ARGS("b", show), SD_BUS_NO_RESULT,
                            methodShowAccuracyTargets, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_SIGNAL_WITH_ARGS(bus::kSignalContacts, SD_BUS_ARGS("a(uddbd)", contacts), 0),
    SD_BUS_SIGNAL_WITH_ARGS(bus::kSignalCalibrationProgress,
                            SD_BUS_ARGS("s", step, "d", fraction, "s", message), 0),
    SD_BUS_SIGNAL_WITH_ARGS(bus::kSignalCalibrationFinished, SD_BUS_ARGS("b", ok, "s", message, "d", rms_px),
                            0),
    SD_BUS_SIGNAL_WITH_ARGS(bus::kSignalCalibrationCorrected,
                            SD_BUS_ARGS("d", before_px, "d", after_px, "s", what), 0),
    SD_BUS_VTABLE_END,
};

}  // namespace

BusService::BusService(Daemon& daemon) : daemon_(daemon), authorization_(bus::kPrivilegedGroup) {}

int BusService::connect(sd_event* event, std::string& failedStep) {
    sd_bus* bus = nullptr;
    int r = sd_bus_open_system(&bus);
    bus_.reset(bus);
    if (r < 0) {
        failedStep = "connect to the system bus";
        return r;
    }
    // If the bus goes away, so does the daemon; systemd restarts it and it reconnects.
    if ((r = sd_bus_set_exit_on_disconnect(bus_.get(), 1)) < 0 ||
        (r = sd_bus_attach_event(bus_.get(), event, SD_EVENT_PRIORITY_NORMAL)) < 0) {
        failedStep = "attach the bus to the event loop";
        return r;
    }
    sd_bus_slot* slot = nullptr;
    r = sd_bus_add_object_vtable(bus_.get(), &slot, bus::kObjectPath, bus::kInterface, kVtable, this);
    objectSlot_.reset(slot);
    if (r < 0) {
        failedStep = "publish " + std::string(bus::kObjectPath);
        return r;
    }
    if ((r = sd_bus_request_name(bus_.get(), bus::kBusName, 0)) < 0) {
        failedStep = "own the bus name " + std::string(bus::kBusName);
        return r;
    }
    if (!authorization_.groupExists())
        ET_LOG(Notice) << "there is no group \"" << authorization_.groupName()
                       << "\": only root may calibrate or change settings";
    return 0;
}

void BusService::showAccuracyTargets(sd_bus_message* call, bool show) {
    accuracyTargetsClient_.reset();
    if (!show) {
        daemon_.hideAccuracyTargets();
        return;
    }
    daemon_.showAccuracyTargets();
    // The circles go when the client that asked for them leaves the bus, however it ends.
    sd_bus_track* track = nullptr;
    int r = sd_bus_track_new(sd_bus_message_get_bus(call), &track, onAccuracyTargetsClientGone, this);
    io::BusTrack owned(track);
    if (r < 0 || (r = sd_bus_track_add_sender(track, call)) < 0) {
        daemon_.hideAccuracyTargets();
        checkBusCall(r, "following the client that shows the accuracy test's circles");
    }
    accuracyTargetsClient_ = std::move(owned);
}

void BusService::requirePrivileged(sd_bus_message* message, const char* action) const {
    const int r = authorization_.check(message);
    if (r < 0)
        throw BusError(SD_BUS_ERROR_ACCESS_DENIED,
                       std::string("Cannot check the caller's credentials: ") + std::strerror(-r));
    if (r == 0)
        throw BusError(SD_BUS_ERROR_ACCESS_DENIED, std::string(action) +
                                                       " needs root or membership in the \"" +
                                                       authorization_.groupName() + "\" group");
}

void BusService::propertiesChanged(const std::vector<const char*>& names) {
    std::vector<char*> list;
    for (const char* name : names)
        list.push_back(const_cast<char*>(name));
    list.push_back(nullptr);
    const int r =
        sd_bus_emit_properties_changed_strv(bus_.get(), bus::kObjectPath, bus::kInterface, list.data());
    if (r < 0)
        ET_LOG(Warning) << "cannot signal changed properties: " << std::strerror(-r);
}

void BusService::contacts(const core::Contacts& contacts) {
    sd_bus_message* raw = nullptr;
    int r =
        sd_bus_message_new_signal(bus_.get(), &raw, bus::kObjectPath, bus::kInterface, bus::kSignalContacts);
    const io::BusMessage signal(raw);
    if (r >= 0)
        r = sd_bus_message_open_container(signal.get(), 'a', "(uddbd)");
    for (const core::Contact& contact : contacts)
        if (r >= 0)
            r = sd_bus_message_append(signal.get(), "(uddbd)", contact.id, contact.x, contact.y,
                                      static_cast<int>(contact.touching), contact.heightMm);
    if (r >= 0)
        r = sd_bus_message_close_container(signal.get());
    if (r >= 0)
        r = sd_bus_send(bus_.get(), signal.get(), nullptr);
    if (r < 0)
        ET_LOG(Warning) << "cannot send the Contacts signal: " << std::strerror(-r);
}

void BusService::calibrationProgress(const std::string& step, double fraction, const std::string& message) {
    const int r =
        sd_bus_emit_signal(bus_.get(), bus::kObjectPath, bus::kInterface, bus::kSignalCalibrationProgress,
                           "sds", step.c_str(), fraction, message.c_str());
    if (r < 0)
        ET_LOG(Warning) << "cannot send CalibrationProgress: " << std::strerror(-r);
}

void BusService::calibrationFinished(bool ok, const std::string& message, double rmsPx) {
    const int r =
        sd_bus_emit_signal(bus_.get(), bus::kObjectPath, bus::kInterface, bus::kSignalCalibrationFinished,
                           "bsd", static_cast<int>(ok), message.c_str(), rmsPx);
    if (r < 0)
        ET_LOG(Warning) << "cannot send CalibrationFinished: " << std::strerror(-r);
}

void BusService::calibrationCorrected(double beforePx, double afterPx, const std::string& what) {
    const int r =
        sd_bus_emit_signal(bus_.get(), bus::kObjectPath, bus::kInterface, bus::kSignalCalibrationCorrected,
                           "dds", beforePx, afterPx, what.c_str());
    if (r < 0)
        ET_LOG(Warning) << "cannot send CalibrationCorrected: " << std::strerror(-r);
}

void BusService::reply(sd_bus_message* call) {
    const int r = sd_bus_reply_method_return(call, nullptr);
    if (r < 0)
        ET_LOG(Debug) << "cannot reply to " << sd_bus_message_get_sender(call) << ": " << std::strerror(-r);
}

void BusService::replyError(sd_bus_message* call, const char* name, const std::string& message) {
    const int r = sd_bus_reply_method_errorf(call, name, "%s", message.c_str());
    if (r < 0)
        ET_LOG(Debug) << "cannot reply to " << sd_bus_message_get_sender(call) << ": " << std::strerror(-r);
}

}  // namespace everytouch::service

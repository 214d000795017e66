#pragma once

#include <string>
#include <vector>

#include <systemd/sd-bus.h>
#include <systemd/sd-event.h>

#include "core/contact.h"
#include "io/handles.h"
#include "service/sender_authorization.h"

namespace everytouch::service {

class Daemon;

// The daemon's face on the system bus: the org.everytouch.Daemon1 object (docs/architecture.md, "D-Bus
// interface"). It parses arguments, checks who may change state, and turns the daemon's BusErrors into error
// replies. Main thread only.
class BusService {
public:
    explicit BusService(Daemon& daemon);

    // Connects to the system bus on `event`, publishes the object and takes the bus name. Returns 0 or a
    // negative errno; then `failedStep` says what could not be done.
    int connect(sd_event* event, std::string& failedStep);

    void propertiesChanged(const std::vector<const char*>& names);
    void contacts(const core::Contacts& contacts);
    void calibrationProgress(const std::string& step, double fraction, const std::string& message);
    void calibrationFinished(bool ok, const std::string& message, double rmsPx);
    void calibrationCorrected(double beforePx, double afterPx, const std::string& what);

    // Answers a method call the daemon kept for later.
    void reply(sd_bus_message* call);
    void replyError(sd_bus_message* call, const char* name, const std::string& message);

    // Shows the accuracy test's circles for the sender of `call` until it asks to hide them or leaves the
    // bus, or hides them. Throws BusError.
    void showAccuracyTargets(sd_bus_message* call, bool show);
    // Throws BusError(AccessDenied) unless the sender of `message` may change the daemon's state.
    void requirePrivileged(sd_bus_message* message, const char* action) const;

    Daemon& daemon() { return daemon_; }

private:
    Daemon& daemon_;
    SenderAuthorization authorization_;
    io::Bus bus_;
    io::BusSlot objectSlot_;
    io::BusTrack accuracyTargetsClient_;  // who asked for the accuracy test's circles
};

}  // namespace everytouch::service

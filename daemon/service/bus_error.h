#pragma once

#include <cstring>
#include <stdexcept>
#include <string>

#include <systemd/sd-bus.h>

namespace everytouch::service {

// What the bus-facing operations throw; the bus turns it into an error reply with this name.
class BusError : public std::runtime_error {
public:
    BusError(const char* name, const std::string& message) : std::runtime_error(message), name_(name) {}
    const char* name() const { return name_; }

private:
    const char* name_;
};

// For sd-bus calls that read a client's message: a failure (negative errno) means the message does not hold
// what it should, and `what` names the part.
inline void checkBusCall(int r, const char* what) {
    if (r < 0)
        throw BusError(SD_BUS_ERROR_INVALID_ARGS, std::string(what) + ": " + std::strerror(-r));
}

}  // namespace everytouch::service

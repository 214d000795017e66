#pragma once

#include <stdexcept>
#include <string>

namespace everytouch::service {

// What the bus-facing operations throw; the bus turns it into an error reply with this name.
class BusError : public std::runtime_error {
public:
    BusError(const char* name, const std::string& message) : std::runtime_error(message), name_(name) {}
    const char* name() const { return name_; }

private:
    const char* name_;
};

}  // namespace everytouch::service

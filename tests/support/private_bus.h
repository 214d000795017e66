#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>

#include "support/temp_dir.h"

namespace everytouch::test {

// A dbus-daemon of type "system" on a socket in a temporary directory, with the deny-by-default policy of
// Debian's system bus plus the given policy file (the one we ship), or, `permissive`, one that lets anyone
// call anything, to test the daemon's own checks. Sets DBUS_SYSTEM_BUS_ADDRESS for this process and its
// children while it lives.
class PrivateBus {
public:
    PrivateBus(const std::filesystem::path& policyFile, bool permissive);
    ~PrivateBus();
    PrivateBus(const PrivateBus&) = delete;
    PrivateBus& operator=(const PrivateBus&) = delete;

    const std::string& address() const { return address_; }

private:
    TempDir directory_;
    std::string address_;
    pid_t pid_ = 0;
};

}  // namespace everytouch::test

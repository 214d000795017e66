#pragma once

#include <sys/types.h>

#include <optional>
#include <string>

#include <systemd/sd-bus.h>

namespace everytouch::service {

// Decides whether the sender of a method call may change the daemon's state: root, or a member of the
// privileged group, judged by the effective uid the bus reports for the sender and by the groups the bus
// reports or, where it reports none, the group database. This holds on top of the D-Bus policy, which already
// keeps others from calling; it guards against a looser policy.
class SenderAuthorization {
public:
    // Looks the group up now; without such a group only root is allowed.
    explicit SenderAuthorization(const std::string& groupName);

    // 1 when allowed, 0 when not, a negative errno when the sender's credentials cannot be read.
    int check(sd_bus_message* message) const;

    const std::string& groupName() const { return groupName_; }
    bool groupExists() const { return gid_.has_value(); }

private:
    std::string groupName_;
    std::optional<gid_t> gid_;
};

}  // namespace everytouch::service

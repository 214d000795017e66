#pragma once

#include <sys/types.h>

#include <optional>
#include <string>

namespace everytouch::test {

// Makes sure a group of this name exists for this process and its children, so that tests can run a client
// as a member of it. If the system has none, and this process may, it enters a private mount namespace and
// lays a copy of /etc/group with the group added over the real one; the host is not touched. Must run
// before any thread starts (first thing in main). Returns the group id, or nothing with the reason in `why`.
std::optional<gid_t> provideGroup(const std::string& name, std::string& why);

}  // namespace everytouch::test

#pragma once

#include <sys/types.h>

#include <optional>
#include <string>

namespace everytouch::test {

// A user the group database lists as a member of a group.
struct GroupMember {
    uid_t uid = 0;
    gid_t gid = 0;  // the group's
};

// Makes sure, for this process and its children, that a group of this name exists and that a user of its own
// is listed as a member, so that tests can run a client as that user. It enters a private mount namespace
// and lays copies of /etc/passwd and /etc/group with the user and the membership added over the real ones;
// the host is not touched. Must run before any thread starts (first thing in main). Returns the member, or
// nothing with the reason in `why`.
std::optional<GroupMember> provideGroupMember(const std::string& groupName, std::string& why);

}  // namespace everytouch::test

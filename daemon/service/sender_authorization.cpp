#include "service/sender_authorization.h"

#include <grp.h>
#include <pwd.h>

#include <algorithm>
#include <vector>

#include "io/handles.h"

namespace everytouch::service {

namespace {

// Whether the group database makes this user a member of the group, as its primary group or in its list
// (getgrouplist returns both).
bool databaseListsMember(uid_t uid, gid_t gid) {
    std::vector<char> buffer(16384);
    passwd entry{};
    passwd* found = nullptr;
    if (getpwuid_r(uid, &entry, buffer.data(), buffer.size(), &found) != 0 || !found)
        return false;
    std::vector<gid_t> groups(64);
    int count = static_cast<int>(groups.size());
    while (getgrouplist(found->pw_name, found->pw_gid, groups.data(), &count) < 0) {
        // count now holds the number needed.
        groups.resize(static_cast<std::size_t>(count));
    }
    return std::find(groups.begin(), groups.begin() + count, gid) != groups.begin() + count;
}

}  // namespace

SenderAuthorization::SenderAuthorization(const std::string& groupName) : groupName_(groupName) {
    std::vector<char> buffer(16384);
    group entry{};
    group* found = nullptr;
    if (getgrnam_r(groupName.c_str(), &entry, buffer.data(), buffer.size(), &found) == 0 && found)
        gid_ = found->gr_gid;
}

int SenderAuthorization::check(sd_bus_message* message) const {
    // Only what the bus itself vouches for: augmenting from /proc/PID races with the sender exiting and its
    // PID being reused, and systemd refuses such credentials for permission checks.
    sd_bus_creds* raw = nullptr;
    int r = sd_bus_query_sender_creds(message, SD_BUS_CREDS_EUID | SD_BUS_CREDS_SUPPLEMENTARY_GIDS, &raw);
    const io::BusCreds creds(raw);
    if (r < 0)
        return r;
    uid_t euid = 0;
    r = sd_bus_creds_get_euid(creds.get(), &euid);
    if (r < 0)
        return r;
    if (euid == 0)
        return 1;
    if (!gid_)
        return 0;
    // dbus-broker and newer dbus-daemons report the sender's groups; dbus-daemon 1.14 does not, and there
    // the group database decides, as it does for dbus-daemon's own group policies.
    const gid_t* groups = nullptr;
    r = sd_bus_creds_get_supplementary_gids(creds.get(), &groups);
    if (r < 0 && r != -ENODATA)
        return r;
    if (r > 0 && std::find(groups, groups + r, *gid_) != groups + r)
        return 1;
    return databaseListsMember(euid, *gid_) ? 1 : 0;
}

}  // namespace everytouch::service

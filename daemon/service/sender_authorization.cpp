#include "service/sender_authorization.h"

#include <grp.h>

#include <vector>

#include "io/handles.h"

namespace everytouch::service {

SenderAuthorization::SenderAuthorization(const std::string& groupName) : groupName_(groupName) {
    std::vector<char> buffer(16384);
    group entry{};
    group* found = nullptr;
    if (getgrnam_r(groupName.c_str(), &entry, buffer.data(), buffer.size(), &found) == 0 && found)
        gid_ = found->gr_gid;
}

int SenderAuthorization::check(sd_bus_message* message) const {
    sd_bus_creds* raw = nullptr;
    int r = sd_bus_query_sender_creds(
        message, SD_BUS_CREDS_EUID | SD_BUS_CREDS_SUPPLEMENTARY_GIDS | SD_BUS_CREDS_AUGMENT, &raw);
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
    const gid_t* groups = nullptr;
    r = sd_bus_creds_get_supplementary_gids(creds.get(), &groups);
    if (r < 0)
        return r == -ENODATA ? 0 : r;
    for (int i = 0; i < r; ++i)
        if (groups[i] == *gid_)
            return 1;
    return 0;
}

}  // namespace everytouch::service

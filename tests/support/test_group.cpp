#include "support/test_group.h"

#include <grp.h>
#include <pwd.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace everytouch::test {

namespace {

constexpr const char* kMemberName = "everytouch-test-member";
constexpr gid_t kNogroup = 65534;

// Lays a file with this text over `target` in the current mount namespace.
bool layOver(const char* target, const std::string& text, std::string& why) {
    char path[] = "/tmp/everytouch-test-db-XXXXXX";
    const int fd = ::mkstemp(path);
    if (fd < 0) {
        why = std::string("cannot write a copy of ") + target + ": " + std::strerror(errno);
        return false;
    }
    const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
    ::fchmod(fd, 0644);
    ::close(fd);
    const bool mounted = written && ::mount(path, target, nullptr, MS_BIND, nullptr) == 0;
    const int mountError = errno;
    // The mount keeps the file's contents; its name is no longer needed.
    ::unlink(path);
    if (!mounted)
        why = std::string("cannot lay a copy over ") + target + ": " + std::strerror(mountError);
    return mounted;
}

}  // namespace

std::optional<GroupMember> provideGroupMember(const std::string& groupName, std::string& why) {
    if (::unshare(CLONE_NEWNS) < 0) {
        why = std::string("cannot enter a private mount namespace: ") + std::strerror(errno);
        return std::nullopt;
    }
    if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) < 0) {
        why = std::string("cannot make the mounts private: ") + std::strerror(errno);
        return std::nullopt;
    }
    GroupMember member{60999, 60999};
    while (member.uid > 60000 && ::getpwuid(member.uid))
        --member.uid;
    if (const group* existing = ::getgrnam(groupName.c_str())) {
        member.gid = existing->gr_gid;
    } else {
        while (member.gid > 60000 && ::getgrgid(member.gid))
            --member.gid;
    }

    std::ostringstream users;
    users << std::ifstream("/etc/passwd").rdbuf() << kMemberName << ":x:" << member.uid << ":" << kNogroup
          << "::/nonexistent:/usr/sbin/nologin\n";
    // The group's line, if any, is replaced by one that also lists the member.
    std::ostringstream groups;
    std::ifstream groupFile("/etc/group");
    std::string members;
    for (std::string line; std::getline(groupFile, line);) {
        if (line.rfind(groupName + ":", 0) == 0) {
            members = line.substr(line.rfind(':') + 1);
            continue;
        }
        groups << line << '\n';
    }
    groups << groupName << ":x:" << member.gid << ":" << members << (members.empty() ? "" : ",")
           << kMemberName << '\n';
    if (!layOver("/etc/passwd", users.str(), why) || !layOver("/etc/group", groups.str(), why))
        return std::nullopt;
    return member;
}

}  // namespace everytouch::test

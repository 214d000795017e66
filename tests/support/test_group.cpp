#include "support/test_group.h"

#include <grp.h>
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

std::optional<gid_t> lookUp(const std::string& name) {
    if (const group* entry = ::getgrnam(name.c_str()))
        return entry->gr_gid;
    return std::nullopt;
}

}  // namespace

std::optional<gid_t> provideGroup(const std::string& name, std::string& why) {
    if (const std::optional<gid_t> existing = lookUp(name))
        return existing;
    if (::unshare(CLONE_NEWNS) < 0) {
        why = std::string("cannot enter a private mount namespace: ") + std::strerror(errno);
        return std::nullopt;
    }
    if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) < 0) {
        why = std::string("cannot make the mounts private: ") + std::strerror(errno);
        return std::nullopt;
    }
    gid_t gid = 60999;
    while (gid > 60000 && ::getgrgid(gid))
        --gid;
    std::ostringstream groups;
    groups << std::ifstream("/etc/group").rdbuf() << name << ":x:" << gid << ":\n";
    char path[] = "/tmp/everytouch-test-group-XXXXXX";
    const int fd = ::mkstemp(path);
    if (fd < 0) {
        why = std::string("cannot write a group file: ") + std::strerror(errno);
        return std::nullopt;
    }
    const std::string text = groups.str();
    const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
    ::fchmod(fd, 0644);
    ::close(fd);
    const bool mounted = written && ::mount(path, "/etc/group", nullptr, MS_BIND, nullptr) == 0;
    // The mount keeps the file's contents; its name is no longer needed.
    ::unlink(path);
    if (!mounted) {
        why = std::string("cannot lay the group file over /etc/group: ") + std::strerror(errno);
        return std::nullopt;
    }
    return lookUp(name);
}

}  // namespace everytouch::test

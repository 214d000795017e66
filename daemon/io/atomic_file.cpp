#include "io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <system_error>

#include "io/handles.h"

namespace everytouch::io {

namespace {

[[noreturn]] void throwErrno(int error, const std::string& what) {
    throw std::system_error(error, std::generic_category(), what);
}

void writeAll(int fd, std::string_view contents, const std::string& name) {
    while (!contents.empty()) {
        const ssize_t written = ::write(fd, contents.data(), contents.size());
        if (written < 0) {
            if (errno == EINTR)
                continue;
            throwErrno(errno, "Failed to write " + name);
        }
        contents.remove_prefix(static_cast<size_t>(written));
    }
}

}  // namespace

void writeFileAtomically(const std::filesystem::path& path, std::string_view contents) {
    const std::filesystem::path directory = path.has_parent_path() ? path.parent_path() : ".";
    std::string temporary = (directory / ("." + path.filename().string() + ".XXXXXX")).string();
    UniqueFd fd(::mkostemp(temporary.data(), O_CLOEXEC));
    if (!fd)
        throwErrno(errno, "Failed to create a temporary file for " + path.string());
    try {
        writeAll(fd.get(), contents, temporary);
        if (::fchmod(fd.get(), 0644) < 0)
            throwErrno(errno, "Failed to set permissions of " + temporary);
        if (::fsync(fd.get()) < 0)
            throwErrno(errno, "Failed to flush " + temporary);
        fd.reset();
        if (::rename(temporary.c_str(), path.c_str()) < 0)
            throwErrno(errno, "Failed to replace " + path.string());
    } catch (...) {
        ::unlink(temporary.c_str());
        throw;
    }
    UniqueFd directoryFd(::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
    if (directoryFd)
        ::fsync(directoryFd.get());
}

}  // namespace everytouch::io

#include "io/log.h"

#include <sys/stat.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace everytouch::io {

namespace {

std::atomic<bool> verboseLogging{false};

// systemd sets JOURNAL_STREAM to "device:inode" of the stream it connected; it only counts if stderr is that
// stream.
bool stderrIsJournal() {
    static const bool isJournal = [] {
        const char* value = std::getenv("JOURNAL_STREAM");
        unsigned long long device = 0, inode = 0;
        if (!value || std::sscanf(value, "%llu:%llu", &device, &inode) != 2)
            return false;
        struct stat status {};
        return fstat(STDERR_FILENO, &status) == 0 && status.st_dev == device && status.st_ino == inode;
    }();
    return isJournal;
}

const char* tag(LogLevel level) {
    switch (level) {
        case LogLevel::Error:
            return "error: ";
        case LogLevel::Warning:
            return "warning: ";
        case LogLevel::Debug:
            return "debug: ";
        case LogLevel::Notice:
        case LogLevel::Info:
            break;
    }
    return "";
}

}  // namespace

void setLogVerbose(bool verbose) {
    verboseLogging = verbose;
}

bool logEnabled(LogLevel level) {
    return level != LogLevel::Debug || verboseLogging;
}

LogLine::~LogLine() {
    std::string line = stderrIsJournal() ? "<" + std::to_string(static_cast<int>(level_)) + ">" : tag(level_);
    line += stream_.str();
    line += '\n';
    std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace everytouch::io

#pragma once

#include <sstream>

namespace everytouch::io {

// Priorities as in syslog(3) and sd-daemon(3).
enum class LogLevel { Error = 3, Warning = 4, Notice = 5, Info = 6, Debug = 7 };

void setLogVerbose(bool verbose);
bool logEnabled(LogLevel level);

// One log line, written to stderr when it goes out of scope. With stderr connected to the journal
// ($JOURNAL_STREAM) lines carry sd-daemon priority prefixes instead of a readable tag.
class LogLine {
public:
    explicit LogLine(LogLevel level) : level_(level) {}
    LogLine(const LogLine&) = delete;
    LogLine& operator=(const LogLine&) = delete;
    ~LogLine();

    template <typename T>
    LogLine& operator<<(const T& value) {
        stream_ << value;
        return *this;
    }

private:
    LogLevel level_;
    std::ostringstream stream_;
};

}  // namespace everytouch::io

// Streams one log line; the arguments are not evaluated when the level is disabled.
#define ET_LOG(level)                                                                               \
    for (bool enabled_ = ::everytouch::io::logEnabled(::everytouch::io::LogLevel::level); enabled_; \
         enabled_ = false)                                                                          \
    ::everytouch::io::LogLine(::everytouch::io::LogLevel::level)

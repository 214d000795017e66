#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "core/contact.h"
#include "io/touch_sink.h"

namespace everytouch::io {

// One line of a touch log (docs/architecture.md, "Touch log").
struct TouchLogEntry {
    std::uint64_t index = 0;
    std::int64_t timestampUs = 0;
    core::Contacts contacts;
    std::size_t line = 0;  // where readTouchLog found it, 1-based: messages about the entry name it
};

// Writes the JSON Lines touch log: one object per frame in which anything changed. "-" writes to stdout.
class TouchLogWriter final : public TouchSink {
public:
    explicit TouchLogWriter(const std::filesystem::path& path);
    ~TouchLogWriter() override;

    void publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts) override;

private:
    std::FILE* file_ = nullptr;
    bool ownsFile_ = false;
    core::Contacts last_;
    bool wroteAny_ = false;
};

// Reads a touch log; throws InputError naming the file, the line and the field at fault.
std::vector<TouchLogEntry> readTouchLog(const std::filesystem::path& path);

}  // namespace everytouch::io

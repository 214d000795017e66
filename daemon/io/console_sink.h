#pragma once

#include <map>

#include "io/touch_sink.h"

namespace everytouch::io {

// Tells a person at the terminal what the touchscreen would do: one line per touch down and up (every move
// too with --verbose), in display pixels and millimetres of height.
class ConsoleSink final : public TouchSink {
public:
    void publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts) override;

private:
    std::map<std::uint32_t, core::Contact> current_;
};

}  // namespace everytouch::io

#pragma once

#include <cstdint>

#include "core/contact.h"

namespace everytouch::io {

// Where contacts go: the virtual touchscreen, the touch log. `publish` receives the complete set of current
// contacts after each processed frame; a contact missing from the set has been lifted. Publishing an empty
// set releases everything, which the daemon does on shutdown and on any pipeline or camera failure.
class TouchSink {
public:
    virtual ~TouchSink() = default;
    virtual void publish(std::uint64_t frameIndex, std::int64_t timestampUs,
                         const core::Contacts& contacts) = 0;
};

}  // namespace everytouch::io
